//! The documentation is true: every relative link of the README, the guide and the other
//! pages resolves (files and `#anchors`), every file, module and test that ARCHITECTURE.md
//! and TESTING.md name exists, and no page points outside the repository or at the
//! machine it was written on.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` (relative to the root), build outputs and Git's folder left out.
fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name == "target" || name == ".git" || name.starts_with(".venv") || name == "corpus" {
            continue;
        }
        if path.is_dir() {
            walk(&path, out);
        } else {
            out.push(path.strip_prefix(root()).unwrap().to_path_buf());
        }
    }
}

fn files() -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(&root(), &mut out);
    out
}

/// The Markdown pages users and contributors read.
fn pages() -> Vec<PathBuf> {
    files()
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .filter(|p| !p.starts_with("fuzz/artifacts"))
        .collect()
}

fn read(path: &Path) -> String {
    fs::read_to_string(root().join(path)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The text outside fenced code blocks.
fn prose(text: &str) -> String {
    let mut fenced = false;
    let mut out = String::new();
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// The targets of `[text](target)` links.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        rest = &rest[i + 2..];
        if let Some(end) = rest.find(')') {
            out.push(rest[..end].to_string());
        }
    }
    out
}

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

fn anchors(text: &str) -> BTreeSet<String> {
    prose(text)
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(|l| anchor(l.trim_start_matches('#')))
        .collect()
}

#[test]
fn every_relative_link_resolves() {
    let mut broken = Vec::new();
    for page in pages() {
        let text = read(&page);
        for link in links(&prose(&text)) {
            if link.contains("://") || link.starts_with("mailto:") {
                continue;
            }
            let (file, fragment) = link.split_once('#').unwrap_or((&link, ""));
            let target = if file.is_empty() {
                page.clone()
            } else {
                page.parent().unwrap().join(file)
            };
            let full = root().join(&target);
            if !full.exists() {
                broken.push(format!("{}: {link} (no such file)", page.display()));
            } else if !fragment.is_empty()
                && target.extension().is_some_and(|e| e == "md")
                && !anchors(&read(&target)).contains(fragment)
            {
                broken.push(format!("{}: {link} (no such heading)", page.display()));
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn no_page_points_outside_the_repository_or_at_a_machine() {
    let outside = [
        "../shared",
        "/work/",
        "/home/",
        "/tmp/",
        "farm-studio",
        "fnlen.py",
    ];
    let mut found = Vec::new();
    for page in pages() {
        for (n, line) in read(&page).lines().enumerate() {
            if let Some(bad) = outside.iter().find(|b| line.contains(*b)) {
                found.push(format!("{}:{}: {bad}", page.display(), n + 1));
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

/// The `code spans` of a page's prose and tables.
fn code_spans(text: &str) -> Vec<String> {
    prose(text)
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// Whether `span` names a file: a path with a known extension, no spaces or patterns.
fn is_file_name(span: &str) -> bool {
    const EXTENSIONS: [&str; 10] = [
        ".rs", ".md", ".sh", ".py", ".ron", ".png", ".toml", ".wgsl", ".pyi", ".glb",
    ];
    // A bare `name.png` or `name.ron` is a file a program writes, not one of the repository.
    let source = [".rs", ".md", ".sh", ".py", ".wgsl", ".pyi"];
    !span.contains(|c: char| " *<{$=:".contains(c))
        && EXTENSIONS.iter().any(|e| span.ends_with(e))
        && (span.contains('/') || source.iter().any(|e| span.ends_with(e)))
        && !span.starts_with('.')
}

/// The files of every module called `name`: `name.rs`, `name/mod.rs`, a file that declares
/// `mod name {` inline, an integration test `tests/name.rs`, or a crate's root.
fn module_files(all: &[PathBuf], name: &str) -> Vec<PathBuf> {
    let crate_root = match name {
        "rwt_core" => Some("crates/rwt_core/src/lib.rs"),
        "bevy_rwt" => Some("crates/bevy_rwt/src/lib.rs"),
        "rwt_py" => Some("crates/rwt_py/src/lib.rs"),
        _ => None,
    };
    let inline = format!("mod {name} {{");
    let mut out: Vec<PathBuf> = crate_root.map(|r| root().join(r)).into_iter().collect();
    for file in all
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "rs"))
    {
        let stem = file.file_stem().unwrap().to_string_lossy();
        let dir = file.parent().and_then(Path::file_name);
        let is_mod =
            (stem == name && stem != "mod") || (stem == "mod" && dir.is_some_and(|d| d == name));
        let full = root().join(file);
        if is_mod || fs::read_to_string(&full).is_ok_and(|t| t.contains(&inline)) {
            out.push(full);
        }
    }
    out
}

/// The files of a module: its own and every file under its folder.
fn module_text(file: &Path) -> String {
    let mut text = fs::read_to_string(file).unwrap_or_default();
    let dir = match file.file_name().and_then(|f| f.to_str()) {
        Some("mod.rs" | "lib.rs" | "main.rs") => file.parent().map(Path::to_path_buf),
        _ => file
            .to_str()
            .map(|f| PathBuf::from(f.trim_end_matches(".rs"))),
    };
    if let Some(dir) = dir.filter(|d| d.is_dir()) {
        let mut inner = Vec::new();
        walk(&dir, &mut inner);
        for f in inner {
            text.push_str(&fs::read_to_string(root().join(f)).unwrap_or_default());
        }
    }
    text
}

/// The file of module `name` inside the module whose file is `parent` (a `mod.rs`,
/// `lib.rs` or `name.rs`), or `None`; an inline `mod name {` resolves to its parent's file.
fn child_module(parent: &Path, name: &str) -> Option<PathBuf> {
    let dir = match parent.file_name()?.to_str()? {
        "mod.rs" | "lib.rs" | "main.rs" => parent.parent()?.to_path_buf(),
        file => parent.parent()?.join(file.trim_end_matches(".rs")),
    };
    for candidate in [
        dir.join(format!("{name}.rs")),
        dir.join(name).join("mod.rs"),
    ] {
        if candidate.exists() {
            return Some(candidate);
        }
    }
    let text = fs::read_to_string(parent).ok()?;
    text.contains(&format!("mod {name} {{"))
        .then(|| parent.to_path_buf())
}

/// Whether `path` (`module::sub::Item::method`, or `test_file::test_name`) names a chain of
/// modules of ours whose last one mentions the remaining items.
fn module_path_exists(all: &[PathBuf], path: &str) -> bool {
    let segments: Vec<&str> = path.split("::").collect();
    module_files(all, segments[0]).into_iter().any(|start| {
        let mut file = start;
        for (i, segment) in segments.iter().enumerate().skip(1) {
            match child_module(&file, segment) {
                Some(next) => file = next,
                None => {
                    let text = module_text(&file);
                    return segments[i..].iter().all(|s| mentions(&text, s));
                }
            }
        }
        true
    })
}

fn mentions(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + word.len()..].chars().next();
        let ident = |c: Option<char>| c.is_some_and(|c| c.is_alphanumeric() || c == '_');
        !ident(before) && !ident(after)
    })
}

/// A Rust path of ours worth resolving: lower-case segments joined by `::`, not an
/// external crate's.
fn is_module_path(span: &str) -> bool {
    const EXTERNAL: [&str; 12] = [
        "bevy", "std", "glam", "ron", "serde", "image", "noise", "spade", "rayon", "pyo3", "numpy",
        "naga",
    ];
    let first = span.split("::").next().unwrap_or("");
    span.contains("::")
        && !span.contains(|c: char| " (<{!.&=".contains(c))
        && first.chars().all(|c| c.is_ascii_lowercase() || c == '_')
        && !EXTERNAL.contains(&first)
}

/// A test function's name: lower case, at least four words.
fn is_test_name(span: &str) -> bool {
    span.matches('_').count() >= 3
        && span
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
}

#[test]
fn every_file_module_and_test_the_architecture_and_testing_pages_name_exists() {
    let all = files();
    let sources: String = all
        .iter()
        .filter(|p| {
            p.extension()
                .is_some_and(|e| e == "rs" || e == "py" || e == "sh")
        })
        .filter_map(|p| fs::read_to_string(root().join(p)).ok())
        .collect::<Vec<_>>()
        .join("\n");
    let mut missing = Vec::new();
    for page in ["docs/ARCHITECTURE.md", "TESTING.md", "CONTRIBUTING.md"] {
        let page = Path::new(page);
        let mut checked = 0;
        for span in code_spans(&read(page)) {
            let span = span.trim_end_matches("()").trim_end_matches('/');
            let ok = if is_file_name(span) {
                all.iter().any(|f| f.ends_with(span)) || page.parent().unwrap().join(span).exists()
            } else if is_module_path(span) {
                module_path_exists(&all, span)
            } else if is_test_name(span) {
                mentions(&sources, span)
            } else {
                continue;
            };
            checked += 1;
            if !ok {
                missing.push(format!("{}: `{span}`", page.display()));
            }
        }
        assert!(
            checked >= 10,
            "{}: only {checked} names checked",
            page.display()
        );
    }
    assert!(
        missing.is_empty(),
        "named but missing:\n{}",
        missing.join("\n")
    );
}

#[test]
fn the_checks_catch_what_they_are_for() {
    let all = files();
    assert!(module_path_exists(&all, "rwt_core::construction::seam"));
    assert!(module_path_exists(&all, "bevy_rwt::save::SaveWorld"));
    assert!(module_path_exists(
        &all,
        "save::a_world_that_does_not_stream_says_so"
    ));
    assert!(!module_path_exists(&all, "bevy_rwt::streaming::tests"));
    assert!(!module_path_exists(&all, "bevy_rwt::no_such_module"));
    assert!(!module_path_exists(&all, "persist::tests"));
    assert!(is_file_name("crates/bevy_rwt/tests/integration/save.rs") && !is_file_name("*.rs"));
    assert!(is_test_name(
        "parallel_queries_return_the_serial_points_in_the_serial_order"
    ));
    assert_eq!(
        anchor("Quality beside the references"),
        "quality-beside-the-references"
    );
    assert_eq!(
        anchor("The `rwt` CLI: 2 commands!"),
        "the-rwt-cli-2-commands"
    );
    assert_eq!(links("see [a](b.md#c) and [d](e)"), ["b.md#c", "e"]);
}

#[test]
fn the_readme_is_a_front_page() {
    let readme = read(Path::new("README.md"));
    let lines = readme.lines().count();
    assert!(
        lines <= 250,
        "README.md has {lines} lines: move detail into docs/guide/"
    );
    // The two set-up commands, and a way into the guide.
    for needed in [
        "cargo run --release --example open_world",
        "cargo test --workspace",
        "docs/guide/README.md",
    ] {
        assert!(readme.contains(needed), "README.md lacks {needed}");
    }
}
