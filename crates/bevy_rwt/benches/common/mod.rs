//! What the headless benchmarks share: an app without a renderer, and a viewer to fly.

use bevy::prelude::*;
use bevy_rwt::prelude::*;

/// A headless app (`MinimalPlugins`, assets) with `plugin`, and a viewer that streams all
/// around it; returns the app and the viewer.
pub fn headless_app(plugin: RwtPlugins) -> (App, Entity) {
    let mut app = App::new();
    app.add_plugins((MinimalPlugins, bevy::asset::AssetPlugin::default(), plugin));
    app.finish();
    app.cleanup();
    let viewer = app
        .world_mut()
        .spawn((
            RwtViewer::all_around(),
            Transform::default(),
            GlobalTransform::default(),
        ))
        .id();
    (app, viewer)
}

/// Moves the viewer (both transforms: no propagation runs headless).
pub fn move_viewer(app: &mut App, viewer: Entity, at: Vec3) {
    let mut e = app.world_mut().entity_mut(viewer);
    *e.get_mut::<Transform>().unwrap() = Transform::from_translation(at);
    *e.get_mut::<GlobalTransform>().unwrap() = GlobalTransform::from_translation(at);
}
