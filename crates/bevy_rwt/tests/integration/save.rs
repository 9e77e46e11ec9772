//! World saves without the brush: a game saves what the player chopped and the maps it
//! changed itself, and loads them into a fresh world.

use crate::common::*;
use bevy::prelude::*;
use bevy_rwt::edits::EditInstance;
use bevy_rwt::prelude::*;
use bevy_rwt::save::{
    INDEX_FILE, LoadSummary, PaintedMaps, SaveError, SaveSummary, WorldLoaded, WorldSaved,
};
use rwt_core::edits::EditsError;
use rwt_core::files::FileError;
use std::path::{Path, PathBuf};

/// A world of two named layers around the origin: a forest of constant density (its trees
/// are what the player chops) and a meadow read from a grey map (what the game repaints).
/// Returns the app and the meadow's map.
fn world() -> (App, NamedMap, Handle<Image>) {
    world_on(Lattice::Seeded)
}

/// [`world`] with its layers on `lattice`.
fn world_on(lattice: Lattice) -> (App, NamedMap, Handle<Image>) {
    let mut app = create_app();
    spawn_viewer(&mut app, Vec3::ZERO);
    let forest = layer(LayerDensity::Constant(0.3)).with_seed(11);
    app.world_mut()
        .spawn((Name::new("forest"), forest.with_lattice(lattice)));
    let (map, density) = gray_map(&mut app, 0.5);
    let meadow = app
        .world_mut()
        .spawn((Name::new("meadow"), layer(density).with_lattice(lattice)))
        .id();
    tick_app(&mut app, 2_000);
    (app, NamedMap::new(meadow, 0, "meadow"), map)
}

/// The player chops every `every`-th tree; returns how many.
fn chop(app: &mut App, every: usize) -> usize {
    let forest = named(app, "forest");
    let mut q = app.world_mut().query::<&ScatterEntity>();
    let mut trees: Vec<_> = q.iter(app.world()).filter(|e| e.layer == forest).collect();
    trees.sort_by_key(|e| e.id);
    let edits: Vec<_> = trees
        .iter()
        .step_by(every)
        .map(|e| EditInstance::remove(forest, e.id))
        .collect();
    let n = edits.len();
    app.world_mut().write_message_batch(edits);
    tick_app(app, 2_000);
    n
}

fn named(app: &mut App, name: &str) -> Entity {
    let mut q = app.world_mut().query::<(Entity, &Name)>();
    q.iter(app.world())
        .find(|(_, n)| n.as_str() == name)
        .map(|(e, _)| e)
        .unwrap()
}

fn save(app: &mut App, dir: &Path, maps: &[NamedMap]) -> Result<SaveSummary, SaveError> {
    let mut request = SaveWorld::to(dir).with_maps(maps.iter().cloned());
    // The test layers' mesh and material are not named assets: no layer files.
    request.layer_files = false;
    app.world_mut().write_message(request);
    app.update();
    let mut answers = app.world_mut().resource_mut::<Messages<WorldSaved>>();
    let answer = answers.drain().last().expect("the save answers");
    assert_eq!(answer.dir, dir);
    answer.result
}

fn load(app: &mut App, dir: &Path, maps: &[NamedMap]) -> Result<LoadSummary, SaveError> {
    let request = LoadWorld::from(dir).with_maps(maps.iter().cloned());
    app.world_mut().write_message(request);
    app.update();
    let mut answers = app.world_mut().resource_mut::<Messages<WorldLoaded>>();
    answers.drain().last().expect("the load answers").result
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rwt-save-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    dir
}

#[test]
fn a_world_with_chopped_trees_and_a_changed_map_saves_and_loads_without_the_brush() {
    let (mut app, meadow, map) = world();
    #[cfg(feature = "brush")]
    assert!(!app.is_plugin_added::<bevy_rwt::brush::RwtBrushPlugin>());
    let untouched = layered(&mut app);
    let chopped = chop(&mut app, 5);
    assert!(chopped > 20, "{chopped} trees chopped");
    // The game changes the meadow's map itself: a bright square.
    paint_square(&mut app, &map, 40, 40, Color::WHITE);
    tick_app(&mut app, 2_000);
    let played = layered(&mut app);
    assert_ne!(played, untouched);

    let dir = scratch("world");
    let saved = save(&mut app, &dir, std::slice::from_ref(&meadow)).unwrap();
    let expected = SaveSummary {
        maps: 1,
        layer_files: 0,
        edits: chopped,
    };
    assert_eq!(saved, expected);
    let index = PaintedMaps::read(&dir).unwrap();
    let files: Vec<&str> = index.edits.iter().map(|e| e.file.as_str()).collect();
    assert_eq!(files.len(), 2, "{files:?}");
    assert_eq!(index.maps[0].name, "meadow");

    // Another session: the same layers, untouched, get the played world back.
    let (mut fresh, meadow, _) = world();
    assert_eq!(layered(&mut fresh), untouched);
    let loaded = load(&mut fresh, &dir, &[meadow]).unwrap();
    assert_eq!(
        loaded,
        LoadSummary {
            maps: 1,
            edits: chopped
        }
    );
    tick_app(&mut fresh, 2_000);
    assert_eq!(layered(&mut fresh), played);

    // Loading the edits alone leaves the map as it is: the trees go, the meadow stays grey.
    let (mut edits_only, ..) = world();
    let loaded = load(&mut edits_only, &dir, &[]).unwrap();
    assert_eq!((loaded.maps, loaded.edits), (0, chopped));
    tick_app(&mut edits_only, 2_000);
    let kept = layered(&mut edits_only);
    assert_eq!(kept.len(), untouched.len() - chopped);
    assert!(kept.iter().all(|(id, p)| untouched.get(id) == Some(p)));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn failed_saves_and_loads_are_typed_and_change_nothing() {
    let (mut app, meadow, _) = world();
    chop(&mut app, 7);
    let before = layered(&mut app);
    let missing = scratch("missing");
    assert!(matches!(
        load(&mut app, &missing, std::slice::from_ref(&meadow)),
        Err(SaveError::File(FileError::Io { .. }))
    ));
    tick_app(&mut app, 2_000);
    assert_eq!(layered(&mut app), before);

    // Two maps of one name could not be told apart: refused, nothing written.
    let twins = scratch("twins");
    let err = save(&mut app, &twins, &[meadow.clone(), meadow.clone()]).unwrap_err();
    assert!(
        matches!(&err, SaveError::DuplicateMap { name } if name == "meadow"),
        "{err:?}"
    );
    assert!(!twins.exists());

    // A damaged edits file: named, and the world keeps its own edits.
    let dir = scratch("damaged");
    save(&mut app, &dir, &[]).unwrap();
    let index = PaintedMaps::read(&dir).unwrap();
    let forest = index.edits.iter().find(|e| e.layer == "forest").unwrap();
    let file = dir.join(&forest.file);
    let mut bytes = std::fs::read(&file).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 1;
    std::fs::write(&file, bytes).unwrap();
    let (mut other, ..) = world();
    let fresh = layered(&mut other);
    let err = load(&mut other, &dir, &[]).unwrap_err();
    assert!(
        matches!(&err, SaveError::Edits { file: f, .. } if *f == file),
        "{err:?}"
    );
    tick_app(&mut other, 2_000);
    assert_eq!(layered(&mut other), fresh);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_world_that_does_not_stream_says_so() {
    let plugins = RwtPlugins::default()
        .build()
        .disable::<RwtStreamingPlugin>();
    let mut app = bevy_rwt::testing::headless_app_with(plugins, |_| {});
    let dir = scratch("no-streaming");
    assert!(matches!(
        save(&mut app, &dir, &[]),
        Err(SaveError::NotStreaming)
    ));
    assert!(!dir.exists());
}

/// Rewrites a save as format 1 wrote it: no format in its index, edits files of format 1
/// (no lattice byte).
fn as_format_1(dir: &Path) {
    let index = dir.join(INDEX_FILE);
    let text = std::fs::read_to_string(&index).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| !l.contains("format:")).collect();
    assert!(lines.len() < text.lines().count(), "{text}");
    std::fs::write(&index, lines.join("\n")).unwrap();
    for saved in PaintedMaps::read(dir).unwrap().edits {
        let file = dir.join(&saved.file);
        let bytes = std::fs::read(&file).unwrap();
        let body = &bytes[..bytes.len() - 4];
        assert_eq!(body[4], rwt_core::edits::EDITS_FORMAT);
        let mut old = body[..4].to_vec();
        old.push(1);
        old.extend_from_slice(&body[6..]);
        let crc = crc32fast::hash(&old);
        old.extend_from_slice(&crc.to_le_bytes());
        std::fs::write(&file, old).unwrap();
    }
}

#[test]
fn a_save_of_format_1_loads_placed_as_before_or_is_refused_by_its_version() {
    let (mut app, ..) = world_on(Lattice::Aligned);
    let untouched = layered(&mut app);
    let chopped = chop(&mut app, 5);
    let played = layered(&mut app);
    let dir = scratch("format-1");
    save(&mut app, &dir, &[]).unwrap();
    as_format_1(&dir);
    assert_eq!(PaintedMaps::read(&dir).unwrap().format, 1);

    // Into the world it was made in (its layers on the aligned lattice): the same trees go.
    let (mut same, ..) = world_on(Lattice::Aligned);
    assert_eq!(layered(&mut same), untouched);
    assert_eq!(load(&mut same, &dir, &[]).unwrap().edits, chopped);
    tick_app(&mut same, 2_000);
    assert_eq!(layered(&mut same), played);

    // Into layers on their seeded lattices the trees would be others: refused, by version.
    let (mut seeded, ..) = world();
    let fresh = layered(&mut seeded);
    let err = load(&mut seeded, &dir, &[]).unwrap_err();
    assert!(
        matches!(
            &err,
            SaveError::Edits {
                error: EditsError::FormatLattice { version: 1, .. },
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("format 1"), "{err}");
    tick_app(&mut seeded, 2_000);
    assert_eq!(layered(&mut seeded), fresh);

    // A save of a newer format than this library reads: refused.
    let index = dir.join(INDEX_FILE);
    let text = std::fs::read_to_string(&index).unwrap();
    let newer = format!(
        "(format: 3,{}",
        text.trim_start().strip_prefix('(').unwrap()
    );
    std::fs::write(&index, newer).unwrap();
    let err = load(&mut seeded, &dir, &[]).unwrap_err();
    assert!(matches!(err, SaveError::Format { found: 3, .. }), "{err:?}");
    std::fs::remove_dir_all(&dir).ok();
}
