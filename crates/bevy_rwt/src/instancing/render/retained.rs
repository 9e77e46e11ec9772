//! Our items in Bevy's binned phases. Those phases are retained: an item stays until it is
//! removed. Every frame each view's visible chunks are binned anew (a pipeline may have
//! changed: a view's MSAA or prepasses, a mesh reloaded), and the chunks the view showed
//! last frame and no longer shows (culled, unloaded) are taken out.

use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_phase::{
    BinnedPhaseItem, BinnedRenderPhase, BinnedRenderPhaseType, InputUniformIndex,
};
use bevy::render::sync_world::{MainEntity, MainEntityHashSet};
use bevy::render::view::RetainedViewEntity;
use std::marker::PhantomData;

/// One phase item of a chunk: its batch set and bin keys, and its render and main entity.
pub(super) type BinnedChunk<P> = (
    <P as BinnedPhaseItem>::BatchSetKey,
    <P as BinnedPhaseItem>::BinKey,
    (Entity, MainEntity),
);

/// The chunks binned into phase `P`, per view, last frame.
#[derive(Resource)]
pub(in crate::instancing) struct Queued<P> {
    views: HashMap<RetainedViewEntity, MainEntityHashSet>,
    /// Views binned this frame (the others are forgotten at its end).
    seen: Vec<RetainedViewEntity>,
    phase: PhantomData<fn() -> P>,
}

impl<P> Default for Queued<P> {
    fn default() -> Self {
        Self {
            views: HashMap::default(),
            seen: Vec::new(),
            phase: PhantomData,
        }
    }
}

impl<P: BinnedPhaseItem> Queued<P> {
    /// Bins `chunks` into `view`'s `phase`, replacing what was binned for it last frame.
    pub fn rebin(
        &mut self,
        view: RetainedViewEntity,
        phase: &mut BinnedRenderPhase<P>,
        chunks: impl IntoIterator<Item = BinnedChunk<P>>,
    ) {
        let last = self.views.entry(view).or_default();
        let mut now = MainEntityHashSet::default();
        for (batch_set, bin, entities) in chunks {
            phase.remove(entities.1);
            phase.add(
                batch_set,
                bin,
                entities,
                InputUniformIndex::default(),
                BinnedRenderPhaseType::NonMesh,
            );
            now.insert(entities.1);
        }
        for gone in last.difference(&now) {
            phase.remove(*gone);
        }
        *last = now;
        self.seen.push(view);
    }

    /// The chunks binned into each view (by main entity).
    pub fn binned(&self) -> impl Iterator<Item = (&RetainedViewEntity, &MainEntityHashSet)> {
        self.views.iter()
    }

    /// Forgets the views not binned this frame (their phases are gone with them).
    pub fn end_frame(&mut self) {
        let seen = std::mem::take(&mut self.seen);
        self.views.retain(|view, _| seen.contains(view));
        self.seen = seen;
        self.seen.clear();
    }
}
