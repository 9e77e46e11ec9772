//! The README's commands are real: each subcommand exists and takes the options the README
//! gives it, and its first command runs as written.

mod common;

use common::{rwt, scratch};

/// The `rwt ...` lines of the README's shell block, comments cut, split into words.
fn readme_commands() -> Vec<Vec<String>> {
    let readme = include_str!("../README.md");
    readme
        .lines()
        .filter_map(|l| l.strip_prefix("rwt "))
        .map(|l| l.split("  #").next().unwrap_or(l))
        .map(|l| l.split_whitespace().map(str::to_string).collect())
        .collect()
}

#[test]
fn every_readme_command_names_real_subcommands_and_options() {
    let commands = readme_commands();
    assert!(commands.len() >= 5, "{commands:?}");
    let dir = scratch("readme");
    for words in &commands {
        let subcommands: Vec<&str> = words
            .iter()
            .take_while(|w| !w.starts_with('-') && !w.contains(['.', ':']))
            .map(String::as_str)
            .collect();
        let mut args = subcommands.clone();
        args.push("--help");
        let out = rwt(&dir, &args);
        let help = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "rwt {}: {help}", args.join(" "));
        for option in words.iter().filter(|w| w.starts_with("--")) {
            assert!(
                help.contains(option.as_str()),
                "rwt {words:?}: no {option} in\n{help}"
            );
        }
    }
    // The first command, as written: about 2 points per unit area over 100 x 100.
    let first = &commands[0];
    let args: Vec<&str> = first.iter().map(String::as_str).collect();
    let out = rwt(&dir, &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let written = std::fs::read_to_string(dir.join("points.txt")).unwrap();
    let points = written.lines().filter(|l| !l.starts_with('#')).count();
    assert!((19_000..21_000).contains(&points), "{points} points");
    std::fs::remove_dir_all(&dir).ok();
}
