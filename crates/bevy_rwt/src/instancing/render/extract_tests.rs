//! Extraction by change: a chunk is extracted again when it, its transform or its bounds
//! changed, and otherwise keeps last frame's extraction in the render world.

use super::extract::ExtractedChunk;
use crate::instancing::chunk::{InstanceBuffer, InstancedChunk};
use crate::look::InstancedShading;
use bevy::camera::primitives::Aabb;
use bevy::ecs::change_detection::Tick;
use bevy::ecs::schedule::ScheduleLabel;
use bevy::prelude::*;
use bevy::render::extract_component::ExtractComponentPlugin;
use bevy::render::extract_plugin::ExtractPlugin;
use bevy::render::{Render, RenderApp};
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

/// An app with a render world that extracts chunks (and nothing else), and one chunk.
fn app_with_a_chunk() -> (App, Entity) {
    let mut app = App::new();
    app.add_plugins((
        ExtractPlugin::default(),
        ExtractComponentPlugin::<InstancedChunk>::default(),
    ));
    app.sub_app_mut(RenderApp).update_schedule = Some(Render.intern());
    let chunk = InstancedChunk {
        layer: Entity::PLACEHOLDER,
        chunk: ChunkCoord { x: 0, y: 0 },
        class: 0,
        mesh: Handle::default(),
        meshes: (Handle::default(), None),
        far_per_instance: false,
        material: InstancedShading::default(),
        mesh_top: 1.0,
        max_scale: 1.0,
        falloff: None,
        buffer: Arc::new(InstanceBuffer::default()),
        impostor: None,
        fade_out: None,
        fade_in: None,
        surface: None,
    };
    let aabb = Aabb::from_min_max(Vec3::ZERO, Vec3::ONE);
    let entity = app.world_mut().spawn((chunk, aabb)).id();
    (app, entity)
}

/// The render world's extraction of the one chunk: its roughness, its bounds' centre, and
/// when it was last written.
fn extracted(app: &mut App) -> (f32, Vec3, Tick) {
    let world = app.sub_app_mut(RenderApp).world_mut();
    let mut chunks = world.query::<Ref<ExtractedChunk>>();
    let chunk = chunks.single(world).expect("one extracted chunk");
    (
        chunk.uniform.roughness,
        chunk.bounds.center.into(),
        chunk.last_changed(),
    )
}

#[test]
fn a_chunk_is_extracted_again_only_when_it_its_place_or_its_bounds_change() {
    let (mut app, entity) = app_with_a_chunk();
    app.update();
    let first = extracted(&mut app);
    assert_eq!(first.1, Vec3::splat(0.5));
    // Nothing changed: the render world keeps what it had.
    app.update();
    app.update();
    assert_eq!(extracted(&mut app), first);
    // The chunk changed.
    let mut chunk = app.world_mut().get_mut::<InstancedChunk>(entity).unwrap();
    chunk.material.roughness = 0.25;
    app.update();
    let changed = extracted(&mut app);
    assert_eq!(changed.0, 0.25);
    assert_ne!(changed.2, first.2);
    // Its place changed.
    let mut transform = app.world_mut().get_mut::<GlobalTransform>(entity).unwrap();
    *transform = GlobalTransform::from_translation(Vec3::new(10.0, 0.0, 0.0));
    app.update();
    assert_eq!(extracted(&mut app).1, Vec3::new(10.5, 0.5, 0.5));
    // Its bounds changed.
    *app.world_mut().get_mut::<Aabb>(entity).unwrap() =
        Aabb::from_min_max(Vec3::ZERO, Vec3::splat(3.0));
    app.update();
    assert_eq!(extracted(&mut app).1, Vec3::new(11.5, 1.5, 1.5));
}
