//! Dabs of paint on a map's texels, and what a stroke needs to be undone.

use super::{BrushError, DensityBrush};
use crate::layers::{GroundMap, ScatterLayer, set_texel_luminance, texel_luminance};
use crate::save::MapProblem;
use bevy::asset::RenderAssetUsages;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
use rwt_core::Rect;

/// A black map of `texels x texels` over the ground rectangle `area`, a value of 1 meaning
/// `scale` (for a density: instances per square unit where it is white): a canvas for the
/// brush (`LayerDensity::Image(map)`). The image is linear 8-bit RGBA, kept on the CPU so
/// that it can be painted.
pub fn blank_map(
    images: &mut Assets<Image>,
    texels: u32,
    area: bevy::math::Rect,
    scale: f64,
) -> GroundMap {
    let image = Image::new_fill(
        Extent3d {
            width: texels.max(1),
            height: texels.max(1),
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        &[0, 0, 0, 255],
        TextureFormat::Rgba8Unorm,
        RenderAssetUsages::MAIN_WORLD | RenderAssetUsages::RENDER_WORLD,
    );
    GroundMap {
        image: images.add(image),
        min: area.min,
        size: area.size(),
        scale,
    }
}

/// The map a target paints.
pub(super) fn target_map(
    brush: &DensityBrush,
    index: usize,
    layers: &Query<&ScatterLayer>,
) -> Result<GroundMap, BrushError> {
    let target = brush
        .targets
        .get(index)
        .ok_or(BrushError::NoTarget(index))?;
    Ok(target.ground_map(layers)?)
}

impl GroundMap {
    /// Ground position of the centre of texel `(x, y)` of its `w x h` image (row 0 at the
    /// far edge).
    fn texel_centre(&self, x: u32, y: u32, w: u32, h: u32) -> Vec2 {
        Vec2::new(
            self.min.x + (x as f32 + 0.5) / w as f32 * self.size.x,
            self.min.y + self.size.y - (y as f32 + 0.5) / h as f32 * self.size.y,
        )
    }

    /// Texel columns and rows whose centres may lie within `radius` of `centre`.
    fn texel_span(&self, centre: Vec2, radius: f32, w: u32, h: u32) -> (u32, u32, u32, u32) {
        let to_x = |g: f32| (g - self.min.x) / self.size.x * w as f32;
        let to_y = |g: f32| (self.min.y + self.size.y - g) / self.size.y * h as f32;
        let clamp = |v: f32, n: u32| v.clamp(0.0, n as f32) as u32;
        let (x0, x1) = (
            to_x(centre.x - radius).floor(),
            to_x(centre.x + radius).ceil(),
        );
        let (y0, y1) = (
            to_y(centre.y + radius).floor(),
            to_y(centre.y - radius).ceil(),
        );
        (clamp(x0, w), clamp(x1, w), clamp(y0, h), clamp(y1, h))
    }
}

/// A map's texel values before a stroke changed them, and the ground the stroke covered.
#[derive(Default, Debug, Clone)]
pub(super) struct StrokeRecord {
    /// Per map: texel index to its value before the stroke.
    pub before: HashMap<AssetId<Image>, HashMap<u32, f32>>,
    /// Per map: the ground the stroke's dabs covered.
    pub regions: HashMap<AssetId<Image>, Rect>,
}

impl StrokeRecord {
    fn note(&mut self, map: AssetId<Image>, texel: u32, value: f32) {
        self.before
            .entry(map)
            .or_default()
            .entry(texel)
            .or_insert(value);
    }

    fn cover(&mut self, map: AssetId<Image>, region: Rect) {
        let merged = match self.regions.get(&map) {
            Some(r) => {
                Rect::new(r.min().min(region.min()), r.max().max(region.max())).unwrap_or(region)
            }
            None => region,
        };
        self.regions.insert(map, merged);
    }

    /// Whether the stroke changed nothing.
    pub fn is_empty(&self) -> bool {
        self.before.values().all(HashMap::is_empty)
    }
}

/// What a dab does to a map: the texels it changes and the ground it covers.
#[derive(Debug, Default, PartialEq)]
pub(super) struct Dab {
    /// Texel index, old value, new value.
    changes: Vec<(u32, f32, f32)>,
    region: Option<Rect>,
}

/// The dab adding `amount` (negative erases) to the texels within `radius` of `centre`,
/// weighted by a smooth bump (1 at the centre, 0 at the radius), clamped to `0..=1`: read
/// only, so that a dab changing nothing (outside the map, or already full or empty) leaves
/// the map unmodified (a modified map is re-read and re-scattered). `Err` for a map whose
/// texels cannot be read on the CPU.
pub(super) fn dab(
    image: &Image,
    at: &GroundMap,
    centre: Vec2,
    radius: f32,
    amount: f32,
) -> Result<Dab, MapProblem> {
    let (w, h) = (image.width(), image.height());
    let radius = radius.max(1e-3);
    let (x0, x1, y0, y1) = at.texel_span(centre, radius, w, h);
    let mut changes = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            let d = at.texel_centre(x, y, w, h).distance(centre) / radius;
            if d >= 1.0 {
                continue;
            }
            let weight = (1.0 - d * d).powi(2);
            let old = texel_luminance(image, x, y).ok_or(MapProblem::of(Some(image)))?;
            let new = (old + amount * weight).clamp(0.0, 1.0);
            if (new - old).abs() >= 1e-4 {
                changes.push((y * w + x, old, new));
            }
        }
    }
    let (lo, hi) = (centre - radius, centre + radius);
    let region = Rect::new(lo.as_dvec2(), hi.as_dvec2()).ok();
    Ok(Dab { changes, region })
}

impl Dab {
    /// Whether the dab changes no texel.
    pub fn is_empty(&self) -> bool {
        self.changes.is_empty()
    }

    /// Writes the dab into map `id`, noting each changed texel's old value in `record`;
    /// returns the ground region changed (`None` when nothing changed), or `Err` for a map
    /// whose texels cannot be written.
    pub fn apply(
        &self,
        image: &mut Image,
        id: AssetId<Image>,
        record: &mut StrokeRecord,
    ) -> Result<Option<Rect>, MapProblem> {
        if self.is_empty() {
            return Ok(None);
        }
        let w = image.width().max(1);
        for &(texel, old, new) in &self.changes {
            record.note(id, texel, old);
            if !set_texel_luminance(image, texel % w, texel / w, new) {
                return Err(MapProblem::of(Some(image)));
            }
        }
        if let Some(r) = self.region {
            record.cover(id, r);
        }
        Ok(self.region)
    }
}

/// Puts back the texel values a stroke changed in one map.
pub(super) fn restore(image: &mut Image, before: &HashMap<u32, f32>) {
    let w = image.width().max(1);
    for (&texel, &value) in before {
        set_texel_luminance(image, texel % w, texel / w, value);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn canvas(format: TextureFormat) -> Image {
        Image::new_fill(
            Extent3d {
                width: 32,
                height: 32,
                depth_or_array_layers: 1,
            },
            TextureDimension::D2,
            &vec![0; format.block_copy_size(None).unwrap() as usize],
            format,
            RenderAssetUsages::MAIN_WORLD,
        )
    }

    /// A dab read from and written into `image`.
    fn paint(
        image: &mut Image,
        id: AssetId<Image>,
        at: &GroundMap,
        centre: Vec2,
        radius: f32,
        amount: f32,
        record: &mut StrokeRecord,
    ) -> Result<Option<Rect>, MapProblem> {
        dab(image, at, centre, radius, amount)?.apply(image, id, record)
    }

    #[test]
    fn a_dab_paints_a_smooth_disc_and_a_stroke_restores() {
        let at = &GroundMap {
            image: Handle::default(),
            min: Vec2::ZERO,
            size: Vec2::splat(32.0),
            scale: 1.0,
        };
        for format in [
            TextureFormat::Rgba8Unorm,
            TextureFormat::Rgba8UnormSrgb,
            TextureFormat::R8Unorm,
            TextureFormat::R32Float,
        ] {
            let mut image = canvas(format);
            let id = AssetId::default();
            let mut record = StrokeRecord::default();
            let centre = Vec2::new(10.5, 20.5);
            let changed = paint(&mut image, id, at, centre, 4.0, 0.6, &mut record).unwrap();
            assert!(changed.is_some(), "{format:?}");
            // Row 0 is the max-z edge: ground (10.5, 20.5) is the centre of texel (10, 11).
            let peak = texel_luminance(&image, 10, 11).unwrap();
            let edge = texel_luminance(&image, 13, 11).unwrap();
            let outside = texel_luminance(&image, 15, 11).unwrap();
            assert!((peak - 0.6).abs() < 0.03, "{format:?} {peak}");
            assert!(edge > 0.0 && edge < peak, "{format:?} {edge}");
            assert_eq!(outside, 0.0);
            // Erasing more than there is stops at 0; restoring brings back the blank map.
            paint(&mut image, id, at, centre, 4.0, -5.0, &mut record).unwrap();
            assert_eq!(texel_luminance(&image, 10, 11).unwrap(), 0.0);
            restore(&mut image, &record.before[&id]);
            assert!((0..32).all(|y| (0..32).all(|x| texel_luminance(&image, x, y) == Some(0.0))));
        }
    }

    #[test]
    fn dabs_off_the_map_change_nothing() {
        let at = &GroundMap {
            image: Handle::default(),
            min: Vec2::ZERO,
            size: Vec2::splat(32.0),
            scale: 1.0,
        };
        let mut image = canvas(TextureFormat::Rgba8Unorm);
        let mut record = StrokeRecord::default();
        let far = Vec2::new(-100.0, 500.0);
        let id = AssetId::default();
        assert_eq!(
            paint(&mut image, id, at, far, 4.0, 1.0, &mut record),
            Ok(None)
        );
        assert_eq!(
            paint(&mut image, id, at, Vec2::ONE, 0.0, 1.0, &mut record),
            Ok(None)
        );
        assert!(record.is_empty());
        assert!(dab(&image, at, far, 4.0, 1.0).unwrap().is_empty());
    }
}
