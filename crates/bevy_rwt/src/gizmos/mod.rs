//! Optional debug drawing: loaded chunks and, inside them, the base Wang tiles.

mod plugin;

pub use plugin::RwtGizmosPlugin;

use crate::layers::{ScatterLayer, ScatterLayerStatus};
use crate::look::GroundPlane;
use bevy::prelude::*;

/// What [`RwtGizmosPlugin`] draws.
#[derive(Resource, Clone, Copy, Debug, Reflect)]
#[reflect(Resource, Clone, Debug)]
pub struct RwtGizmos {
    /// Outline every loaded chunk.
    pub chunks: bool,
    /// Outline the base tiles inside loaded chunks.
    pub tiles: bool,
    /// Height above the ground of the lines.
    pub lift: f32,
}

impl Default for RwtGizmos {
    fn default() -> Self {
        Self {
            chunks: true,
            tiles: false,
            lift: 0.05,
        }
    }
}

fn square(gizmos: &mut Gizmos, plane: GroundPlane, min: Vec2, size: f32, lift: f32, color: Color) {
    let corner = |u: f32, v: f32| plane.point_at(Vec2::new(u, v), lift);
    let corners = [
        corner(min.x, min.y),
        corner(min.x + size, min.y),
        corner(min.x + size, min.y + size),
        corner(min.x, min.y + size),
    ];
    for i in 0..4 {
        gizmos.line(corners[i], corners[(i + 1) % 4], color);
    }
}

/// Squares to outline for one layer: `(min corner (x, z), side, is_tile)`.
pub fn outlines(
    layer: &ScatterLayer,
    status: &ScatterLayerStatus,
    settings: &RwtGizmos,
) -> Vec<(Vec2, f32, bool)> {
    let mut out = Vec::new();
    let size = layer.streaming.chunk_size;
    for chunk in &status.loaded_chunks {
        let r = chunk.rect(size);
        if settings.chunks {
            out.push((
                Vec2::new(r.min().x as f32, r.min().y as f32),
                size as f32,
                false,
            ));
        }
        if settings.tiles && layer.tile_size > 0.0 {
            let t = layer.tile_size;
            let (i0, i1) = (
                (r.min().x / t).floor() as i64,
                (r.max().x / t).ceil() as i64,
            );
            let (j0, j1) = (
                (r.min().y / t).floor() as i64,
                (r.max().y / t).ceil() as i64,
            );
            // Only chunks holding a handful of tiles are worth outlining.
            if (i1 - i0).saturating_mul(j1 - j0) <= 256 {
                for j in j0..j1 {
                    for i in i0..i1 {
                        out.push((
                            Vec2::new((i as f64 * t) as f32, (j as f64 * t) as f32),
                            t as f32,
                            true,
                        ));
                    }
                }
            }
        }
    }
    out
}

fn draw(
    mut gizmos: Gizmos,
    settings: Res<RwtGizmos>,
    layers: Query<(&ScatterLayer, &ScatterLayerStatus)>,
) {
    for (layer, status) in &layers {
        for (min, side, tile) in outlines(layer, status, &settings) {
            let color = if tile {
                Color::srgb(0.2, 0.7, 1.0)
            } else {
                Color::srgb(1.0, 0.8, 0.1)
            };
            square(&mut gizmos, layer.plane, min, side, settings.lift, color);
        }
    }
}
