//! The brush's and the world save's last answer, as a line for a HUD and as a result for a
//! script: what `BrushOutcome`, `WorldSaved` and `WorldLoaded` messages said last.

use bevy::prelude::*;
use bevy_rwt::brush::BrushOutcome;
use bevy_rwt::save::{WorldLoaded, WorldSaved};

/// The last answer: `Ok` with what was done, `Err` with why not (as text).
#[derive(Resource, Default, Debug)]
pub struct BrushStatus {
    /// The last answer, if any came since it was cleared.
    pub last: Option<Result<String, String>>,
}

impl BrushStatus {
    /// The answer as a HUD shows it.
    pub fn line(&self) -> String {
        match &self.last {
            Some(Ok(done)) => done.clone(),
            Some(Err(e)) => format!("failed: {e}"),
            None => String::new(),
        }
    }
}

/// Keeps [`BrushStatus`] (add it beside the brush).
pub struct BrushStatusPlugin;

impl Plugin for BrushStatusPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<BrushStatus>()
            .add_systems(PostUpdate, track);
    }
}

/// A folder as a HUD shows it: relative to the working directory when inside it (no
/// machine's paths in screenshots).
fn shown(dir: &std::path::Path) -> String {
    let cwd = std::env::current_dir().unwrap_or_default();
    dir.strip_prefix(&cwd).unwrap_or(dir).display().to_string()
}

/// What an answer of the world save says, for the HUD.
fn answered<T: std::fmt::Display, E: std::fmt::Display>(
    result: &Result<T, E>,
    place: &str,
) -> Result<String, String> {
    match result {
        Ok(done) => Ok(format!("{done} {place}")),
        Err(e) => Err(e.to_string()),
    }
}

fn track(
    mut status: ResMut<BrushStatus>,
    mut outcomes: MessageReader<BrushOutcome>,
    mut saved: MessageReader<WorldSaved>,
    mut loaded: MessageReader<WorldLoaded>,
) {
    for outcome in outcomes.read() {
        status.last = Some(match outcome {
            BrushOutcome::Undone { strokes_left } => {
                Ok(format!("undid a stroke ({strokes_left} left)"))
            }
            BrushOutcome::Failed(e) => Err(e.to_string()),
        });
    }
    for s in saved.read() {
        status.last = Some(answered(&s.result, &format!("to {}", shown(&s.dir))));
    }
    for l in loaded.read() {
        status.last = Some(answered(&l.result, &format!("from {}", shown(&l.dir))));
    }
}
