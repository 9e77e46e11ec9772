//! Debug outlines of chunks and tiles.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::prelude::*;

#[test]
fn gizmos_outline_loaded_chunks_and_their_tiles() {
    use bevy_rwt::gizmos::outlines;
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let l = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.1)))
        .id();
    tick_app(&mut app, 2_000);
    let (layer, status) = app
        .world_mut()
        .query::<(&ScatterLayer, &ScatterLayerStatus)>()
        .get(app.world(), l)
        .unwrap();
    let chunks = status.loaded_chunks.len();
    let only_chunks = outlines(
        layer,
        status,
        &RwtGizmos {
            chunks: true,
            tiles: false,
            lift: 0.1,
        },
    );
    assert_eq!(only_chunks.len(), chunks);
    let both = outlines(
        layer,
        status,
        &RwtGizmos {
            chunks: true,
            tiles: true,
            lift: 0.1,
        },
    );
    // Chunks of 16 over tiles of 8: four tiles per chunk.
    assert_eq!(both.iter().filter(|o| o.2).count(), 4 * chunks);
    assert!(both.iter().filter(|o| o.2).all(|o| o.1 == 8.0));
}
