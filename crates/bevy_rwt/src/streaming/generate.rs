//! A chunk's points as the layer shows them: the query at the chunk's level of detail, the
//! height and slope filters, then the chunk's per-instance edits and footprints. Generation
//! tasks make them so, and picking makes them again for the chunks a ray crosses.

use super::resolve::Sources;
use crate::edits::{Edit, EditSet};
use crate::footprints::GroundFootprint;
use crate::layers::{HeightFn, ScatterLayer, SharedDensity, slope};
use bevy::prelude::*;
use rwt_core::density::Scale;
use rwt_core::query::{Point, QueryError, Rect, Sampler};
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
    pub height: HeightFn,
    range: Option<(f32, f32)>,
    max_slope: Option<f32>,
    classes: usize,
}

/// Class densities at a level-of-detail factor.
pub(crate) type Scaled = Vec<Scale<SharedDensity>>;

impl Generator {
    pub(super) fn new(layer: &ScatterLayer, sampler: Arc<Sampler>, sources: &Sources) -> Self {
        Self {
            sampler,
            densities: sources.densities.clone(),
            height: sources.height.clone(),
            range: layer.height_range,
            max_slope: layer.max_slope,
            classes: layer.classes.len(),
        }
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
        let mut out = Vec::new();
        let height = &self.height;
        self.sampler.query_classes(rect, scaled, |p| {
            let ground = Vec2::new(p.position.x as f32, p.position.y as f32);
            let in_range = self
                .range
                .is_none_or(|(lo, hi)| (lo..=hi).contains(&height(ground)));
            let flat_enough = self
                .max_slope
                .is_none_or(|m| slope(height, ground, 0.25) <= m);
            if in_range && flat_enough {
                out.push(p);
            }
        })?;
        if let Some(edits) = &changes.edits {
            EditSet::apply(edits, &mut out, self.classes);
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
        Ok(out)
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
