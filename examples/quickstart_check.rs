//! quickstart in the smoke session: the example's own `setup` and `orbit` under the
//! examples' harness (window size, screenshot, instance count, exit), so that quickstart
//! itself stays the smallest game, with nothing but `bevy` and `bevy_rwt`.
//!
//! `RWT_SCREENSHOT=shot.png cargo run --example quickstart_check` (`scripts/smoke.sh` runs it)

use bevy::prelude::*;
use bevy_rwt::prelude::*;
use rwt_examples::prelude::*;

#[path = "quickstart.rs"]
#[allow(
    dead_code,
    reason = "its `main` is the game's, replaced here by the harness's"
)]
mod quickstart;

fn main() {
    App::new()
        .add_plugins((example_plugins("rwt quickstart"), SmokePlugin))
        .add_plugins(RwtPlugins::default())
        .add_systems(Startup, quickstart::setup)
        .add_systems(Update, quickstart::orbit)
        .run();
}
