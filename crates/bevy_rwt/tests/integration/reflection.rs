//! Reflection: the plugin's components, resources and messages are registered, and a layer's
//! settings changed through reflection (as an inspector changes them) take effect: the layer
//! scatters anew.

use crate::common::*;
use bevy::ecs::reflect::{ReflectComponent, ReflectResource};
use bevy::prelude::*;
use bevy::reflect::{GetPath, TypeRegistry};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::any::TypeId;
use std::collections::BTreeMap;

fn registered<T: 'static>(registry: &TypeRegistry) -> bool {
    registry.get(TypeId::of::<T>()).is_some()
}

#[test]
fn components_resources_and_messages_are_registered() {
    let app = create_app_with(|app| {
        app.add_plugins(RwtBrushPlugin::default());
    });
    let registry = app.world().resource::<AppTypeRegistry>().read();
    let component = |id: TypeId| {
        registry
            .get(id)
            .is_some_and(|r| r.data::<ReflectComponent>().is_some())
    };
    for id in [
        TypeId::of::<ScatterLayer>(),
        TypeId::of::<ScatterLayerSource>(),
        TypeId::of::<ScatterLayerStatus>(),
        TypeId::of::<ScatterEntity>(),
        TypeId::of::<ScatterEdits>(),
        TypeId::of::<Footprint>(),
        TypeId::of::<RwtViewer>(),
        TypeId::of::<InstancedChunk>(),
        TypeId::of::<Bender>(),
    ] {
        assert!(component(id), "{:?}", registry.get_type_info(id));
    }
    let resource = |id: TypeId| {
        registry
            .get(id)
            .is_some_and(|r| r.data::<ReflectResource>().is_some())
    };
    for id in [
        TypeId::of::<RwtSettings>(),
        TypeId::of::<RwtStats>(),
        TypeId::of::<RwtWind>(),
        TypeId::of::<RwtFadeIn>(),
        TypeId::of::<DensityBrush>(),
    ] {
        assert!(resource(id), "{:?}", registry.get_type_info(id));
    }
    assert!(registered::<ChunkLoaded>(&registry));
    assert!(registered::<DensityMapPainted>(&registry));
    assert!(registered::<EditInstance>(&registry));
    assert!(registered::<PaintDab>(&registry));
    // Field types come with the types that hold them.
    assert!(registered::<LayerDensity>(&registry));
    assert!(registered::<InstancedShading>(&registry));
    assert!(registered::<StreamingConfig>(&registry));
}

fn instances(app: &mut App) -> BTreeMap<PointId, Vec3> {
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    q.iter(app.world())
        .map(|(i, t)| (i.id, t.translation))
        .collect()
}

/// Sets `path` of `entity`'s layer to `value` through the type registry only, as an
/// inspector does.
fn set_by_reflection<T: Reflect>(app: &mut App, entity: Entity, path: &str, value: T) {
    let registry = app.world().resource::<AppTypeRegistry>().clone();
    let registry = registry.read();
    let reflect = registry
        .get_type_data::<ReflectComponent>(TypeId::of::<ScatterLayer>())
        .expect("ScatterLayer is registered with ReflectComponent");
    let mut entity = app.world_mut().entity_mut(entity);
    let mut layer = reflect.reflect_mut(&mut entity).expect("a layer");
    *layer.path_mut::<T>(path).expect("the path") = value;
}

#[test]
fn layer_settings_changed_through_reflection_scatter_anew() {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let entity = app
        .world_mut()
        .spawn(layer(LayerDensity::Constant(0.2)))
        .id();
    tick_app(&mut app, 2_000);
    let before = instances(&mut app);
    assert!(before.len() > 100);

    // Another seed: another layout (hardly a point in common), in as many instances.
    set_by_reflection(&mut app, entity, "seed", 77_u64);
    tick_app(&mut app, 2_000);
    let reseeded = instances(&mut app);
    let kept = reseeded
        .iter()
        .filter(|(id, p)| before.get(id) == Some(p))
        .count();
    assert!(kept * 10 < before.len(), "{kept} of {}", before.len());
    let ratio = reseeded.len() as f64 / before.len() as f64;
    assert!((0.8..1.25).contains(&ratio), "{ratio}");

    // Twice the density of the first class: about twice the instances, and the first
    // layout's points all kept (the denser set is a superset, paper section 5).
    set_by_reflection(&mut app, entity, "seed", 3_u64);
    set_by_reflection(&mut app, entity, "classes[0].density.0", 0.4_f64);
    tick_app(&mut app, 2_000);
    let denser = instances(&mut app);
    let ratio = denser.len() as f64 / before.len() as f64;
    assert!((1.8..2.2).contains(&ratio), "{ratio}");
    assert!(before.iter().all(|(id, p)| denser.get(id) == Some(p)));

    // The same settings again: the first layout, bit for bit.
    set_by_reflection(&mut app, entity, "classes[0].density.0", 0.2_f64);
    tick_app(&mut app, 2_000);
    assert_eq!(instances(&mut app), before);
}
