//! Blades that part around whoever walks through them.
//!
//! Every entity with a [`Bender`] stamps, each frame, how far the blades around it lean and
//! which way (away from it) into a [`BendField`]: a fixed grid of
//! [`BEND_FIELD_TEXELS`]² texels of [`BEND_TEXEL`] metres centred on the main camera. The
//! field relaxes towards upright over [`BEND_RECOVERY`] seconds, so a bender leaves a trail
//! that straightens behind it. The vertex shader turns each instance of a class with a
//! [`InstancedShading::bend_response`](crate::InstancedShading::bend_response) about its
//! root by the lean it reads at its root. The cost is bounded whatever the number of
//! benders: a 32 KB texture uploaded once a frame, one texture read per vertex, and on the
//! CPU the texels each bender covers. Blades farther than half the field's side (16 m) from
//! the main camera do not bend.

use bevy::prelude::*;
use bevy::render::extract_resource::ExtractResource;

/// Texels along each side of the bend field.
pub const BEND_FIELD_TEXELS: u32 = 128;
/// Side of one texel, metres (the field spans `BEND_FIELD_TEXELS * BEND_TEXEL` = 32 m).
pub const BEND_TEXEL: f32 = 0.25;
/// Seconds after which a bent blade stands up again (to 5 % of its lean).
pub const BEND_RECOVERY: f32 = 2.0;

/// An entity whose passage bends instanced blades away from it: a player's capsule, a
/// rolling ball, a deer. Its `GlobalTransform`'s translation is its centre on the ground.
#[derive(Component, Clone, Copy, Debug, PartialEq, Reflect)]
#[reflect(Component, Default)]
pub struct Bender {
    /// Radius of the circle it bends, metres.
    pub radius: f32,
    /// How far blades at its centre lean, 0..1 (1 lays them flat).
    pub strength: f32,
}

impl Default for Bender {
    fn default() -> Self {
        Self {
            radius: 0.7,
            strength: 1.0,
        }
    }
}

/// How far blades lean around the main camera: per texel a lean vector on the ground
/// (x, z), its length 0..1 (1 lays a blade flat), pointing the way the blade falls.
#[derive(Resource, ExtractResource, Clone, Debug, Reflect)]
#[reflect(Resource, Clone, Debug)]
pub struct BendField {
    /// Ground position (x, z) of the field's min corner, a multiple of [`BEND_TEXEL`].
    min: Vec2,
    /// Lean per texel, row by row (z) from the min corner.
    lean: Vec<Vec2>,
    /// Whether any texel leans (the shader skips the field otherwise).
    active: bool,
}

impl Default for BendField {
    fn default() -> Self {
        Self {
            min: Vec2::ZERO,
            lean: vec![Vec2::ZERO; (BEND_FIELD_TEXELS * BEND_FIELD_TEXELS) as usize],
            active: false,
        }
    }
}

impl BendField {
    /// Ground position (x, z) of the min corner.
    pub fn min(&self) -> Vec2 {
        self.min
    }

    /// Side of the field, metres.
    pub fn extent(&self) -> f32 {
        BEND_FIELD_TEXELS as f32 * BEND_TEXEL
    }

    /// Whether any blade leans.
    pub fn active(&self) -> bool {
        self.active
    }

    /// The leans, row by row (z) from the min corner.
    pub fn texels(&self) -> &[Vec2] {
        &self.lean
    }

    /// The lean of the texel holding ground point `p` (x, z), zero outside the field.
    pub fn lean_at(&self, p: Vec2) -> Vec2 {
        self.index(((p - self.min) / BEND_TEXEL).floor().as_ivec2())
            .map_or(Vec2::ZERO, |i| self.lean[i])
    }

    fn index(&self, cell: IVec2) -> Option<usize> {
        let n = BEND_FIELD_TEXELS as i32;
        ((0..n).contains(&cell.x) && (0..n).contains(&cell.y))
            .then(|| (cell.y * n + cell.x) as usize)
    }

    /// Moves the field so that it is centred on `centre` (whole texels; what leaves it is
    /// forgotten, what enters stands upright).
    pub fn recentre(&mut self, centre: Vec2) {
        let half = self.extent() * 0.5;
        let min = ((centre - half) / BEND_TEXEL).floor() * BEND_TEXEL;
        let shift = ((min - self.min) / BEND_TEXEL).round().as_ivec2();
        if shift == IVec2::ZERO {
            return;
        }
        let upright = vec![Vec2::ZERO; self.lean.len()];
        let old = std::mem::replace(&mut self.lean, upright);
        let n = BEND_FIELD_TEXELS as i32;
        for y in 0..n {
            for x in 0..n {
                if let Some(from) = self.index(IVec2::new(x, y) + shift) {
                    self.lean[(y * n + x) as usize] = old[from];
                }
            }
        }
        self.min = min;
    }

    /// Lets every blade stand up by `seconds` of recovery.
    pub fn relax(&mut self, seconds: f32) {
        if !self.active {
            return;
        }
        // After BEND_RECOVERY seconds, 5 % of the lean is left.
        let keep = (-(20.0f32).ln() * seconds / BEND_RECOVERY).exp();
        let mut any = false;
        for lean in &mut self.lean {
            *lean *= keep;
            if lean.length_squared() < 1e-6 {
                *lean = Vec2::ZERO;
            } else {
                any = true;
            }
        }
        self.active = any;
    }

    /// Bends the blades within `bender.radius` of ground point `at` away from it: fully
    /// (`strength`) at its centre, less towards its rim; a blade keeps the larger of its
    /// lean and this one.
    pub fn stamp(&mut self, at: Vec2, bender: Bender) {
        let radius = bender.radius.max(0.0);
        let strength = bender.strength.clamp(0.0, 1.0);
        if !(radius > 0.0 && strength > 0.0 && at.is_finite()) {
            return;
        }
        let lo = ((at - radius - self.min) / BEND_TEXEL).floor().as_ivec2();
        let hi = ((at + radius - self.min) / BEND_TEXEL).floor().as_ivec2();
        let n = BEND_FIELD_TEXELS as i32 - 1;
        for y in lo.y.max(0)..=hi.y.min(n) {
            for x in lo.x.max(0)..=hi.x.min(n) {
                let centre = self.min + (Vec2::new(x as f32, y as f32) + 0.5) * BEND_TEXEL;
                let away = centre - at;
                let d = away.length() / radius;
                if d >= 1.0 {
                    continue;
                }
                let push = away.normalize_or(Vec2::X) * strength * (1.0 - d * d);
                let i = (y * (n + 1) + x) as usize;
                if push.length_squared() > self.lean[i].length_squared() {
                    self.lean[i] = push;
                    self.active = true;
                }
            }
        }
    }
}

/// Centres the field on the main camera (the active 3-D camera of lowest order, else the
/// first viewer), lets it relax and stamps every bender.
pub(super) fn update_bend_field(
    time: Res<Time>,
    mut field: ResMut<BendField>,
    benders: Query<(&GlobalTransform, &Bender)>,
    cameras: Query<(&Camera, &GlobalTransform), With<Camera3d>>,
    viewers: Query<&GlobalTransform, With<crate::RwtViewer>>,
) {
    let camera = cameras
        .iter()
        .filter(|(c, _)| c.is_active)
        .min_by_key(|(c, _)| c.order)
        .map(|(_, at)| at.translation());
    let Some(centre) = camera.or_else(|| viewers.iter().next().map(|v| v.translation())) else {
        return;
    };
    if benders.is_empty() && !field.active {
        return;
    }
    field.recentre(centre.xz());
    field.relax(time.delta_secs());
    for (at, bender) in &benders {
        field.stamp(at.translation().xz(), *bender);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bender_lays_blades_away_from_it_and_they_stand_up_again() {
        let mut field = BendField::default();
        field.recentre(Vec2::new(100.0, -40.0));
        let at = Vec2::new(101.0, -40.0);
        field.stamp(at, Bender::default());
        assert!(field.active());
        let east = field.lean_at(at + Vec2::new(0.3, 0.0));
        // Away from the bender, to within the texel's offset from the point.
        assert!(east.x > 0.5 && east.x > 2.0 * east.y.abs(), "{east}");
        let north = field.lean_at(at + Vec2::new(0.0, -0.3));
        assert!(north.y < -0.5 && -north.y > 2.0 * north.x.abs(), "{north}");
        assert_eq!(field.lean_at(at + Vec2::new(1.0, 0.0)), Vec2::ZERO);
        // Half the recovery: still leaning; the whole of it: 5 % left; then upright.
        field.relax(BEND_RECOVERY / 2.0);
        let half = field.lean_at(at + Vec2::new(0.3, 0.0)).length();
        assert!(
            (half / east.length() - 20f32.powf(-0.5)).abs() < 1e-3,
            "{half}"
        );
        field.relax(BEND_RECOVERY / 2.0);
        let left = field.lean_at(at + Vec2::new(0.3, 0.0)).length();
        assert!((left / east.length() - 0.05).abs() < 1e-3, "{left}");
        field.relax(10.0 * BEND_RECOVERY);
        assert!(!field.active());
    }

    #[test]
    fn a_moving_bender_leaves_a_trail_that_follows_the_field_as_it_moves() {
        let mut field = BendField::default();
        field.recentre(Vec2::ZERO);
        for step in 0..20 {
            field.relax(0.05);
            field.stamp(Vec2::new(step as f32 * 0.25, 0.0), Bender::default());
        }
        // Older places lean less than newer ones, and all lean (a trail).
        let side = |x: f32| field.lean_at(Vec2::new(x, 0.4)).length();
        assert!(side(0.0) > 0.0 && side(0.0) < side(2.5) && side(2.5) < side(4.75));
        // Moving the field by whole texels keeps the leans where they are on the ground.
        let before = field.lean_at(Vec2::new(2.5, 0.4));
        field.recentre(Vec2::new(3.0, -1.0));
        assert_eq!(field.lean_at(Vec2::new(2.5, 0.4)), before);
        field.recentre(Vec2::new(500.0, 0.0));
        assert_eq!(field.lean_at(Vec2::new(2.5, 0.4)), Vec2::ZERO);
    }

    #[test]
    fn bad_benders_change_nothing() {
        let mut field = BendField::default();
        for bender in [
            Bender {
                radius: f32::NAN,
                strength: 1.0,
            },
            Bender {
                radius: -1.0,
                strength: 1.0,
            },
            Bender {
                radius: 1.0,
                strength: 0.0,
            },
        ] {
            field.stamp(Vec2::ZERO, bender);
        }
        field.stamp(Vec2::INFINITY, Bender::default());
        field.stamp(Vec2::splat(1e30), Bender::default());
        assert!(!field.active());
    }
}
