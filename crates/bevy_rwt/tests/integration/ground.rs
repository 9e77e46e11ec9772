//! Ground: layers on the game's meshes (`ScatterSurface`, `HeightSource::Surfaces`), surface
//! policies, surface-true density, stances, and re-scattering when a ground mesh moves.

use crate::common::*;
use bevy::asset::RenderAssetUsages;
use bevy::mesh::{Indices, PrimitiveTopology};
use bevy::prelude::*;
use bevy_rwt::ground::{ScatterSurface, SurfaceMesh, SurfacePolicy};
use bevy_rwt::prelude::*;
use bevy_rwt::rwt_core::query::PointId;
use std::collections::HashMap;
use std::sync::Arc;

/// Heights of a grid of `n x n` quads of side `step` from `origin`: the heightfield both
/// as a mesh and as a function.
struct Heightfield {
    origin: Vec2,
    step: f32,
    n: usize,
}

impl Heightfield {
    fn vertex_height(&self, i: usize, j: usize) -> f32 {
        let (x, z) = (i as f32 * 0.37, j as f32 * 0.29);
        1.5 * x.sin() + 0.8 * (z + 0.3 * x).cos()
    }

    /// The mesh: two triangles a quad, split along the (i, j) -> (i + 1, j + 1) diagonal,
    /// counter-clockwise seen from above.
    fn mesh(&self) -> Mesh {
        let n = self.n;
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let p = self.origin + Vec2::new(i as f32, j as f32) * self.step;
                positions.push([p.x, self.vertex_height(i, j), p.y]);
            }
        }
        let at = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut indices = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                indices.extend([a, c, b, a, d, c]);
            }
        }
        triangle_mesh(positions, indices)
    }

    /// The same surface as a function: the plane of the triangle holding the point.
    fn height(&self, p: Vec2) -> f32 {
        let g = (p - self.origin) / self.step;
        let (i, j) = (g.x.floor().max(0.0) as usize, g.y.floor().max(0.0) as usize);
        let (i, j) = (i.min(self.n - 1), j.min(self.n - 1));
        let (fx, fz) = (g.x - i as f32, g.y - j as f32);
        let h = |a: usize, b: usize| self.vertex_height(a, b);
        if fx >= fz {
            // Triangle (i, j), (i + 1, j), (i + 1, j + 1).
            h(i, j) + fx * (h(i + 1, j) - h(i, j)) + fz * (h(i + 1, j + 1) - h(i + 1, j))
        } else {
            // Triangle (i, j), (i + 1, j + 1), (i, j + 1).
            h(i, j) + fz * (h(i, j + 1) - h(i, j)) + fx * (h(i + 1, j + 1) - h(i, j + 1))
        }
    }
}

fn triangle_mesh(positions: Vec<[f32; 3]>, indices: Vec<u32>) -> Mesh {
    Mesh::new(
        PrimitiveTopology::TriangleList,
        RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_indices(Indices::U32(indices))
}

/// A flat rectangle `min..max` (x, z) at `height`, facing up, as two triangles.
fn quad(min: Vec2, max: Vec2, height: f32) -> Mesh {
    let positions = vec![
        [min.x, height, min.y],
        [max.x, height, min.y],
        [max.x, height, max.y],
        [min.x, height, max.y],
    ];
    triangle_mesh(positions, vec![0, 2, 1, 0, 3, 2])
}

fn add_mesh(app: &mut App, mesh: Mesh) -> Handle<Mesh> {
    app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh)
}

/// Marks `mesh` placed by `at` as ground.
fn spawn_surface(
    app: &mut App,
    mesh: Handle<Mesh>,
    at: Transform,
    marker: ScatterSurface,
) -> Entity {
    app.world_mut()
        .spawn((Mesh3d(mesh), at, GlobalTransform::from(at), marker))
        .id()
}

fn ground_app() -> App {
    create_app_with(|app| {
        app.init_asset::<Mesh>().init_asset::<StandardMaterial>();
    })
}

fn surface_layer(density: f64) -> ScatterLayer {
    layer(LayerDensity::Constant(density)).on_surfaces(SurfacePolicy::TopMost)
}

/// Every live instance by identity: its transform.
fn placed(app: &mut App) -> HashMap<PointId, Transform> {
    let mut q = app.world_mut().query::<(&ScatterEntity, &Transform)>();
    q.iter(app.world()).map(|(i, t)| (i.id, *t)).collect()
}

#[test]
fn a_triangulated_heightfield_gives_the_points_of_its_function() {
    let field = Arc::new(Heightfield {
        origin: Vec2::splat(-80.0),
        step: 2.0,
        n: 80,
    });
    let mut on_mesh = ground_app();
    let mesh = add_mesh(&mut on_mesh, field.mesh());
    spawn_surface(
        &mut on_mesh,
        mesh,
        Transform::IDENTITY,
        ScatterSurface::all(),
    );
    on_mesh
        .world_mut()
        .spawn(surface_layer(0.8).with_per_area(false));
    spawn_viewer(&mut on_mesh, Vec3::ZERO);
    tick_app(&mut on_mesh, 5_000);

    let mut on_function = ground_app();
    let f = field.clone();
    let height = HeightSource::Function(Arc::new(move |p| f.height(p)));
    on_function.world_mut().spawn(
        layer(LayerDensity::Constant(0.8))
            .with_height(height)
            .with_per_area(false),
    );
    spawn_viewer(&mut on_function, Vec3::ZERO);
    tick_app(&mut on_function, 5_000);

    let (a, b) = (placed(&mut on_mesh), placed(&mut on_function));
    assert!(a.len() > 5_000, "{} instances", a.len());
    let inside = |t: &Transform| t.translation.xz().abs().max_element() < 79.0;
    let a: HashMap<_, _> = a.into_iter().filter(|(_, t)| inside(t)).collect();
    let b: HashMap<_, _> = b.into_iter().filter(|(_, t)| inside(t)).collect();
    assert_eq!(a.len(), b.len());
    for (id, t) in &a {
        let u = b
            .get(id)
            .unwrap_or_else(|| panic!("{id:?} only on the mesh"));
        assert_eq!(t.translation.xz(), u.translation.xz());
        let dy = (t.translation.y - u.translation.y).abs();
        assert!(
            dy < 1e-4,
            "{id:?}: heights {} and {}",
            t.translation.y,
            u.translation.y
        );
    }
}

/// A level: a ground quad, a raised box (a rock: its top, and walls), a bridge deck (a
/// box, its top at 4) above the ground with a gap under it, and a tilted roof steeper than
/// the slope limit.
fn level(app: &mut App, rock_marker: ScatterSurface) -> [Entity; 4] {
    let ground = add_mesh(app, quad(Vec2::splat(-60.0), Vec2::splat(60.0), 0.0));
    let ground = spawn_surface(app, ground, Transform::IDENTITY, ScatterSurface::all());
    let rock = add_mesh(app, Cuboid::new(10.0, 3.0, 10.0).mesh().build());
    let rock = spawn_surface(
        app,
        rock,
        Transform::from_xyz(-20.0, 1.5, -20.0),
        rock_marker,
    );
    let deck = add_mesh(app, Cuboid::new(30.0, 1.0, 8.0).mesh().build());
    let deck_at = Transform::from_xyz(25.0, 3.5, 0.0);
    let deck = spawn_surface(app, deck, deck_at, ScatterSurface::all());
    let roof = add_mesh(app, Plane3d::new(Vec3::Y, Vec2::splat(5.0)).mesh().build());
    let steep = Transform::from_xyz(0.0, 6.0, 30.0).with_rotation(Quat::from_rotation_x(1.2));
    let roof = spawn_surface(app, roof, steep, ScatterSurface::all());
    [ground, rock, deck, roof]
}

/// The meshes of `app`'s marked entities, as ground.
fn surfaces_of(app: &mut App) -> Vec<SurfaceMesh> {
    let mut q = app
        .world_mut()
        .query_filtered::<(Entity, &Mesh3d, &GlobalTransform), With<ScatterSurface>>();
    let found: Vec<_> = q
        .iter(app.world())
        .map(|(e, m, t)| (e, m.0.clone(), *t))
        .collect();
    let meshes = app.world().resource::<Assets<Mesh>>();
    found
        .into_iter()
        .map(|(e, m, t)| {
            SurfaceMesh::from_mesh(meshes.get(&m).unwrap(), &t, GroundPlane::Xz, Some(e)).unwrap()
        })
        .collect()
}

/// Heights and slopes of every surface above `p`.
fn surfaces_above(meshes: &[SurfaceMesh], p: Vec2) -> Vec<(f32, f32)> {
    let mut out = Vec::new();
    for m in meshes {
        m.hits(p, &mut |h| out.push((h.height, h.slope())));
    }
    out
}

#[test]
fn instances_stand_on_the_meshes_and_never_on_walls() {
    for policy in [SurfacePolicy::TopMost, SurfacePolicy::Every] {
        let mut app = ground_app();
        level(&mut app, ScatterSurface::all());
        let layer = surface_layer(0.5).on_surfaces(policy).with_max_slope(1.0);
        app.world_mut().spawn(layer);
        spawn_viewer(&mut app, Vec3::ZERO);
        tick_app(&mut app, 5_000);
        let meshes = surfaces_of(&mut app);
        let placed = placed(&mut app);
        assert!(
            placed.len() > 1_000,
            "{policy:?}: {} instances",
            placed.len()
        );
        let mut on_deck = 0;
        let mut under_deck = 0;
        for (id, t) in &placed {
            let p = t.translation;
            let below = surfaces_above(&meshes, p.xz());
            let on = below.iter().find(|(h, _)| (h - p.y).abs() < 1e-3);
            let (_, slope) = on.unwrap_or_else(|| panic!("{policy:?} {id:?} floats at {p}"));
            assert!(
                *slope <= 1.0,
                "{policy:?} {id:?} at {p} on a slope of {slope}"
            );
            let top = below.iter().map(|(h, _)| *h).fold(f32::MIN, f32::max);
            if policy == SurfacePolicy::TopMost {
                assert_eq!(p.y, top, "{id:?} under a surface at {p}");
            }
            let deck = p.x > 10.5 && p.x < 39.5 && p.z.abs() < 3.5;
            on_deck += (deck && p.y > 3.9) as usize;
            under_deck += (deck && p.y < 0.1) as usize;
        }
        // 0.5 per square unit on 29 x 7 units of deck (and as much again under it).
        let expected = 0.5 * 29.0 * 7.0;
        assert!(
            (on_deck as f32 - expected).abs() < 0.1 * expected,
            "{policy:?}: {on_deck}"
        );
        match policy {
            SurfacePolicy::TopMost => assert_eq!(under_deck, 0),
            SurfacePolicy::Every => {
                let under = under_deck as f32;
                assert!(
                    (under - expected).abs() < 0.1 * expected,
                    "under the deck: {under}"
                )
            }
        }
    }
}

#[test]
fn a_surface_for_other_layers_covers_what_lies_under_it() {
    // Under every policy: grass never grows inside a rock, though the ground goes on there.
    for policy in [SurfacePolicy::TopMost, SurfacePolicy::Every] {
        let mut app = ground_app();
        let moss_only = ScatterSurface::for_layers([Entity::PLACEHOLDER]);
        let [_, rock, ..] = level(&mut app, moss_only);
        app.world_mut()
            .spawn(surface_layer(0.5).on_surfaces(policy));
        spawn_viewer(&mut app, Vec3::ZERO);
        tick_app(&mut app, 5_000);
        let rock_at = app.world().get::<Transform>(rock).unwrap().translation.xz();
        let placed = placed(&mut app);
        assert!(placed.len() > 1_000);
        for t in placed.values() {
            let d = (t.translation.xz() - rock_at).abs();
            let p = t.translation;
            assert!(
                d.max_element() > 5.0,
                "{policy:?}: grass inside the rock at {p}"
            );
        }
    }
}

/// A square plane of half side `half` through the origin, turned by `tilt`, as ground.
fn spawn_tilted_plane(app: &mut App, half: f32, tilt: Quat) {
    let plane = Plane3d::new(Vec3::Y, Vec2::splat(half)).mesh().build();
    let plane = add_mesh(app, plane);
    spawn_surface(
        app,
        plane,
        Transform::from_rotation(tilt),
        ScatterSurface::all(),
    );
}

/// Instances per unit of surface area on a plane tilted by `angle` about z, counted over
/// the plane's middle.
fn per_surface_area(angle: f32, on_mesh: bool) -> f64 {
    let mut app = ground_app();
    let density = 2.0;
    let tilt = Quat::from_rotation_z(angle);
    let layer = if on_mesh {
        spawn_tilted_plane(&mut app, 200.0, tilt);
        surface_layer(density)
    } else {
        let rise = angle.tan();
        layer(LayerDensity::Constant(density))
            .with_height(HeightSource::Function(Arc::new(move |p| p.x * rise)))
    };
    app.world_mut().spawn(layer);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 5_000);
    let side = 40.0;
    let count = placed(&mut app)
        .values()
        .filter(|t| t.translation.xz().abs().max_element() < side / 2.0)
        .count();
    count as f64 / (side as f64 * side as f64 / angle.cos() as f64)
}

#[test]
fn density_counts_per_unit_of_surface_area() {
    for on_mesh in [false, true] {
        let flat = per_surface_area(0.0, on_mesh);
        assert!(
            (flat / 2.0 - 1.0).abs() < 0.03,
            "flat: {flat} per square unit"
        );
        for degrees in [45.0f32, 60.0] {
            let tilted = per_surface_area(degrees.to_radians(), on_mesh);
            let ratio = tilted / flat;
            assert!(
                (ratio - 1.0).abs() < 0.03,
                "mesh {on_mesh}: {degrees} degrees gets {ratio} of the flat density"
            );
        }
    }
}

#[test]
fn stances_stand_along_the_normal_and_sink() {
    let mut app = ground_app();
    let tilt = Quat::from_rotation_z(0.5);
    spawn_tilted_plane(&mut app, 100.0, tilt);
    let mut layer = surface_layer(0.3);
    layer.classes[0] = layer.classes[0].clone().with_stance(1.0, 0.25);
    app.world_mut().spawn(layer);
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 5_000);
    let normal = tilt * Vec3::Y;
    let placed = placed(&mut app);
    assert!(placed.len() > 500);
    for t in placed.values() {
        let up = t.rotation * Vec3::Y;
        assert!(up.distance(normal) < 1e-4, "up {up}, normal {normal}");
        // Sunk a quarter unit below the plane, along its normal.
        let depth = -t.translation.dot(normal);
        assert!((depth - 0.25).abs() < 1e-3, "{} deep", depth);
    }
}

#[test]
fn instanced_classes_stand_along_the_normal_too() {
    let mut app = ground_app();
    let tilt = Quat::from_rotation_z(0.5);
    spawn_tilted_plane(&mut app, 100.0, tilt);
    let class = ScatterClass::instanced(
        LayerDensity::Constant(0.3),
        Handle::default(),
        InstancedShading::default(),
    )
    .with_stance(1.0, 0.25);
    let layer = layer(LayerDensity::Constant(0.0)).on_surfaces(SurfacePolicy::TopMost);
    app.world_mut().spawn(ScatterLayer {
        classes: vec![class],
        ..layer
    });
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 5_000);
    let normal = tilt * Vec3::Y;
    let mut q = app
        .world_mut()
        .query::<(&bevy_rwt::InstancedChunk, &Transform)>();
    let mut n = 0;
    for (chunk, at) in q.iter(app.world()) {
        for i in &chunk.buffer.instances {
            n += 1;
            let up = i.up();
            assert!(up.distance(normal) < 0.02, "up {up}, normal {normal}");
            // Its root sunk a quarter unit below the plane, along the normal.
            let root = at.translation + Vec3::from_array(i.offset);
            assert!((-root.dot(normal) - 0.25).abs() < 1e-3, "{root}");
        }
    }
    assert!(n > 500, "{n} instances");
}

/// Chunks loaded for `layer` whose rectangles overlap `rect` (min, max on the ground).
fn chunks_over(app: &App, layer: Entity, rects: &[(Vec2, Vec2)]) -> usize {
    let status = app.world().get::<ScatterLayerStatus>(layer).unwrap();
    let size = streaming().chunk_size as f32;
    status
        .loaded_chunks
        .iter()
        .filter(|c| {
            let lo = Vec2::new(c.x as f32, c.y as f32) * size;
            let hi = lo + Vec2::splat(size);
            rects
                .iter()
                .any(|(a, b)| lo.x <= b.x && a.x <= hi.x && lo.y <= b.y && a.y <= hi.y)
        })
        .count()
}

#[test]
fn moving_a_ground_mesh_rescatters_the_chunks_under_it_only() {
    let mut app = ground_app();
    let [_, rock, ..] = level(&mut app, ScatterSurface::all());
    let layer = app.world_mut().spawn(surface_layer(0.5)).id();
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 5_000);
    reloaded(&mut app, layer);
    let to = Transform::from_xyz(22.0, 1.5, -26.0);
    app.world_mut()
        .entity_mut(rock)
        .insert((to, GlobalTransform::from(to)));
    tick_app(&mut app, 5_000);
    let again = reloaded(&mut app, layer);
    // The rock's 10 x 10 ground rectangle before and after.
    let old = (Vec2::new(-25.0, -25.0), Vec2::new(-15.0, -15.0));
    let new = (Vec2::new(17.0, -31.0), Vec2::new(27.0, -21.0));
    let expected = chunks_over(&app, layer, &[old, new]);
    assert!(expected >= 2);
    assert_eq!(again.len(), expected, "re-scattered {again:?}");

    // The same world as a fresh start with the rock where it ended.
    let mut fresh = ground_app();
    let [_, fresh_rock, ..] = level(&mut fresh, ScatterSurface::all());
    fresh
        .world_mut()
        .entity_mut(fresh_rock)
        .insert((to, GlobalTransform::from(to)));
    fresh.world_mut().spawn(surface_layer(0.5));
    spawn_viewer(&mut fresh, Vec3::ZERO);
    tick_app(&mut fresh, 5_000);
    let (a, b) = (placed(&mut app), placed(&mut fresh));
    assert_eq!(a.len(), b.len());
    for (id, t) in &a {
        assert_eq!(Some(t), b.get(id), "{id:?}");
    }
}

/// The distinct chunks of `layer` loaded again since the messages were last drained.
fn reloaded(app: &mut App, layer: Entity) -> Vec<(i64, i64)> {
    let mut chunks: Vec<_> = app
        .world_mut()
        .resource_mut::<Messages<ChunkLoaded>>()
        .drain()
        .filter(|m| m.layer == layer)
        .map(|m| (m.chunk.x, m.chunk.y))
        .collect();
    chunks.sort();
    chunks.dedup();
    chunks
}

#[test]
fn adding_or_removing_a_ground_mesh_rescatters_the_chunks_under_it_only() {
    let mut app = ground_app();
    level(&mut app, ScatterSurface::all());
    let layer = app.world_mut().spawn(surface_layer(0.5)).id();
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 5_000);
    reloaded(&mut app, layer);
    // A 6 x 6 box over -12..-6 (x) and 6..12 (z): inside one chunk, and over two.
    for (x, expected) in [(-9.0, 1), (-1.0, 2)] {
        let rock = add_mesh(&mut app, Cuboid::new(6.0, 2.0, 6.0).mesh().build());
        let at = Transform::from_xyz(x, 0.5, 9.0);
        let rock = spawn_surface(&mut app, rock, at, ScatterSurface::all());
        tick_app(&mut app, 5_000);
        assert_eq!(
            reloaded(&mut app, layer).len(),
            expected,
            "adding at x = {x}"
        );
        app.world_mut().entity_mut(rock).despawn();
        tick_app(&mut app, 5_000);
        assert_eq!(
            reloaded(&mut app, layer).len(),
            expected,
            "removing at x = {x}"
        );
    }
}

#[test]
fn removing_the_ground_removes_what_stood_on_it() {
    let mut app = ground_app();
    let [_, _, deck, _] = level(&mut app, ScatterSurface::all());
    app.world_mut().spawn(surface_layer(0.5));
    spawn_viewer(&mut app, Vec3::ZERO);
    tick_app(&mut app, 5_000);
    let on_deck = |t: &&Transform| {
        let p = t.translation;
        p.y > 3.9 && p.x > 10.0 && p.x < 40.0 && p.z.abs() < 4.0
    };
    let high = |app: &mut App| placed(app).values().filter(on_deck).count();
    assert!(high(&mut app) > 50);
    app.world_mut().entity_mut(deck).remove::<ScatterSurface>();
    tick_app(&mut app, 5_000);
    assert_eq!(high(&mut app), 0);
}
