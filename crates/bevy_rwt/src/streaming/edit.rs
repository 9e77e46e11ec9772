//! Per-instance edits reach the chunk that holds the point: its generation tasks apply the
//! chunk's edits, and the entity look despawns or swaps an edited instance at once.

use super::{LayerState, RwtTileSet};
use crate::edits::{
    ConfirmedEdit, EditAuthority, EditError, EditInstance, EditOutcome, EditSet, InstanceEdit,
    ScatterEdits,
};
use crate::entities::Spawner;
use crate::layers::ScatterLayer;
use crate::settings::RwtSettings;
use bevy::platform::collections::HashMap;
use bevy::prelude::*;
use rwt_core::query::{Point, Sampler};
use rwt_core::streaming::ChunkCoord;
use std::sync::Arc;

/// Indexes replaced edit sets by chunk, then applies the frame's [`EditInstance`]s (where
/// this app has the [`EditAuthority`]) and [`ConfirmedEdit`]s, telling each one's
/// [`EditOutcome`].
#[allow(clippy::too_many_arguments)]
pub(super) fn apply_edits(
    mut messages: MessageReader<EditInstance>,
    mut confirmed: MessageReader<ConfirmedEdit>,
    authority: Res<EditAuthority>,
    mut outcomes: MessageWriter<EditOutcome>,
    mut layers: Query<(Entity, &ScatterLayer, &mut LayerState, &mut ScatterEdits)>,
    tile_set: Res<RwtTileSet>,
    settings: Res<RwtSettings>,
    mut commands: Commands,
) {
    let budget = settings.chunk_point_budget;
    for (_, layer, mut state, edits) in &mut layers {
        if edits.is_changed() || !state.edits_indexed {
            let sampler = state.sampler(layer, &tile_set.set, budget);
            index_edits(&mut state, layer, &sampler, edits.edits());
        }
    }
    let local = *authority == EditAuthority::Local;
    let game = messages.read().filter(|_| local);
    for message in game.chain(confirmed.read().map(|c| &c.0)) {
        let result = match layers.get_mut(message.layer) {
            Ok((entity, layer, mut state, mut edits)) => {
                let sampler = state.sampler(layer, &tile_set.set, budget);
                // Single edits do not count as a replaced set (see `index_edits`).
                let edits = edits.bypass_change_detection();
                let target = EditTarget {
                    entity,
                    layer,
                    state: &mut state,
                    sampler: &sampler,
                    edits,
                };
                apply_edit(&mut commands, target, message)
            }
            Err(_) => Err(EditError::NoLayer(message.layer)),
        };
        if let Err(e) = &result {
            warn!("scatter layer {}: edit refused: {e}", message.layer);
        }
        outcomes.write(EditOutcome {
            edit: *message,
            result,
        });
    }
}

/// The layer an edit applies to, and what the plugin keeps of it.
struct EditTarget<'a> {
    entity: Entity,
    layer: &'a ScatterLayer,
    state: &'a mut LayerState,
    sampler: &'a Sampler,
    edits: &'a mut ScatterEdits,
}

/// Makes the by-chunk index of a layer's (new) edits; the chunks the old or the new edits
/// touch are generated again.
fn index_edits(state: &mut LayerState, layer: &ScatterLayer, sampler: &Sampler, edits: &EditSet) {
    let size = layer.streaming.chunk_size;
    let mut by_chunk: HashMap<ChunkCoord, EditSet> = HashMap::new();
    for (id, edit) in edits.iter() {
        // An identity the tiling lacks names no point: it can never apply.
        if let Some(p) = sampler.locate(id) {
            let chunk = ChunkCoord::containing(p, size);
            // A share of a set that took these edits: it takes them too.
            let _ = by_chunk.entry(chunk).or_default().set(*id, *edit);
        }
    }
    let old = std::mem::take(&mut state.chunk_edits);
    for chunk in old.keys().chain(by_chunk.keys()) {
        state.mark_chunk_stale(*chunk);
    }
    state.chunk_edits = by_chunk
        .into_iter()
        .map(|(chunk, set)| (chunk, Arc::new(set)))
        .collect();
    state.edits_indexed = true;
}

/// Applies one edit: to the layer's set, to its chunk's set, and to what the looks show.
fn apply_edit(
    commands: &mut Commands,
    target: EditTarget,
    message: &EditInstance,
) -> Result<(), EditError> {
    let EditTarget {
        entity,
        layer,
        state,
        sampler,
        edits,
    } = target;
    let id = message.id;
    let position = sampler.locate(&id).ok_or(EditError::NoSuchPoint(id))?;
    let class = match message.edit {
        InstanceEdit::Reclass(class) => {
            let classes = layer.classes.len();
            if class as usize >= classes {
                return Err(EditError::NoSuchClass { class, classes });
            }
            Some(class)
        }
        _ => None,
    };
    edits.apply(id, message.edit)?;
    let chunk = ChunkCoord::containing(position, layer.streaming.chunk_size);
    // A chunk holds a share of the layer's edits: what the layer's set took, it takes.
    message.edit.apply_to(
        Arc::make_mut(state.chunk_edits.entry(chunk).or_default()),
        id,
    )?;
    let entity_class = class.filter(|c| !layer.classes[*c as usize].look.is_instanced());
    let generator = state.generator(layer);
    let shown = match (message.edit, entity_class, generator.as_ref()) {
        (InstanceEdit::Remove, _, _) => {
            state.entities.remove_now(commands, chunk, &id)
                || state.instanced.remove_now(commands, chunk, &id)
        }
        (InstanceEdit::Reclass(_), Some(class), Some(generator)) => {
            let spawner = Spawner {
                entity,
                layer,
                ground: &generator.ground,
            };
            let p = Point {
                position,
                id,
                threshold: 0.0,
                class,
            };
            state.entities.reclass_now(commands, &spawner, chunk, &p)
        }
        _ => false,
    };
    // Otherwise the point is instanced, restored, or not shown: its chunk is generated
    // again; so is a chunk drawing impostors, whose buffers show its points too.
    let impostors = layer.classes.iter().any(|c| c.impostor.is_some());
    if !shown || impostors {
        state.mark_chunk_stale(chunk);
    }
    Ok(())
}
