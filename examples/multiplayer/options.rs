//! The command line: which part to run, and its settings.

use crate::world::DEFAULT_PORT;
use std::fmt;
use std::net::{Ipv4Addr, SocketAddr, ToSocketAddrs};
use std::path::PathBuf;

/// How to call it.
pub const USAGE: &str = "usage: multiplayer [--port P] [--save DIR] [--detail D]
       multiplayer server [--port P] [--save DIR] [--detail D]
       multiplayer client [--name N] [--server HOST:PORT | --port P] [--detail D]";

/// The part to run.
#[derive(Clone, Debug, PartialEq)]
pub enum Role {
    /// A server and two players, each a process of its own.
    Launcher(ServerOptions),
    /// The server alone.
    Server(ServerOptions),
    /// One player.
    Client(ClientOptions),
}

/// The server's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ServerOptions {
    /// The UDP port it listens on (on 127.0.0.1).
    pub port: u16,
    /// Where it saves its world, and restores it from.
    pub save: PathBuf,
    /// The share of the vegetation that grows.
    pub detail: f64,
}

/// A player's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ClientOptions {
    /// Its name (the window's title, its log lines).
    pub name: String,
    /// The server's address.
    pub server: SocketAddr,
    /// The share of the vegetation that grows.
    pub detail: f64,
    /// What the player does by itself (the launcher's script).
    pub script: Option<ScriptRole>,
}

/// A scripted player's part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScriptRole {
    /// Chops three trees and asks for a cabin once joined.
    Chop,
    /// Only watches.
    Watch,
}

/// What is wrong with the command line.
#[derive(Clone, Debug, PartialEq)]
pub enum UsageError {
    /// An argument no part takes.
    Unknown(String),
    /// An option without its value.
    Missing(&'static str),
    /// An option whose value does not read.
    Invalid {
        /// The option.
        option: &'static str,
        /// Its value.
        value: String,
    },
}

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            UsageError::Unknown(arg) => write!(f, "unknown argument {arg:?}"),
            UsageError::Missing(option) => write!(f, "{option} needs a value"),
            UsageError::Invalid { option, value } => write!(f, "{option} {value:?} does not read"),
        }
    }
}

impl Role {
    /// Reads the arguments after the program's name.
    pub fn parse(args: &[String]) -> Result<Self, UsageError> {
        let (part, rest) = match args.first().map(String::as_str) {
            Some("server") => ("server", &args[1..]),
            Some("client") => ("client", &args[1..]),
            _ => ("launcher", args),
        };
        let from_env = std::env::var("RWT_DETAIL").ok();
        let mut server = ServerOptions {
            port: DEFAULT_PORT,
            save: PathBuf::from("multiplayer_world"),
            detail: from_env.as_deref().map_or(Ok(1.0), detail)?,
        };
        let mut name = "player".to_string();
        let mut address = None;
        let mut script = None;
        let mut args = rest.iter();
        while let Some(arg) = args.next() {
            let mut value = |option: &'static str| args.next().ok_or(UsageError::Missing(option));
            match (part, arg.as_str()) {
                (_, "--port") => server.port = parse("--port", value("--port")?)?,
                (_, "--detail") => server.detail = detail(value("--detail")?)?,
                ("server" | "launcher", "--save") => server.save = value("--save")?.into(),
                ("client", "--name") => name = value("--name")?.clone(),
                ("client", "--server") => address = Some(socket_address(value("--server")?)?),
                ("client", "--script") => script = Some(script_role(value("--script")?)?),
                _ => return Err(UsageError::Unknown(arg.clone())),
            }
        }
        Ok(match part {
            "server" => Role::Server(server),
            "client" => Role::Client(ClientOptions {
                name,
                server: address.unwrap_or((Ipv4Addr::LOCALHOST, server.port).into()),
                detail: server.detail,
                script,
            }),
            _ => Role::Launcher(server),
        })
    }
}

fn parse<T: std::str::FromStr>(option: &'static str, value: &str) -> Result<T, UsageError> {
    value.parse().map_err(|_| UsageError::Invalid {
        option,
        value: value.to_string(),
    })
}

/// A detail over 0 and at most 1.
fn detail(value: &str) -> Result<f64, UsageError> {
    let d: f64 = parse("--detail", value)?;
    match d > 0.0 && d <= 1.0 {
        true => Ok(d),
        false => Err(UsageError::Invalid {
            option: "--detail",
            value: value.to_string(),
        }),
    }
}

/// `HOST:PORT`, looked up.
fn socket_address(value: &str) -> Result<SocketAddr, UsageError> {
    let invalid = || UsageError::Invalid {
        option: "--server",
        value: value.to_string(),
    };
    let mut found = value.to_socket_addrs().map_err(|_| invalid())?;
    found.next().ok_or_else(invalid)
}

fn script_role(value: &str) -> Result<ScriptRole, UsageError> {
    match value {
        "chop" => Ok(ScriptRole::Chop),
        "watch" => Ok(ScriptRole::Watch),
        _ => Err(UsageError::Invalid {
            option: "--script",
            value: value.to_string(),
        }),
    }
}
