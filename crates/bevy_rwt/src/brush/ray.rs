//! Where a ray meets the ground of a height field.

use bevy::prelude::*;

/// The first point where the ray from `origin` along `direction` meets the ground
/// `y = height(x, z)`, within `max_distance`; `None` when it starts below the ground or never
/// reaches it. Marches with steps growing with the distance (fine near the eye, where the
/// brush is), then bisects the crossing.
pub fn ground_hit(
    origin: Vec3,
    direction: Vec3,
    height: &dyn Fn(Vec2) -> f32,
    max_distance: f32,
) -> Option<Vec3> {
    let dir = direction.try_normalize()?;
    let above = |t: f32| {
        let p = origin + dir * t;
        p.y - height(p.xz())
    };
    let start = above(0.0);
    if start.is_nan() || start < 0.0 {
        return None;
    }
    let (mut lo, mut t) = (0.0, 0.0);
    while t < max_distance {
        let step = (0.25 + 0.01 * t).min(8.0);
        t = (t + step).min(max_distance);
        // Infinitely far above where the ground has a hole; no answer where it is NaN.
        let h = above(t);
        if h.is_nan() || h == f32::NEG_INFINITY {
            return None;
        }
        if h < 0.0 {
            let mut hi = t;
            for _ in 0..24 {
                let mid = 0.5 * (lo + hi);
                if above(mid) < 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(origin + dir * hi);
        }
        lo = t;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_crossing_of_hilly_ground() {
        let hills = |p: Vec2| 3.0 * (p.x * 0.2).sin() + 2.0 * (p.y * 0.13).cos();
        let origin = Vec3::new(-20.0, 15.0, 4.0);
        let direction = Vec3::new(1.0, -0.4, 0.3);
        let hit = ground_hit(origin, direction, &hills, 500.0).unwrap();
        assert!((hit.y - hills(hit.xz())).abs() < 1e-2, "{hit}");
        // No earlier point on the ray is below the ground.
        let dir = direction.normalize();
        let t_hit = (hit - origin).length();
        for i in 0..1000 {
            let p = origin + dir * (t_hit * i as f32 / 1000.0);
            assert!(p.y >= hills(p.xz()) - 1e-3, "{p}");
        }
    }

    #[test]
    fn misses_are_none() {
        let flat = |_: Vec2| 0.0;
        let up = ground_hit(Vec3::Y, Vec3::Y, &flat, 1e4);
        let below = ground_hit(-Vec3::Y, Vec3::NEG_Y, &flat, 1e4);
        let short = ground_hit(
            Vec3::new(0.0, 100.0, 0.0),
            Vec3::new(1.0, -0.01, 0.0),
            &flat,
            50.0,
        );
        let degenerate = ground_hit(Vec3::Y, Vec3::ZERO, &flat, 1e4);
        let nan = ground_hit(Vec3::Y, Vec3::NEG_Y, &|_| f32::NAN, 1e4);
        assert_eq!(
            (up, below, short, degenerate, nan),
            (None, None, None, None, None)
        );
        let down = ground_hit(Vec3::new(3.0, 10.0, 4.0), Vec3::NEG_Y, &flat, 1e4).unwrap();
        assert!(down.distance(Vec3::new(3.0, 0.0, 4.0)) < 1e-3);
    }
}
