//! Fuzz check of `bevy_rwt`'s layer file loader: any text is rejected with an error or
//! becomes a layer whose densities, streaming and queries behave.

use bevy_rwt::LayerDensity;
use bevy_rwt::layers::file::{LayerDescription, NamedAssets, Placeholders};
use bevy_rwt::rwt_core::density::{Density, sanitize};
use bevy_rwt::rwt_core::query::{Rect, Sampler};
use bevy_rwt::rwt_core::streaming::{ChunkSet, Viewer};
use bevy_rwt::rwt_core::tileset::TileSet;
use glam::DVec2;
use std::sync::OnceLock;

/// A sampler over the shipped set, prepared once (cloning and reseeding it is cheap).
fn embedded() -> Sampler {
    static SAMPLER: OnceLock<Sampler> = OnceLock::new();
    SAMPLER
        .get_or_init(|| Sampler::new(&TileSet::embedded(), 0))
        .clone()
}

/// A `.layer.ron` file; returns whether it was accepted.
pub fn layer_file(data: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(data) else {
        return false;
    };
    let Ok(description) = LayerDescription::from_ron(text) else {
        return false;
    };
    // With no names registered, a file naming a mesh, material or ground is rejected.
    let Ok(layer) = description.to_layer(&NamedAssets::default(), &mut Placeholders) else {
        return false;
    };
    // Streaming around a viewer at the origin stays bounded and terminates.
    let mut chunks = ChunkSet::default();
    let viewer = Viewer::omni(DVec2::ZERO);
    let changes = chunks.update(&layer.streaming, &[viewer]);
    assert!(changes.load.len() <= 1_000_000);
    // Every non-image class density answers with a bounded query.
    let sampler = embedded()
        .with_seed(layer.seed)
        .with_tile_size(layer.tile_size)
        .with_budget(100_000);
    let rect = Rect::new(DVec2::splat(-3.0), DVec2::splat(3.0)).unwrap();
    for class in &layer.classes {
        let density: Box<dyn Density> = match &class.density {
            LayerDensity::Constant(v) => Box::new(bevy_rwt::rwt_core::density::Constant(*v)),
            LayerDensity::Noise(n) => Box::new(n.clone()),
            _ => continue,
        };
        let _ = sanitize(density.density(DVec2::ZERO));
        let _ = sampler.query_with(rect, &density, |p| assert!(rect.contains(p.position)));
    }
    true
}
