//! Multiplayer: a server and players who all see the same streamed open world, where only
//! edits cross the network (`bevy_rwt_net` on bevy_replicon, over renet's netcode on UDP).
//!
//! `cargo run --release --example multiplayer` starts a server on 127.0.0.1 (its world saved
//! to `multiplayer_world/`) and two players' windows. Each player
//! - flies: WASD / arrows, Q / E down and up, Shift boosts, hold the right mouse button to
//!   look, the wheel sets the speed;
//! - left-clicks a tree to chop it: a stump stays, for every player;
//! - presses H to ask the server for a cabin 14 m ahead: it clears the ground for everyone;
//! - F1 hides the overlay.
//!
//! Close a window and start a player again (`-- client`): it joins with every chopped tree
//! and cabin. Stop the server and start it again: it loads its save, and the players
//! reconnect by themselves.
//!
//! The parts alone:
//! - `-- server [--port P] [--save DIR] [--detail D]`: the server, headless;
//! - `-- client [--name N] [--server HOST:PORT | --port P] [--detail D]`: a player.
//!
//! `--detail D` (0 < D <= 1; default `RWT_DETAIL`, else 1) grows that share of the
//! vegetation: a player whose world differs from the server's (another detail, another
//! version) is refused, told what differs.
//!
//! With `RWT_SCREENSHOT=PATH`, the one command plays a script instead (CI's smoke run):
//! player A chops three trees and asks for a cabin, B joins late, the server is stopped
//! once it saved and started again from its save, B reconnects, C joins and takes the
//! screenshot; it prints `rwt-multiplayer: agree players=3 edits=3 cabins=1 digest=H` when
//! the server and every player hold the same edits and cabins, and fails otherwise.

mod client;
mod launcher;
mod options;
mod script;
mod server;
mod world;

use options::Role;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let role = match Role::parse(&args) {
        Ok(role) => role,
        Err(error) => {
            eprintln!("{error}\n\n{}", options::USAGE);
            return ExitCode::from(2);
        }
    };
    let exit = match role {
        Role::Launcher(options) => return launcher::run(options),
        Role::Server(options) => server::run(options),
        Role::Client(options) => {
            let role = options.script;
            client::run(options, |app| {
                if let Some(role) = role {
                    script::plugin(app, role);
                }
            })
        }
    };
    match exit.is_success() {
        true => ExitCode::SUCCESS,
        false => ExitCode::FAILURE,
    }
}
