//! Levels of detail from glTF's `MSFT_lod` extension: a node naming lower levels by index
//! (`"extensions": {"MSFT_lod": {"ids": [1, 2]}}`), with the screen coverage at which each
//! is shown as a hint in its extras (`"extras": {"MSFT_screencoverage": [0.5, 0.2, 0.01]}`).
//! Bevy's loader keeps neither: [`MsftLodHandler`] reads them as a file loads (and again
//! as it reloads) into the [`MsftLodTable`], by the file's path.

use bevy::asset::{AssetPath, LoadContext};
use bevy::gltf::GltfLoaderSettings;
use bevy::gltf::extensions::{ErasedGltfExtensionHandler, GltfExtensionHandler};
use bevy::gltf::gltf::{Document, Gltf as GltfDocument};
use bevy::platform::collections::{HashMap, HashSet};
use bevy::prelude::*;
use serde_json::Value;
use std::sync::{Arc, RwLock};

/// The most levels a node may name (a file naming more is read as naming the first ones).
pub const MAX_MSFT_LEVELS: usize = 16;

/// One node's `MSFT_lod`: its lower levels and their screen coverage hints.
#[derive(Clone, Debug, Default, PartialEq, Reflect)]
pub struct MsftLod {
    /// The nodes (indices in the file) of the levels after the node's own, nearest first.
    pub ids: Vec<usize>,
    /// `MSFT_screencoverage`: the fraction of the screen each level is shown down to, the
    /// node's own level first (one more than `ids` when the file gives them all: the last is
    /// where nothing is drawn). Empty when the file gives none or they are not fractions
    /// falling from 1 towards 0.
    pub coverage: Vec<f32>,
}

/// A file's `MSFT_lod` nodes, by node index (empty when it uses none).
#[derive(Clone, Debug, Default, PartialEq, Reflect)]
pub struct MsftLods {
    /// Each node with the extension.
    pub nodes: HashMap<usize, MsftLod>,
}

impl MsftLods {
    /// Reads the extension and its hints from a file's JSON.
    pub fn read(document: &Document) -> Self {
        let count = document.nodes().len();
        let nodes = document
            .nodes()
            .filter_map(|node| {
                let ext = node.extensions()?.get("MSFT_lod")?;
                let ids: Vec<usize> = ext
                    .get("ids")?
                    .as_array()?
                    .iter()
                    .filter_map(Value::as_u64)
                    .filter_map(|i| usize::try_from(i).ok())
                    .filter(|i| *i < count && *i != node.index())
                    .take(MAX_MSFT_LEVELS)
                    .collect();
                let extras = node.extras().as_ref().map(|raw| raw.get());
                let coverage = extras.map(coverage_hint).unwrap_or_default();
                Some((node.index(), MsftLod { ids, coverage }))
            })
            .collect();
        Self { nodes }
    }

    /// The nodes that are another node's lower level: never drawn as themselves.
    pub fn alternates(&self) -> HashSet<usize> {
        self.nodes
            .values()
            .flat_map(|l| l.ids.iter().copied())
            .collect()
    }
}

/// `MSFT_screencoverage` from a node's extras, when they are fractions falling from 1
/// towards 0 (anything else is no hint).
fn coverage_hint(extras: &str) -> Vec<f32> {
    let Ok(value) = serde_json::from_str::<Value>(extras) else {
        return Vec::new();
    };
    let Some(values) = value.get("MSFT_screencoverage").and_then(Value::as_array) else {
        return Vec::new();
    };
    let coverage: Option<Vec<f32>> = values
        .iter()
        .take(MAX_MSFT_LEVELS + 1)
        .map(|v| v.as_f64().map(|c| c as f32))
        .collect();
    let coverage = coverage.unwrap_or_default();
    let fractions = coverage.iter().all(|c| *c > 0.0 && *c <= 1.0);
    let falling = coverage.windows(2).all(|w| w[1] < w[0]);
    match fractions && falling {
        true => coverage,
        false => Vec::new(),
    }
}

/// Every glTF file's `MSFT_lod` as [`MsftLodHandler`] last read it, by the file's path (a
/// small entry per file loaded, replaced as it reloads).
#[derive(Resource, Clone, Default)]
pub struct MsftLodTable(Arc<RwLock<HashMap<AssetPath<'static>, Arc<MsftLods>>>>);

impl MsftLodTable {
    /// The `MSFT_lod` of the file at `path` (`None`: not loaded through Bevy's loader).
    pub fn get(&self, path: &AssetPath) -> Option<Arc<MsftLods>> {
        let table = self.0.read().ok()?;
        table.get(&path.clone_owned()).cloned()
    }

    fn insert(&self, path: AssetPath<'static>, lods: MsftLods) {
        if let Ok(mut table) = self.0.write() {
            table.insert(path, Arc::new(lods));
        }
    }
}

/// Reads every glTF file's `MSFT_lod` as it loads into its [`MsftLodTable`] (see the
/// module's page); registered by [`register`].
#[derive(Clone, Default)]
pub struct MsftLodHandler(pub MsftLodTable);

impl GltfExtensionHandler for MsftLodHandler {
    fn dyn_clone(&self) -> Box<dyn ErasedGltfExtensionHandler> {
        Box::new(self.clone())
    }

    fn on_root(
        &mut self,
        load_context: &mut LoadContext<'_>,
        gltf: &GltfDocument,
        _settings: &GltfLoaderSettings,
    ) {
        let path = load_context.path().without_label().into_owned();
        self.0.insert(path, MsftLods::read(&gltf.document));
    }
}

/// Adds the [`MsftLodTable`] and its [`MsftLodHandler`] to `app` (whether Bevy's glTF
/// plugin comes before or after: both share its handler list).
pub fn register(app: &mut App) {
    let table = MsftLodTable::default();
    app.insert_resource(table.clone())
        .init_resource::<bevy::gltf::extensions::GltfExtensionHandlers>();
    let handlers = app
        .world()
        .resource::<bevy::gltf::extensions::GltfExtensionHandlers>();
    let handler = Box::new(MsftLodHandler(table));
    #[cfg(not(target_family = "wasm"))]
    handlers.0.write_blocking().push(handler);
    #[cfg(target_family = "wasm")]
    bevy::tasks::block_on(async { handlers.0.write().await.push(handler) });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn document(json: &str) -> Document {
        GltfDocument::from_slice(json.as_bytes())
            .expect("a glTF document")
            .document
    }

    #[test]
    fn ids_and_coverage_are_read_and_nonsense_is_dropped() {
        let json = r#"{
            "asset": {"version": "2.0"},
            "nodes": [
                {"name": "High", "extensions": {"MSFT_lod": {"ids": [1, 2, 9, 0]}},
                 "extras": {"MSFT_screencoverage": [0.5, 0.2, 0.01]}},
                {"name": "Mid"}, {"name": "Low"},
                {"name": "Rock", "extensions": {"MSFT_lod": {"ids": [4]}},
                 "extras": {"MSFT_screencoverage": [0.2, 0.5]}},
                {"name": "RockLow"}
            ]
        }"#;
        let lods = MsftLods::read(&document(json));
        // Out of range and self references are no level.
        assert_eq!(lods.nodes[&0].ids, [1, 2]);
        assert_eq!(lods.nodes[&0].coverage, [0.5, 0.2, 0.01]);
        assert_eq!(lods.nodes[&3].ids, [4]);
        assert!(lods.nodes[&3].coverage.is_empty(), "rising: no hint");
        assert_eq!(lods.alternates(), HashSet::from_iter([1, 2, 4]));
        let plain = r#"{"asset": {"version": "2.0"}, "nodes": [{"name": "a"}]}"#;
        assert!(MsftLods::read(&document(plain)).nodes.is_empty());
    }
}
