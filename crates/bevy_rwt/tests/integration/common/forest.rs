//! A forest layer for the tests of edits, footprints, picking and promotion.

use super::*;

/// Classes of the test layer.
pub const TREE: u16 = 0;
pub const STUMP: u16 = 1;
pub const GRASS: u16 = 2;
pub const CLOVER: u16 = 3;

/// Trees (entities) and stumps (entities, nowhere until an edit makes one), grass on a
/// painted map and clover (instanced, nowhere until an edit), with a level-of-detail
/// fall-off. Returns the layer entity and the map.
pub fn forest(app: &mut App) -> (Entity, Handle<Image>) {
    let (map, painted) = gray_map(app, 0.8);
    let tree = ScatterClass::new(LayerDensity::Constant(0.05), default(), default());
    let stump = ScatterClass::new(LayerDensity::Constant(0.0), default(), default());
    let grass = ScatterClass::instanced(painted, default(), InstancedShading::default());
    let clover = ScatterClass::instanced(
        LayerDensity::Constant(0.0),
        default(),
        InstancedShading::default(),
    );
    let mut l = layer(LayerDensity::Constant(0.0)).with_falloff(10.0, 70.0);
    l.classes = vec![tree, stump, grass, clover];
    l.streaming.load_distance = 80.0;
    l.streaming.unload_distance = 96.0;
    (app.world_mut().spawn(l).id(), map)
}
