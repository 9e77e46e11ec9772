//! A chunk's points as the layer shows them: the query at the chunk's level of detail on
//! the layer's ground (its surfaces, their areas, the height and slope filters), then the
//! chunk's per-instance edits and footprints. Generation tasks make them so, and picking
//! makes them again for the chunks a ray crosses.

use super::discs::Discs;
use super::resolve::Sources;
use crate::edits::{Edit, EditSet};
use crate::footprints::GroundFootprint;
use crate::ground::{GroundRule, GroundSettings, Stands};
use crate::layers::{ScatterLayer, SharedDensity};
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use glam::DVec2;
use rwt_core::density::Scale;
use rwt_core::query::{Point, QueryError, Rect, Sampler};
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

/// What a game changed in a chunk: its per-instance edits and the footprints over it.
#[derive(Default)]
pub(crate) struct Changes {
    pub edits: Option<Arc<EditSet>>,
    pub footprints: Vec<GroundFootprint>,
}

/// Everything a layer's chunks are generated from (thread-safe, cheap to clone).
#[derive(Clone)]
pub(crate) struct Generator {
    pub sampler: Arc<Sampler>,
    pub densities: Vec<SharedDensity>,
    /// The layer's ground and how it grows on it.
    pub ground: GroundRule,
    /// The other layers whose instances clear this one.
    keep_out: Arc<[Clearing]>,
    classes: usize,
}

/// Class densities at a level-of-detail factor.
pub(crate) type Scaled = Vec<Scale<SharedDensity>>;

impl Generator {
    pub(super) fn new(
        layer: &ScatterLayer,
        sampler: Arc<Sampler>,
        sources: &Sources,
        keep_out: Arc<[Clearing]>,
    ) -> Self {
        Self {
            sampler,
            densities: sources.densities.clone(),
            ground: GroundRule::new(
                sources.ground.clone(),
                GroundSettings {
                    policy: layer.surfaces,
                    range: layer.height_range,
                    max_slope: layer.max_slope,
                    per_area: layer.per_area,
                    seed: layer.seed,
                },
            ),
            keep_out,
            classes: layer.classes.len(),
        }
    }

    /// The same generator without its keep-outs: what another layer's keep-out asks of it
    /// (a chain of keep-outs goes one layer deep).
    pub fn without_keep_out(&self) -> Self {
        Self {
            keep_out: Arc::from([]),
            ..self.clone()
        }
    }

    /// Whether both generate from the same sampler, densities and ground.
    pub fn same_as(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.sampler, &other.sampler)
            && Arc::ptr_eq(&self.ground.ground, &other.ground.ground)
            && self.densities.len() == other.densities.len()
            && self
                .densities
                .iter()
                .zip(&other.densities)
                .all(|(a, b)| Arc::ptr_eq(a, b))
    }

    /// Applies a set of edits of this layer to `out`.
    pub fn edit(&self, edits: &EditSet, out: &mut Vec<Point>) {
        EditSet::apply(edits, out, self.classes);
    }

    /// The class densities at level-of-detail `factor`, of classes `0..=last` (all of
    /// them for `None`).
    pub fn scaled(&self, factor: f64, last: Option<u16>) -> Scaled {
        let n = last.map_or(self.densities.len(), |l| {
            (l as usize + 1).min(self.densities.len())
        });
        self.densities[..n]
            .iter()
            .map(|d| Scale(d.clone(), factor))
            .collect()
    }

    /// The points of `rect` for the class densities `scaled` (all classes, or the first
    /// ones: the points of classes `0..=i` are exactly those of the sum of their densities),
    /// as the layer shows them after `changes`.
    pub fn points(
        &self,
        rect: Rect,
        scaled: &Scaled,
        changes: &Changes,
    ) -> Result<Vec<Point>, QueryError> {
        let mut out = self.ground.points(&self.sampler, rect, scaled)?;
        self.apply(rect, &mut out, changes)?;
        Ok(out)
    }

    /// [`Generator::points`], with the surfaces the query found them on (see
    /// [`GroundRule::stand_in`]).
    pub fn points_and_stands(
        &self,
        rect: Rect,
        scaled: &Scaled,
        changes: &Changes,
    ) -> Result<(Vec<Point>, Stands), QueryError> {
        let (mut out, stands) = self.ground.points_and_stands(&self.sampler, rect, scaled)?;
        self.apply(rect, &mut out, changes)?;
        Ok((out, stands))
    }

    /// The other layers' keep-outs, the chunk's edits, then its footprints.
    fn apply(&self, rect: Rect, out: &mut Vec<Point>, changes: &Changes) -> Result<(), QueryError> {
        for clearing in self.keep_out.iter() {
            clearing.clear(rect, out)?;
        }
        if let Some(edits) = &changes.edits {
            self.edit(edits, out);
        }
        if !changes.footprints.is_empty() {
            let cleared = |p: &Point| {
                changes
                    .footprints
                    .iter()
                    .any(|f| f.clears(p.position, p.class))
            };
            out.retain(|p| !cleared(p));
        }
        Ok(())
    }
}

impl Changes {
    /// Whether an edit gives some point another class: the points of the first classes
    /// alone may then miss one that an edit brings into them.
    pub fn reclasses(&self) -> bool {
        self.edits
            .as_ref()
            .is_some_and(|e| e.iter().any(|(_, edit)| matches!(edit, Edit::Reclass(_))))
    }
}

/// Another layer's points as they clear a layer ([`keep_out`](super::keep_out)): how
/// they are generated and edited.
#[derive(Clone)]
pub(crate) struct Clearing {
    pub generator: Generator,
    /// Per class of the other layer: how far its instances clear.
    pub radii: Arc<[f32]>,
    /// The other layer's chunk size and edits by chunk.
    pub chunk_size: f64,
    pub edits: HashMap<ChunkCoord, Arc<EditSet>>,
}

impl Clearing {
    /// The largest radius an instance of the other layer clears.
    pub fn reach(&self) -> f64 {
        self.radii.iter().fold(0.0f32, |m, r| m.max(*r)) as f64
    }

    /// Removes from `out` (the points of `rect`) every point within reach of an instance
    /// of the other layer.
    pub fn clear(&self, rect: Rect, out: &mut Vec<Point>) -> Result<(), QueryError> {
        let reach = self.reach();
        if reach <= 0.0 || out.is_empty() {
            return Ok(());
        }
        let grown = Rect::new(
            rect.min() - DVec2::splat(reach),
            rect.max() + DVec2::splat(reach),
        )
        .unwrap_or(rect);
        let g = &self.generator;
        let mut others = g.points(grown, &g.scaled(1.0, None), &Changes::default())?;
        for (chunk, set) in &self.edits {
            if chunk.rect(self.chunk_size).overlaps(&grown) {
                g.edit(set, &mut others);
            }
        }
        let discs = Discs::new(&others, &self.radii, reach);
        out.retain(|p| !discs.covers(p.position));
        Ok(())
    }
}
