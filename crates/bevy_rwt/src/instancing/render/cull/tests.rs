//! The culling shader's layout, its keep rules on the CPU, and the reach it tests.

use super::culler::WORKGROUP;
use super::params::{CullRecord, CullView};
use crate::instancing::chunk::GpuInstance;
use crate::instancing::render::extract::reach;
use crate::instancing::render::shader_check::{
    Space, cache_with_fade, cache_with_fade_reading, mark, marked_layout, marked_lod, struct_layout,
};
use crate::instancing::render::uniforms::LodUniform;
use bevy::asset::uuid::Uuid;
use bevy::camera::primitives::Aabb;
use bevy::prelude::*;
use bevy::shader::{Shader, ShaderCache, ShaderCacheSource};

#[test]
fn the_cull_shader_validates_and_reads_its_settings_as_rust_writes_them() {
    let types = composed_cull(cache_with_fade());
    // Each member's first word marked, then found in encase's bytes.
    let view = CullView {
        planes: [Vec4::splat(mark(0)); 6],
        receivers: [Vec4::splat(mark(1)); 6],
        light: Vec4::splat(mark(2)),
        clip_from_world: Mat4::from_cols_array(&[mark(3); 16]),
        eye: Vec3::splat(mark(4)),
        phase: 5,
        first_record: 6,
        records: 7,
        workgroups: 8,
        workgroups_x: 9,
    };
    let names = [
        "planes",
        "receivers",
        "light",
        "clip_from_world",
        "eye",
        "phase",
        "first_record",
        "records",
        "workgroups",
        "workgroups_x",
    ];
    assert_eq!(
        struct_layout(&types, "View"),
        marked_layout(&view, Space::Storage, &names, |k| k >= 5)
    );
    let record = CullRecord {
        origin: Vec3::splat(mark(0)),
        reach: mark(1),
        shadow_distance: mark(2),
        fade_in_from: mark(3),
        fade_out_to: mark(4),
        lod: LodUniform {
            falloff_near: mark(5),
            ..default()
        },
        instances: 6,
        first_instance: 7,
        first_workgroup: 8,
        kept: 9,
        late_kept: 10,
        count_word: 11,
        late_count_word: 12,
        first_mark: 13,
    };
    let names = [
        "origin",
        "reach",
        "shadow_distance",
        "fade_in_from",
        "fade_out_to",
        "lod",
        "instances",
        "first_instance",
        "first_workgroup",
        "kept",
        "late_kept",
        "count_word",
        "late_count_word",
        "first_mark",
    ];
    assert_eq!(
        struct_layout(&types, "Record"),
        marked_layout(&record, Space::Storage, &names, |k| k >= 6)
    );
    assert_eq!(struct_layout(&types, "Lod"), marked_lod());
}

/// The dispatches' workgroups are as large as the CPU lays them out by (`WORKGROUP`), as
/// naga reads the entry point.
#[test]
fn the_cull_shader_runs_workgroups_as_large_as_the_cpu_lays_out() {
    let cache = cache_with_fade_reading(|_, source, _| match source {
        ShaderCacheSource::Naga(module) => {
            let sizes: Vec<_> = module
                .entry_points
                .iter()
                .map(|e| e.workgroup_size)
                .collect();
            Ok(format!("{sizes:?}"))
        }
        _ => Ok(String::new()),
    });
    assert_eq!(composed_cull(cache), format!("[[{WORKGROUP}, 1, 1]]"));
}

/// What `cache` reads of `cull.wgsl`, composed and validated.
fn composed_cull(mut cache: ShaderCache<String, ()>) -> String {
    let id = AssetId::from(Uuid::from_u128(7));
    cache.set_shader(
        id,
        Shader::from_wgsl(include_str!("cull.wgsl"), "cull.wgsl"),
    );
    let read = cache.get(0, id, &[]);
    read.expect("cull.wgsl composes and validates").to_string()
}

/// The half-spaces of a view looking down +x from the origin: x > 0 and |z| < x (no near
/// or far plane).
pub(super) fn looking_down_x() -> [Vec4; 6] {
    [
        Vec4::new(1.0, 0.0, 0.0, 0.0),
        Vec4::new(1.0, 0.0, 1.0, 0.0).normalize(),
        Vec4::new(1.0, 0.0, -1.0, 0.0).normalize(),
        Vec4::W,
        Vec4::W,
        Vec4::W,
    ]
}

/// An instance at `offset` (from the chunk corner) of scale 1.
fn at(offset: Vec3, appear: f32) -> GpuInstance {
    GpuInstance {
        offset: offset.to_array(),
        scale: 1.0,
        appear: (appear * 65535.0) as u16,
        ..default()
    }
}

#[test]
fn an_instance_is_kept_where_its_sphere_meets_the_view_and_it_has_grown() {
    let view = CullView {
        planes: looking_down_x(),
        ..default()
    };
    let params = CullRecord {
        reach: 0.5,
        shadow_distance: -1.0,
        lod: LodUniform {
            falloff_near: 10.0,
            falloff_far: 20.0,
            falloff_on: 1,
            fade_band: 0.1,
            ..default()
        },
        ..default()
    };
    assert!(params.keeps(&view, &at(Vec3::new(5.0, 0.0, 0.0), 0.5)));
    // Behind the eye, or beside the view by more than its reach: culled.
    assert!(!params.keeps(&view, &at(Vec3::new(-1.0, 0.0, 0.0), 0.0)));
    assert!(!params.keeps(&view, &at(Vec3::new(3.0, 0.0, 4.0), 0.0)));
    // Beside it by less than its reach: kept.
    assert!(params.keeps(&view, &at(Vec3::new(3.0, 0.0, 3.3), 0.0)));
    // At 15 m the factor is 0.5: the instances of rank above it have not grown.
    assert!(params.keeps(&view, &at(Vec3::new(15.0, 0.0, 0.0), 0.45)));
    assert!(!params.keeps(&view, &at(Vec3::new(15.0, 0.0, 0.0), 0.55)));
    // Without the fade every rank is drawn.
    let no_fade = CullRecord {
        lod: LodUniform {
            falloff_on: 0,
            ..params.lod
        },
        ..params
    };
    assert!(no_fade.keeps(&view, &at(Vec3::new(15.0, 0.0, 0.0), 0.95)));
    // In a shadow view, beyond the class's shadow distance from the camera: culled.
    let shadow = CullRecord {
        shadow_distance: 8.0,
        ..no_fade
    };
    assert!(shadow.keeps(&view, &at(Vec3::new(8.4, 0.0, 0.0), 0.0)));
    assert!(!shadow.keeps(&view, &at(Vec3::new(8.6, 0.0, 0.0), 0.0)));
    // In a cascade read up to 6 m ahead, lit from above: what lies beyond casts nowhere.
    let cascade = CullView {
        receivers: [
            Vec4::W,
            Vec4::W,
            Vec4::W,
            Vec4::W,
            Vec4::W,
            Vec4::new(-1.0, 0.0, 0.0, 6.0),
        ],
        light: Vec4::new(0.0, -1.0, 0.0, 1.0),
        ..view
    };
    assert!(no_fade.keeps(&cascade, &at(Vec3::new(6.4, 0.0, 0.0), 0.0)));
    assert!(!no_fade.keeps(&cascade, &at(Vec3::new(6.6, 0.0, 0.0), 0.0)));
    let lit_along = CullView {
        light: Vec4::new(-1.0, 0.0, 0.0, 1.0),
        ..cascade
    };
    assert!(no_fade.keeps(&lit_along, &at(Vec3::new(6.6, 0.0, 0.0), 0.0)));
    // Thinned from 20 m: at 40 m a quarter is kept, the lowest ranks; nearer, all.
    let thinned = CullRecord {
        lod: LodUniform {
            thinning_from: 20.0,
            thinning_floor: 0.1,
            thinning_on: 1,
            ..no_fade.lod
        },
        ..no_fade
    };
    assert!(thinned.keeps(&view, &at(Vec3::new(40.0, 0.0, 0.0), 0.2)));
    assert!(!thinned.keeps(&view, &at(Vec3::new(40.0, 0.0, 0.0), 0.3)));
    assert!(thinned.keeps(&view, &at(Vec3::new(15.0, 0.0, 0.0), 0.99)));
    // Impostors fading in from 12 m: nearer ones are the meshes' to draw.
    let impostors = CullRecord {
        fade_in_from: 12.0,
        ..no_fade
    };
    assert!(!impostors.keeps(&view, &at(Vec3::new(11.9, 0.0, 0.0), 0.0)));
    assert!(impostors.keeps(&view, &at(Vec3::new(12.1, 0.0, 0.0), 0.0)));
    // A class's meshes, gone past the end of their crossfade with its impostors at 14 m.
    let meshes = CullRecord {
        fade_out_to: 14.0,
        ..no_fade
    };
    assert!(meshes.keeps(&view, &at(Vec3::new(13.9, 0.0, 0.0), 0.0)));
    assert!(!meshes.keeps(&view, &at(Vec3::new(14.1, 0.0, 0.0), 0.0)));
    // Down to the floor, however far.
    assert!(thinned.keeps(&view, &at(Vec3::new(900.0, 0.0, 0.0), 0.09)));
    assert!(!thinned.keeps(&view, &at(Vec3::new(900.0, 0.0, 0.0), 0.13)));
    // A widened instance is kept by a view it reaches into only widened (a fraction of
    // a quarter at 40 m: four times as wide).
    let beside = Vec3::new(40.0, 0.0, 40.0 + 1.2 * std::f32::consts::SQRT_2);
    assert!(thinned.keeps(&view, &at(beside, 0.0)));
    assert!(!no_fade.keeps(&view, &at(beside, 0.0)));
}

#[test]
fn the_reach_holds_every_vertex_turned_tilted_and_swaying() {
    // A blade 0.1 wide and 0.7 tall; instances up to 1.5 times its size.
    let (mesh_lo, mesh_hi) = (Vec3::new(-0.05, 0.0, -0.01), Vec3::new(0.05, 0.7, 0.04));
    let roots = (Vec3::new(0.0, -2.0, 0.0), Vec3::new(16.0, 3.0, 16.0));
    let max_scale = 1.5;
    // The chunk's bounds as `InstancedChunk::aabb` makes them.
    let reach_xz = mesh_lo.abs().max(mesh_hi.abs());
    let across = reach_xz.x.max(reach_xz.z) * std::f32::consts::SQRT_2;
    let horizontal = (across + reach_xz.y) * max_scale;
    let below = (mesh_lo.y.min(0.0) - across) * max_scale;
    let local = Aabb::from_min_max(
        roots.0 + Vec3::new(-horizontal, below, -horizontal),
        roots.1 + Vec3::new(horizontal, mesh_hi.y * max_scale, horizontal),
    );
    let r = reach(&local, roots, max_scale, true);
    let corners = (0..8).map(|i| {
        let pick = |bit: u32, lo: f32, hi: f32| if i >> bit & 1 == 1 { hi } else { lo };
        Vec3::new(
            pick(0, mesh_lo.x, mesh_hi.x),
            pick(1, mesh_lo.y, mesh_hi.y),
            pick(2, mesh_lo.z, mesh_hi.z),
        )
    });
    let corners: Vec<Vec3> = corners.collect();
    for k in 0..64u16 {
        // Tilted any way (up to 75 degrees), or upright and swaying by up to its height.
        let tilted = k % 2 == 1;
        let up = Vec3::new((k as f32 * 0.7).sin(), 1.0, (k as f32 * 1.3).cos()).normalize();
        let g = GpuInstance {
            yaw: k * 1021,
            tilt: if tilted { GpuInstance::pack_up(up) } else { 0 },
            ..default()
        };
        let sway = if tilted {
            Vec3::ZERO
        } else {
            Vec3::X * mesh_hi.y
        };
        for &c in &corners {
            let placed = g.rotation() * c + sway * (c.y / mesh_hi.y);
            assert!(placed.length() <= r, "{placed} beyond {r}");
        }
    }
    assert!(r < 2.0, "a reach of {r} culls nothing");
    assert_eq!(reach(&local, roots, max_scale, false), f32::MAX);
}
