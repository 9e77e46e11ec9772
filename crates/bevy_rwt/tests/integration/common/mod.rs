//! Helpers shared by the plugin's integration tests: a headless app (`MinimalPlugins` and
//! assets, no renderer), frame stepping until streaming settles, viewers, layers, painting.
#![allow(dead_code)] // each test file uses some of them

pub mod forest;

use bevy::asset::AssetPlugin;
use bevy::prelude::*;
use bevy_rwt::instancing::InstancedChunk;
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::collections::{HashMap, HashSet};

#[allow(unused_imports)] // each test file uses some of them
pub use bevy_rwt::testing::{move_viewer, run_until, spawn_viewer};

pub fn create_app() -> App {
    create_app_with(|_| {})
}

/// A headless app; `extra` adds plugins before the app is finished.
pub fn create_app_with(extra: impl FnOnce(&mut App)) -> App {
    bevy_rwt::testing::headless_app_with(RwtPlugins::default().with_spawn_budget(50_000), extra)
}

/// A headless app that reads assets (PNG images too) from `dir`.
pub fn app_reading(dir: &std::path::Path) -> App {
    app_reading_with(dir, |_| {})
}

/// A headless app that reads assets from `dir`; `extra` adds plugins before it is finished.
pub fn app_reading_with(dir: &std::path::Path, extra: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins((
        MinimalPlugins,
        AssetPlugin {
            file_path: dir.to_string_lossy().into_owned(),
            ..Default::default()
        },
        bevy::image::ImagePlugin::default(),
        RwtPlugins::default().with_spawn_budget(50_000),
    ))
    .init_asset::<Mesh>()
    .init_asset::<StandardMaterial>();
    // The renderer registers the image loader with the GPU's formats; headless, plain ones.
    use bevy::image::{CompressedImageFormats, ImageLoader};
    app.register_asset_loader(ImageLoader::new(CompressedImageFormats::empty()));
    extra(&mut app);
    app.finish();
    app.cleanup();
    app
}

/// Runs frames until nothing is pending or queued (or `max` frames).
pub fn tick_app(app: &mut App, max: usize) {
    assert!(
        bevy_rwt::testing::settle(app, max),
        "streaming did not settle in {max} frames"
    );
}

/// A `size x size` image of one colour.
pub fn solid_image(size: u32, rgba: [u8; 4]) -> Image {
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
    Image::new_fill(
        Extent3d {
            width: size,
            height: size,
            depth_or_array_layers: 1,
        },
        TextureDimension::D2,
        &rgba,
        TextureFormat::Rgba8Unorm,
        Default::default(),
    )
}

/// Paints texels `[x0, x0 + 8) x [y0, y0 + 8)` of `image` with `color`.
pub fn paint_square(app: &mut App, image: &Handle<Image>, x0: u32, y0: u32, color: Color) {
    let mut images = app.world_mut().resource_mut::<Assets<Image>>();
    let mut img = images.get_mut(image).unwrap();
    for y in y0..y0 + 8 {
        for x in x0..x0 + 8 {
            img.set_color_at(x, y, color).unwrap();
        }
    }
}

/// Whether `p` lies where texels 40..48 of a 64-texel map over -64..64 reach: x in 16..32,
/// z in -32..-16 (rows count from the top, max z = 64), widened by half a texel by bilinear
/// blending.
pub fn in_painted_square(p: &Vec3) -> bool {
    p.x > 15.0 && p.x < 33.0 && p.z > -33.0 && p.z < -15.0
}

pub fn streaming() -> StreamingConfig {
    StreamingConfig {
        chunk_size: 16.0,
        load_distance: 48.0,
        unload_distance: 64.0,
        near_distance: 20.0,
    }
}

pub fn layer(density: LayerDensity) -> ScatterLayer {
    let class = ScatterClass::new(density, Handle::default(), Handle::default());
    ScatterLayer::new(vec![class])
        .with_tile_size(8.0)
        .with_seed(3)
        .with_streaming(streaming())
}

pub fn instances(app: &mut App) -> HashMap<PointId, Vec3> {
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    let mut out = HashMap::new();
    for (i, t) in q.iter(app.world()) {
        assert!(
            out.insert(i.id, t.translation).is_none(),
            "two live instances share {:?}",
            i.id
        );
    }
    out
}

/// Every instance by its layer's name and point, with its position (layers of one seed and
/// tile size share point identities; their names tell them apart).
pub fn layered(app: &mut App) -> HashMap<(String, PointId), Vec3> {
    let names: HashMap<Entity, String> = app
        .world_mut()
        .query::<(Entity, &Name)>()
        .iter(app.world())
        .map(|(e, n)| (e, n.to_string()))
        .collect();
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    q.iter(app.world())
        .map(|(i, t)| ((names[&i.layer].clone(), i.id), t.translation))
        .collect()
}

/// The brush's blank 64-texel map over -64..64 (x and z) at up to 1 instance per square
/// unit, and the layer density reading it.
#[cfg(feature = "brush")]
pub fn blank_canvas(app: &mut App) -> (Handle<Image>, LayerDensity) {
    let map = bevy_rwt::brush::blank_map(
        &mut app.world_mut().resource_mut::<Assets<Image>>(),
        64,
        Rect::from_center_size(Vec2::ZERO, Vec2::splat(128.0)),
        1.0,
    );
    (map.image.clone(), LayerDensity::Image(map))
}

/// A mid-grey 64-texel density map over -64..64 (x and z) times `scale`, and the layer
/// density reading it.
pub fn gray_map(app: &mut App, scale: f64) -> (Handle<Image>, LayerDensity) {
    solid_map(app, [128, 128, 128, 255], scale)
}

/// A 64-texel map of one colour over -64..64 (x and z) times `scale`, and the layer density
/// reading it.
pub fn solid_map(app: &mut App, rgba: [u8; 4], scale: f64) -> (Handle<Image>, LayerDensity) {
    let handle = app
        .world_mut()
        .resource_mut::<Assets<Image>>()
        .add(solid_image(64, rgba));
    let density = LayerDensity::Image(GroundMap {
        image: handle.clone(),
        min: Vec2::splat(-64.0),
        size: Vec2::splat(128.0),
        scale,
    });
    (handle, density)
}

/// What an instance is: where, turned how far, how large, of which class.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placed {
    pub position: Vec3,
    pub yaw: f32,
    pub scale: f32,
    pub class: u16,
}

/// A headless app that keeps the identities of instanced points beside their buffers.
pub fn instanced_app() -> App {
    let mut app = create_app();
    app.world_mut()
        .resource_mut::<RwtSettings>()
        .keep_instance_ids = true;
    app
}

/// Every live instance of either path, by identity.
pub fn placed(app: &mut App) -> HashMap<PointId, Placed> {
    let mut out = HashMap::new();
    let mut entities = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    for (i, t) in entities.iter(app.world()) {
        let (yaw, _, _) = t.rotation.to_euler(EulerRot::YXZ);
        let p = Placed {
            position: t.translation,
            yaw: yaw.rem_euclid(std::f32::consts::TAU),
            scale: t.scale.x,
            class: i.class,
        };
        assert!(out.insert(i.id, p).is_none(), "{:?} twice", i.id);
    }
    // Chunk entities; the children of promoted instances draw what their parents hold.
    let mut chunks = app
        .world_mut()
        .query_filtered::<(&InstancedChunk, &Transform), Without<ChildOf>>();
    for (c, t) in chunks.iter(app.world()) {
        assert_eq!(c.buffer.ids.len(), c.len(), "ids kept beside the buffer");
        for (id, g) in c.buffer.ids.iter().zip(&c.buffer.instances) {
            let p = Placed {
                position: t.translation + Vec3::from_array(g.offset),
                yaw: g.yaw_radians(),
                scale: g.scale,
                class: c.class,
            };
            assert!(out.insert(*id, p).is_none(), "{id:?} twice");
        }
    }
    out
}

/// Asserts that two worlds hold the same points with the same classes and scales, in the
/// same places and turns (to the precision of the instanced path's chunk offsets and 16-bit
/// turns, as the entity and the instanced path of one point differ).
pub fn assert_same(entities: &HashMap<PointId, Placed>, instanced: &HashMap<PointId, Placed>) {
    let a: HashSet<_> = entities.keys().collect();
    let b: HashSet<_> = instanced.keys().collect();
    assert_eq!(a.len(), b.len(), "instance counts differ");
    assert!(a == b, "different points");
    for (id, e) in entities {
        let i = &instanced[id];
        assert_eq!(e.class, i.class, "{id:?}");
        assert_eq!(e.scale, i.scale, "{id:?}");
        assert!(
            e.position.distance(i.position) < 1e-3,
            "{id:?}: {e:?} vs {i:?}"
        );
        let turn = (e.yaw - i.yaw).rem_euclid(std::f32::consts::TAU);
        assert!(
            turn.min(std::f32::consts::TAU - turn) < 2e-4,
            "{id:?}: {e:?} vs {i:?}"
        );
    }
}
