//! The save plugin: [`SaveWorld`] and [`LoadWorld`] in, [`WorldSaved`] and [`WorldLoaded`]
//! out.

use super::files::{LayerEdits, SaveSources, load, save};
use super::{LoadWorld, SaveError, SaveWorld, WorldLoaded, WorldSaved};
use crate::edits::ScatterEdits;
use crate::layers::ScatterLayer;
use crate::layers::file::NamedAssets;
use crate::settings::{RwtSystems, configure_sets, in_schedule};
use crate::streaming::RwtTileSet;
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

/// Saves and loads worlds on request (see [`crate::save`]); part of [`crate::RwtPlugins`].
/// Its systems run in [`SaveSystems`], before
/// [`RwtSystems::Viewers`](crate::RwtSystems::Viewers) in the same schedule: a world loaded
/// in a frame streams with its edits from that frame on.
pub struct RwtSavePlugin {
    schedule: InternedScheduleLabel,
}

in_schedule!(RwtSavePlugin);

/// The save plugin's systems; a system that sends [`SaveWorld`] or [`LoadWorld`] and wants
/// the answer in the same frame runs before them.
#[derive(SystemSet, Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SaveSystems;

impl Plugin for RwtSavePlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        app.register_type::<SaveWorld>()
            .register_type::<LoadWorld>()
            .add_message::<SaveWorld>()
            .add_message::<LoadWorld>()
            .add_message::<WorldSaved>()
            .add_message::<WorldLoaded>()
            .configure_sets(self.schedule, SaveSystems.before(RwtSystems::Viewers))
            .add_systems(
                self.schedule,
                (save_worlds, load_worlds).chain().in_set(SaveSystems),
            );
    }
}

/// What saving and loading read besides the maps: the named layers and their edits, the
/// names of assets, the tile set the edits' identities refer to.
#[derive(SystemParam)]
struct WorldParts<'w, 's> {
    layers: Query<'w, 's, &'static ScatterLayer>,
    named: Query<
        'w,
        's,
        (
            Entity,
            &'static Name,
            &'static ScatterLayer,
            &'static ScatterEdits,
        ),
    >,
    /// Absent without [`crate::RwtLayersPlugin`]: then no layer file names an asset.
    names: Option<Res<'w, NamedAssets>>,
    tile_set: Option<Res<'w, RwtTileSet>>,
}

impl WorldParts<'_, '_> {
    /// Every named layer's edits.
    fn edits(&self) -> Result<Vec<LayerEdits<'_>>, SaveError> {
        let tile_set = self.tile_set.as_ref().ok_or(SaveError::NotStreaming)?;
        Ok(self
            .named
            .iter()
            .map(|(entity, name, layer, edits)| LayerEdits {
                name: name.to_string(),
                entity,
                edits: edits.edits(),
                stamp: tile_set.stamp(layer),
            })
            .collect())
    }

    fn layer_name(&self, layer: Entity) -> Option<String> {
        self.named.get(layer).ok().map(|n| n.1.to_string())
    }
}

fn save_worlds(
    mut requests: MessageReader<SaveWorld>,
    mut answers: MessageWriter<WorldSaved>,
    images: Res<Assets<Image>>,
    world: WorldParts,
) {
    let unnamed = NamedAssets::default();
    let names = world.names.as_deref().unwrap_or(&unnamed);
    for request in requests.read() {
        let result = world.edits().and_then(|edits| {
            let from = SaveSources {
                layers: &world.layers,
                layer_name: &|e| world.layer_name(e),
                names,
                images: &images,
                edits: &edits,
            };
            save(request, &from)
        });
        if let Err(e) = &result {
            warn!("rwt: saving to {}: {e}", request.dir.display());
        }
        answers.write(WorldSaved {
            dir: request.dir.clone(),
            result,
        });
    }
}

fn load_worlds(
    mut requests: MessageReader<LoadWorld>,
    mut answers: MessageWriter<WorldLoaded>,
    mut images: ResMut<Assets<Image>>,
    mut commands: Commands,
    world: WorldParts,
) {
    for request in requests.read() {
        let loaded = world
            .edits()
            .and_then(|edits| load(request, &world.layers, &mut images, &edits));
        let result = loaded.map(|loaded| {
            for (layer, set) in loaded.edits {
                commands.entity(layer).insert(ScatterEdits::new(set));
            }
            loaded.summary
        });
        if let Err(e) = &result {
            warn!("rwt: loading {}: {e}", request.dir.display());
        }
        answers.write(WorldLoaded {
            dir: request.dir.clone(),
            result,
        });
    }
}
