//! The layers feature plugin: the layer file asset and its loader with the names it reads,
//! layer files applied to their entities, and the asset status of every layer.

use super::file::{NamedAssets, ScatterLayerAsset, ScatterLayerLoader, ScatterLayerSource};
use super::status::{AssetFailure, AssetProblem, LayerAsset, LoadFailure};
use super::{AssetStatus, ScatterLayer, ScatterLayerStatus};
use crate::settings::{RwtSystems, configure_sets, in_schedule};
use bevy::asset::LoadState;
use bevy::ecs::schedule::InternedScheduleLabel;
use bevy::prelude::*;

/// Layer files and asset status (part of [`crate::RwtPlugins`]).
pub struct RwtLayersPlugin {
    schedule: InternedScheduleLabel,
}

in_schedule!(RwtLayersPlugin);

impl Plugin for RwtLayersPlugin {
    fn build(&self, app: &mut App) {
        configure_sets(app, self.schedule);
        app.register_type::<ScatterLayer>()
            .register_type::<ScatterLayerSource>()
            .register_type::<ScatterLayerStatus>()
            .init_resource::<NamedAssets>()
            .add_systems(
                self.schedule,
                (apply_layer_assets, watch_layer_files)
                    .chain()
                    .in_set(RwtSystems::Viewers),
            );
    }

    fn finish(&self, app: &mut App) {
        init_image_assets(app);
        // The loader shares the registry of the resource (clones share it).
        let names = app.world().resource::<NamedAssets>().clone();
        app.init_asset::<ScatterLayerAsset>()
            .register_asset_loader(ScatterLayerLoader { names });
    }
}

/// Painted maps are `Image` assets: headless apps without the image plugin still get the
/// asset type (registering it twice would duplicate its systems).
pub(crate) fn init_image_assets(app: &mut App) {
    if !app.world().contains_resource::<Assets<Image>>() {
        app.init_asset::<Image>();
    }
}

/// Why an asset a layer reads is not there: `None` when it is loaded, else whether it is
/// still loading or failed.
pub(crate) fn missing_asset<A: Asset>(
    handle: &Handle<A>,
    loaded: bool,
    server: Option<&AssetServer>,
) -> Option<AssetStatus> {
    if loaded {
        return None;
    }
    let asset = LayerAsset::of(handle);
    Some(match load_failure(handle, server) {
        Some(why) => AssetStatus::Failed(vec![AssetFailure { asset, why }]),
        None => AssetStatus::Waiting(vec![asset]),
    })
}

/// The asset server's error, when `handle`'s last load failed.
fn load_failure<A: Asset>(
    handle: &Handle<A>,
    server: Option<&AssetServer>,
) -> Option<AssetProblem> {
    match server?.get_load_state(handle.id())? {
        LoadState::Failed(err) => Some(AssetProblem::Load(LoadFailure(err))),
        _ => None,
    }
}

/// Sets a layer's asset status, logging an error naming the layer and its assets when they
/// fail (once per failure).
pub(crate) fn report_assets(entity: Entity, status: &mut ScatterLayerStatus, assets: AssetStatus) {
    if status.assets == assets {
        return;
    }
    if let AssetStatus::Failed(failed) = &assets {
        let failed: Vec<String> = failed.iter().map(ToString::to_string).collect();
        error!(
            "rwt: layer {entity} shows nothing: cannot load {}",
            failed.join("; ")
        );
    }
    status.assets = assets;
}

/// Merges the reasons several assets are missing: any failure makes the layer failed.
pub(crate) fn merge_missing(missing: impl IntoIterator<Item = AssetStatus>) -> AssetStatus {
    let (mut waiting, mut failed) = (Vec::new(), Vec::new());
    for m in missing {
        match m {
            AssetStatus::Waiting(w) => waiting.extend(w),
            AssetStatus::Failed(f) => failed.extend(f),
            AssetStatus::Ready => {}
        }
    }
    if !failed.is_empty() {
        AssetStatus::Failed(failed)
    } else if !waiting.is_empty() {
        AssetStatus::Waiting(waiting)
    } else {
        AssetStatus::Ready
    }
}

/// Reports layer files that are still loading or failed to load on entities that have no
/// layer yet.
fn watch_layer_files(
    mut sources: Query<(
        Entity,
        &ScatterLayerSource,
        &mut ScatterLayerStatus,
        Has<ScatterLayer>,
    )>,
    assets: Res<Assets<ScatterLayerAsset>>,
    server: Option<Res<AssetServer>>,
) {
    for (entity, source, mut status, streaming) in &mut sources {
        let handle = &source.0;
        if !streaming {
            let missing = missing_asset(handle, assets.contains(handle), server.as_deref());
            report_assets(entity, &mut status, missing.unwrap_or_default());
            continue;
        }
        // A file that loaded once and then failed to reload: the layer keeps its previous
        // version, and says so.
        let failed = load_failure(handle, server.as_deref()).map(|why| AssetFailure {
            asset: LayerAsset::of(handle),
            why,
        });
        if status.layer_file_error != failed {
            if let Some(why) = &failed {
                error!("rwt: layer {entity} keeps its previous version: cannot reload {why}");
            }
            status.layer_file_error = failed;
        }
    }
}

/// Gives entities the layer of their source file when it loads, and again when it changes.
fn apply_layer_assets(
    mut events: MessageReader<AssetEvent<ScatterLayerAsset>>,
    sources: Query<(Entity, &ScatterLayerSource)>,
    added: Query<(Entity, &ScatterLayerSource), Added<ScatterLayerSource>>,
    assets: Res<Assets<ScatterLayerAsset>>,
    mut commands: Commands,
) {
    let changed: Vec<AssetId<ScatterLayerAsset>> = events
        .read()
        .filter_map(|e| match e {
            AssetEvent::Added { id } | AssetEvent::Modified { id } => Some(*id),
            _ => None,
        })
        .collect();
    for (entity, source) in &sources {
        let fresh = added.contains(entity);
        if (fresh || changed.contains(&source.0.id()))
            && let Some(asset) = assets.get(&source.0)
        {
            commands.entity(entity).insert(asset.0.clone());
        }
    }
}
