//! The one command: the server and the players as processes of this same program, their
//! lines echoed here (`[NAME] ...`). Interactive, it starts a server and two players and
//! stops the server when both windows are closed. Scripted (`RWT_SCREENSHOT`), it plays the
//! session the module's docs describe and checks that every world agrees.

use crate::options::ServerOptions;
use std::ffi::OsString;
use std::io::{BufRead, BufReader};
use std::process::{Child, Command, ExitCode, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender, channel};
use std::time::{Duration, Instant};

/// The longest one step of the script may take (debug builds on a software renderer).
const STEP: Duration = Duration::from_secs(900);
/// A world line that shows the script's chops and cabin.
const AGREED: &str = "edits=3 cabins=1 ";

/// Runs the interactive session, or the script when `RWT_SCREENSHOT` is set.
pub fn run(options: ServerOptions) -> ExitCode {
    // The players read the asset pack: written once, before any of them starts.
    rwt_examples::pack::write_pack();
    let result = match std::env::var_os("RWT_SCREENSHOT") {
        Some(shot) => scripted(&options, shot),
        None => interactive(&options),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("rwt-multiplayer: FAIL {error}");
            ExitCode::FAILURE
        }
    }
}

/// The server and two players; ends when both players' windows are closed.
fn interactive(options: &ServerOptions) -> Result<(), String> {
    let mut peers = Peers::new();
    let server = server_args(options);
    peers.start("server", &server, &[])?;
    peers.wait_for("server", "listening on", 0, Duration::from_secs(120))?;
    // Two windows side by side on a 1920-pixel screen, unless told another size.
    let window = std::env::var("RWT_WINDOW").unwrap_or_else(|_| "940x530".into());
    for name in ["A", "B"] {
        let args = client_args(options, name, None);
        peers.start(name, &args, &[("RWT_WINDOW", Some(window.as_str()))])?;
    }
    let mut server_up = true;
    while !(peers.exited("A") && peers.exited("B")) {
        peers.drain(Duration::from_millis(200));
        if server_up && peers.exited("server") {
            eprintln!("the server stopped: start it again with `-- server`");
            server_up = false;
        }
    }
    Ok(())
}

/// The scripted session: chops and a cabin, a late player, a server restarted from its
/// save, a reconnect and another late player; then every world must agree.
fn scripted(options: &ServerOptions, shot: OsString) -> Result<(), String> {
    let dir = std::env::temp_dir().join(format!("rwt-multiplayer-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let options = ServerOptions {
        save: dir.clone(),
        port: free_port()?,
        ..options.clone()
    };
    let mut peers = Peers::new();
    let quiet = [("RWT_SCREENSHOT", None), ("RWT_EXIT_AFTER_FRAMES", None)];
    peers.start("server", &server_args(&options), &quiet)?;
    peers.wait_for("server", "listening on", 0, STEP)?;
    peers.start("A", &client_args(&options, "A", Some("chop")), &quiet)?;
    let a = peers.wait_for("A", AGREED, 0, STEP)?;
    peers.start("B", &client_args(&options, "B", Some("watch")), &quiet)?;
    peers.wait_for("B", AGREED, 0, STEP)?;
    let saved = peers.wait_for("server", &format!("saved {AGREED}"), 0, STEP)?;
    peers.stop("A");

    // The server goes down once saved, and starts again from its save.
    peers.stop("server");
    let restart = peers.mark();
    peers.start("server", &server_args(&options), &quiet)?;
    let restored = peers.wait_for("server", &format!("restored {AGREED}"), restart, STEP)?;
    let b = peers.wait_for("B", AGREED, restart, STEP)?;
    let shot = shot.to_string_lossy().into_owned();
    let screenshot = [
        ("RWT_SCREENSHOT", Some(shot.as_str())),
        ("RWT_EXIT_AFTER_FRAMES", Some("60")),
    ];
    peers.start("C", &client_args(&options, "C", Some("watch")), &screenshot)?;
    let c = peers.wait_for("C", AGREED, restart, STEP)?;
    peers.wait_exit("C", STEP)?;
    let _ = std::fs::remove_dir_all(&dir);

    let digests: Vec<&str> = [&a, &b, &c, &saved, &restored]
        .iter()
        .map(|line| line.rsplit("digest=").next().unwrap_or(""))
        .collect();
    if digests.iter().any(|d| *d != digests[0]) {
        return Err(format!(
            "the worlds differ: A, B, C, saved, restored: {digests:?}"
        ));
    }
    println!(
        "rwt-multiplayer: agree players=3 {AGREED}digest={}",
        digests[0]
    );
    Ok(())
}

fn server_args(options: &ServerOptions) -> Vec<String> {
    vec![
        "server".into(),
        "--port".into(),
        options.port.to_string(),
        "--save".into(),
        options.save.display().to_string(),
        "--detail".into(),
        options.detail.to_string(),
    ]
}

fn client_args(options: &ServerOptions, name: &str, script: Option<&str>) -> Vec<String> {
    let mut args = vec![
        "client".into(),
        "--name".into(),
        name.into(),
        "--port".into(),
        options.port.to_string(),
        "--detail".into(),
        options.detail.to_string(),
    ];
    if let Some(role) = script {
        args.extend(["--script".into(), role.into()]);
    }
    args
}

/// A UDP port free on 127.0.0.1 now.
fn free_port() -> Result<u16, String> {
    let socket = std::net::UdpSocket::bind(("127.0.0.1", 0)).map_err(|e| e.to_string())?;
    socket
        .local_addr()
        .map(|a| a.port())
        .map_err(|e| e.to_string())
}

/// The child processes, and every line they printed.
struct Peers {
    children: Vec<(String, Child)>,
    lines: Vec<(String, String)>,
    sender: Sender<(String, String)>,
    receiver: Receiver<(String, String)>,
}

impl Peers {
    fn new() -> Self {
        let (sender, receiver) = channel();
        Self {
            children: Vec::new(),
            lines: Vec::new(),
            sender,
            receiver,
        }
    }

    /// Starts this program with `args` as `name`, with `env` set (`None`: removed); its
    /// scripted renet logs stay quiet (a restart's stale packets are logged as errors).
    fn start(
        &mut self,
        name: &str,
        args: &[String],
        env: &[(&str, Option<&str>)],
    ) -> Result<(), String> {
        let exe = std::env::current_exe().map_err(|e| e.to_string())?;
        let mut command = Command::new(exe);
        command.args(args).stdout(Stdio::piped());
        let log = std::env::var("RUST_LOG").unwrap_or_else(|_| "info".into());
        command.env("RUST_LOG", format!("{log},renetcode=off"));
        for (key, value) in env {
            match value {
                Some(v) => command.env(key, v),
                None => command.env_remove(key),
            };
        }
        let mut child = command
            .spawn()
            .map_err(|e| format!("cannot start {name}: {e}"))?;
        let stdout = child.stdout.take().expect("piped");
        let (sender, tag) = (self.sender.clone(), name.to_string());
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                println!("[{tag}] {line}");
                if sender.send((tag.clone(), line)).is_err() {
                    break;
                }
            }
        });
        self.children.retain(|(n, _)| n != name);
        self.children.push((name.to_string(), child));
        Ok(())
    }

    /// Where the next line will be.
    fn mark(&mut self) -> usize {
        self.drain(Duration::ZERO);
        self.lines.len()
    }

    /// Takes the lines that arrived, waiting up to `wait` for the first.
    fn drain(&mut self, wait: Duration) {
        match self.receiver.recv_timeout(wait) {
            Ok(line) => self.lines.push(line),
            Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => return,
        }
        self.lines.extend(self.receiver.try_iter());
    }

    /// The first line of `name` from line `from` on that contains `text`; an error when
    /// `name` exits or `timeout` passes first.
    fn wait_for(
        &mut self,
        name: &str,
        text: &str,
        from: usize,
        timeout: Duration,
    ) -> Result<String, String> {
        let start = Instant::now();
        loop {
            let found = self.lines[from.min(self.lines.len())..]
                .iter()
                .find(|(n, line)| n == name && line.contains(text));
            if let Some((_, line)) = found {
                return Ok(line.clone());
            }
            if self.exited(name) {
                self.drain(Duration::from_millis(100));
                return Err(format!("{name} stopped before it printed {text:?}"));
            }
            if start.elapsed() > timeout {
                return Err(format!("{name} did not print {text:?} in {timeout:?}"));
            }
            self.drain(Duration::from_millis(200));
        }
    }

    /// Waits for `name` to end with success.
    fn wait_exit(&mut self, name: &str, timeout: Duration) -> Result<(), String> {
        let start = Instant::now();
        while !self.exited(name) {
            if start.elapsed() > timeout {
                return Err(format!("{name} did not end in {timeout:?}"));
            }
            self.drain(Duration::from_millis(200));
        }
        let status = self.child(name).and_then(|c| c.try_wait().ok().flatten());
        match status {
            Some(s) if s.success() => Ok(()),
            other => Err(format!("{name} ended with {other:?}")),
        }
    }

    fn child(&mut self, name: &str) -> Option<&mut Child> {
        self.children
            .iter_mut()
            .find(|(n, _)| n == name)
            .map(|(_, c)| c)
    }

    /// Whether `name` has ended (or never started).
    fn exited(&mut self, name: &str) -> bool {
        self.child(name)
            .is_none_or(|c| c.try_wait().ok().flatten().is_some())
    }

    /// Stops `name`.
    fn stop(&mut self, name: &str) {
        if let Some(child) = self.child(name) {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

impl Drop for Peers {
    fn drop(&mut self) {
        for (_, child) in &mut self.children {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
