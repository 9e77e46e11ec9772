//! The smoke session's check, against the level's real meshes as the glTF loader made
//! them: a vertical ray through each instance finds every triangle above and below it.
//! An instance floats when no surface lies at its foot, is buried when more surfaces above
//! its foot face up than down (it stands inside a solid), and stands on a wall when its
//! surface is steeper than its layer allows. Prints
//! `rwt-smoke: ground instances I surfaces S floating F buried B steep W`.

use bevy::mesh::{Indices, VertexAttributeValues};
use bevy::prelude::*;
use bevy_rwt::instancing::InstancedChunk;
use bevy_rwt::{RwtStats, ScatterEntity, ScatterLayer};
use rwt_examples::prelude::*;
use rwt_examples::smoke::SmokeReport;
use std::collections::HashSet;

/// The level's triangles in world space, with the entity of each.
struct Triangles(Vec<([Vec3; 3], Entity)>);

impl Triangles {
    fn of(
        parts: &Query<(Entity, &Mesh3d, &GlobalTransform), With<LevelPart>>,
        meshes: &Assets<Mesh>,
    ) -> Option<Self> {
        let mut out = Vec::new();
        for (entity, mesh, at) in parts {
            let mesh = meshes.get(&mesh.0)?;
            let Some(VertexAttributeValues::Float32x3(p)) =
                mesh.attribute(Mesh::ATTRIBUTE_POSITION)
            else {
                continue;
            };
            let world: Vec<Vec3> = p
                .iter()
                .map(|v| at.transform_point(Vec3::from_array(*v)))
                .collect();
            let indices: Vec<usize> = match mesh.indices() {
                Some(Indices::U16(i)) => i.iter().map(|&i| i as usize).collect(),
                Some(Indices::U32(i)) => i.iter().map(|&i| i as usize).collect(),
                None => (0..world.len()).collect(),
            };
            for t in indices.chunks_exact(3) {
                out.push(([world[t[0]], world[t[1]], world[t[2]]], entity));
            }
        }
        (!out.is_empty()).then_some(Self(out))
    }

    /// Every surface the vertical line through `p` meets: height, unit normal, entity.
    fn vertical(&self, p: Vec2) -> Vec<(f32, Vec3, Entity)> {
        let mut hits = Vec::new();
        for ([a, b, c], e) in &self.0 {
            let (a2, b2, c2) = (a.xz(), b.xz(), c.xz());
            let area = (b2 - a2).perp_dot(c2 - a2);
            if area.abs() < 1e-9 {
                continue;
            }
            let w0 = (c2 - b2).perp_dot(p - b2) / area;
            let w1 = (a2 - c2).perp_dot(p - c2) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < -1e-5 || w1 < -1e-5 || w2 < -1e-5 {
                continue;
            }
            let height = w0 * a.y + w1 * b.y + w2 * c.y;
            hits.push((height, (*b - *a).cross(*c - *a).normalize(), *e));
        }
        hits
    }
}

/// What one instance stands on, as the check judges it.
#[derive(Default)]
pub struct Tally {
    instances: usize,
    surfaces: HashSet<Entity>,
    floating: usize,
    buried: usize,
    steep: usize,
}

impl Tally {
    /// Judges an instance whose foot is at `foot`, in a layer of slope limit `max_slope`.
    fn judge(&mut self, triangles: &Triangles, foot: Vec3, max_slope: f32) {
        self.instances += 1;
        let hits = triangles.vertical(foot.xz());
        let Some(on) = hits.iter().find(|(h, ..)| (h - foot.y).abs() < 0.02) else {
            self.floating += 1;
            eprintln!("rwt-smoke: floating at {foot} over {hits:?}");
            return;
        };
        self.surfaces.insert(on.2);
        // Inside a solid, more surfaces above face up (leaving it) than down (entering).
        let above = hits.iter().filter(|(h, ..)| *h > foot.y + 0.02);
        let winding: i32 = above
            .map(|(_, n, _)| (n.y > 0.0) as i32 - (n.y < 0.0) as i32)
            .sum();
        if winding > 0 {
            self.buried += 1;
            eprintln!("rwt-smoke: buried at {foot} under {hits:?}");
        }
        let n = on.1;
        let slope = if n.y > 0.0 {
            n.xz().length() / n.y
        } else {
            f32::INFINITY
        };
        if slope > max_slope + 1e-3 {
            self.steep += 1;
        }
    }
}

/// Marks the level's mesh entities, whose triangles the check reads.
#[derive(Component)]
pub struct LevelPart;

/// Whether the check ran, so that it runs once.
#[derive(Resource, Default)]
pub struct Checked(bool);

/// Once streaming has settled over the loaded level, checks every entity instance and
/// every hundredth instanced one (the ray test reads every triangle) and prints the line;
/// the screenshot waits for it.
#[allow(clippy::too_many_arguments)]
pub fn report(
    smoke: Res<Smoke>,
    stats: Res<RwtStats>,
    mut checked: ResMut<Checked>,
    mut hold: ResMut<SmokeReport>,
    parts: Query<(Entity, &Mesh3d, &GlobalTransform), With<LevelPart>>,
    meshes: Res<Assets<Mesh>>,
    layers: Query<&ScatterLayer>,
    entities: Query<(&ScatterEntity, &GlobalTransform)>,
    chunks: Query<(&InstancedChunk, &GlobalTransform)>,
) {
    if !smoke.active() || checked.0 {
        return;
    }
    hold.hold = true;
    let settled = stats.settled() && stats.live_instanced > 0;
    if !settled || smoke.frame < 30 {
        return;
    }
    let Some(triangles) = Triangles::of(&parts, &meshes) else {
        return;
    };
    let limit = |layer: Entity| {
        layers
            .get(layer)
            .ok()
            .and_then(|l| l.max_slope)
            .unwrap_or(3.9)
    };
    let mut tally = Tally::default();
    for (instance, at) in &entities {
        // Trees stand sunk into the ground along their up axis.
        let layer = layers.get(instance.layer).ok();
        let sink = layer.map_or(0.0, |l| l.classes[instance.class as usize].stance.sink);
        let foot = at.translation() + at.up() * sink;
        tally.judge(&triangles, foot, limit(instance.layer));
    }
    let mut n = 0usize;
    for (chunk, at) in &chunks {
        // Sunk instances stand upright here (the trees): their foot is above their root.
        let layer = layers.get(chunk.layer).ok();
        let sink = layer.map_or(0.0, |l| l.classes[chunk.class as usize].stance.sink);
        for i in &chunk.buffer.instances {
            n += 1;
            if n.is_multiple_of(100) {
                let foot = at.translation() + Vec3::from_array(i.offset) + Vec3::Y * sink;
                tally.judge(&triangles, foot, limit(chunk.layer));
            }
        }
    }
    let Tally {
        surfaces,
        floating,
        buried,
        steep,
        ..
    } = &tally;
    println!(
        "rwt-smoke: ground instances {} surfaces {} floating {floating} buried {buried} steep {steep}",
        stats.live_entities + stats.live_instanced,
        surfaces.len(),
    );
    println!(
        "rwt-smoke: ground checked {} instances by ray",
        tally.instances
    );
    checked.0 = true;
    hold.hold = false;
}
