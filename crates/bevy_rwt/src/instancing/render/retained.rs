//! Our items in Bevy's binned phases. Those phases are retained: an item stays until it is
//! removed. Every frame each view's visible chunks are binned by change: a chunk binned
//! last frame with the same keys (its pipeline, draw function, mesh slabs) stays as it is;
//! one whose keys changed (a view's MSAA or prepasses, a mesh reloaded) is moved to its new
//! bin; a new one is added; and the chunks the view showed last frame and no longer shows
//! (culled, unloaded) are taken out.

use crate::instancing::chunk::InstancedChunk;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use bevy::render::render_phase::{
    BinnedPhaseItem, BinnedRenderPhase, BinnedRenderPhaseType, InputUniformIndex,
    ViewBinnedRenderPhases,
};
use bevy::render::sync_world::{MainEntity, MainEntityHashMap};
use bevy::render::view::{ExtractedView, RenderVisibleEntities, RetainedViewEntity};

/// One phase item of a chunk: its batch set and bin keys, and its render and main entity.
pub(super) type BinnedChunk<P> = (
    <P as BinnedPhaseItem>::BatchSetKey,
    <P as BinnedPhaseItem>::BinKey,
    (Entity, MainEntity),
);

/// The bins a view's items go into: a phase, or anything that adds and removes the same way.
pub(in crate::instancing) trait Bins<K> {
    fn add(&mut self, keys: K, entities: (Entity, MainEntity));
    fn remove(&mut self, main: MainEntity);
}

impl<P: BinnedPhaseItem> Bins<(P::BatchSetKey, P::BinKey)> for BinnedRenderPhase<P> {
    fn add(&mut self, (batch_set, bin): (P::BatchSetKey, P::BinKey), e: (Entity, MainEntity)) {
        BinnedRenderPhase::add(
            self,
            batch_set,
            bin,
            e,
            InputUniformIndex::default(),
            BinnedRenderPhaseType::NonMesh,
        );
    }

    fn remove(&mut self, main: MainEntity) {
        BinnedRenderPhase::remove(self, main);
    }
}

/// What one view's rebinning did: items added (new or moved) and removed (gone or moved).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(in crate::instancing) struct Rebinned {
    pub added: usize,
    pub removed: usize,
}

/// The items binned into each view last frame, with their keys (`K`).
pub(in crate::instancing) struct Binned<K> {
    views: HashMap<RetainedViewEntity, MainEntityHashMap<(K, Entity)>>,
    /// Views binned this frame (the others are forgotten at its end).
    seen: Vec<RetainedViewEntity>,
}

impl<K> Default for Binned<K> {
    fn default() -> Self {
        Self {
            views: HashMap::default(),
            seen: Vec::new(),
        }
    }
}

impl<K: Clone + PartialEq> Binned<K> {
    /// Bins `items` into `view`'s `bins`, changing only what changed since last frame.
    pub fn rebin(
        &mut self,
        view: RetainedViewEntity,
        bins: &mut impl Bins<K>,
        items: impl IntoIterator<Item = (K, (Entity, MainEntity))>,
    ) -> Rebinned {
        let mut last = self.views.remove(&view).unwrap_or_default();
        let mut now = MainEntityHashMap::default();
        let mut done = Rebinned::default();
        for (keys, (entity, main)) in items {
            match last.remove(&main) {
                Some(was) if was == (keys.clone(), entity) => {}
                Some(_) => {
                    bins.remove(main);
                    bins.add(keys.clone(), (entity, main));
                    done.removed += 1;
                    done.added += 1;
                }
                None => {
                    bins.add(keys.clone(), (entity, main));
                    done.added += 1;
                }
            }
            now.insert(main, (keys, entity));
        }
        for gone in last.into_keys() {
            bins.remove(gone);
            done.removed += 1;
        }
        self.views.insert(view, now);
        self.seen.push(view);
        done
    }

    /// The items binned into each view (their render entities).
    pub fn binned(
        &self,
    ) -> impl Iterator<Item = (&RetainedViewEntity, impl Iterator<Item = Entity> + '_)> {
        self.views
            .iter()
            .map(|(view, items)| (view, items.values().map(|(_, entity)| *entity)))
    }

    /// Forgets the views not binned this frame (their phases are gone with them).
    pub fn end_frame(&mut self) {
        let seen = std::mem::take(&mut self.seen);
        self.views.retain(|view, _| seen.contains(view));
        self.seen = seen;
        self.seen.clear();
    }
}

/// The chunks binned into phase `P`, per view, last frame.
#[derive(Resource, Deref, DerefMut)]
pub(in crate::instancing) struct Queued<P: BinnedPhaseItem>(Binned<(P::BatchSetKey, P::BinKey)>);

impl<P: BinnedPhaseItem> Default for Queued<P> {
    fn default() -> Self {
        Self(Binned::default())
    }
}

impl<P: BinnedPhaseItem> Queued<P> {
    /// Bins `chunks` into `view`'s `phase`, changing only what changed since last frame.
    pub fn rebin_phase(
        &mut self,
        view: RetainedViewEntity,
        phase: &mut BinnedRenderPhase<P>,
        chunks: impl IntoIterator<Item = BinnedChunk<P>>,
    ) -> Rebinned {
        let items = chunks
            .into_iter()
            .map(|(batch_set, bin, entities)| ((batch_set, bin), entities));
        self.0.rebin(view, phase, items)
    }
}

/// Bins into each camera view's phase the chunks its CPU culling kept (by their `Aabb`)
/// that `item` makes an item of under the view's key (`key_of`; none binned while a view
/// has no key), and takes out what the views no longer show.
pub(super) fn rebin_cameras<P: BinnedPhaseItem, K: Copy>(
    phases: &mut ViewBinnedRenderPhases<P>,
    queued: &mut Queued<P>,
    views: &Query<(&ExtractedView, &RenderVisibleEntities)>,
    key_of: impl Fn(&RetainedViewEntity) -> Option<K>,
    mut item: impl FnMut(K, Entity, MainEntity) -> Option<BinnedChunk<P>>,
) {
    for (view, visible) in views {
        let Some(phase) = phases.get_mut(&view.retained_view_entity) else {
            continue;
        };
        let key = key_of(&view.retained_view_entity);
        let visible = visible
            .get::<InstancedChunk>()
            .map(|v| v.entities_cpu_culling.as_slice())
            .unwrap_or_default();
        let items: Vec<_> = visible
            .iter()
            .filter_map(|&(entity, main_entity)| item(key?, entity, main_entity))
            .collect();
        queued.rebin_phase(view.retained_view_entity, phase, items);
    }
    queued.end_frame();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bins that record what was done to them.
    #[derive(Default)]
    struct Log(Vec<String>);

    impl Bins<u32> for Log {
        fn add(&mut self, key: u32, (_, main): (Entity, MainEntity)) {
            self.0.push(format!("add {} {key}", main.index_u32()));
        }

        fn remove(&mut self, main: MainEntity) {
            self.0.push(format!("remove {}", main.index_u32()));
        }
    }

    fn item(key: u32, n: u32) -> (u32, (Entity, MainEntity)) {
        let entity = Entity::from_raw_u32(n).expect("a valid index");
        (key, (entity, MainEntity::from(entity)))
    }

    #[test]
    fn only_what_changed_is_rebinned() {
        let view = RetainedViewEntity::new(MainEntity::from(Entity::PLACEHOLDER), None, 0);
        let mut binned = Binned::<u32>::default();
        let mut log = Log::default();
        let first = binned.rebin(view, &mut log, [item(1, 10), item(1, 11), item(2, 12)]);
        assert_eq!((first.added, first.removed), (3, 0));
        // The same items again: nothing to do.
        log.0.clear();
        let same = binned.rebin(view, &mut log, [item(1, 10), item(1, 11), item(2, 12)]);
        assert_eq!((same, log.0.len()), (Rebinned::default(), 0));
        // 11 moves to bin 3, 12 is gone, 13 is new.
        let changed = binned.rebin(view, &mut log, [item(1, 10), item(3, 11), item(1, 13)]);
        assert_eq!((changed.added, changed.removed), (2, 2));
        log.0.sort();
        assert_eq!(log.0, ["add 11 3", "add 13 1", "remove 11", "remove 12"]);
        let mut now: Vec<u32> = binned
            .binned()
            .flat_map(|(_, entities)| entities)
            .map(|e| e.index_u32())
            .collect();
        now.sort();
        assert_eq!(now, [10, 11, 13]);
    }

    #[test]
    fn a_view_not_binned_in_a_frame_is_forgotten() {
        let view = RetainedViewEntity::new(MainEntity::from(Entity::PLACEHOLDER), None, 0);
        let mut binned = Binned::<u32>::default();
        let mut log = Log::default();
        binned.rebin(view, &mut log, [item(1, 10)]);
        binned.end_frame();
        assert_eq!(binned.binned().count(), 1);
        binned.end_frame();
        assert_eq!(binned.binned().count(), 0);
    }
}
