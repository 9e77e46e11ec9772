//! Imports point one way: no two top-level modules of a crate import each other (what
//! docs/ARCHITECTURE.md promises for every crate).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

const CRATES: [&str; 4] = [
    "crates/rwt_core/src",
    "crates/bevy_rwt/src",
    "crates/rwt_cli/src",
    "crates/rwt_py/src",
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file as it shapes the crate: test modules and comment lines left out.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// A use group's braces.
const OPEN: char = '{';
const CLOSE: char = '}';

fn ident_at(text: &str) -> &str {
    let text = text.trim_start();
    let end = text
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(text.len());
    &text[..end]
}

/// The top-level modules a file's code names through `crate::`.
fn named_modules(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let after = &code[i + "crate::".len()..];
        if let Some(group) = after.strip_prefix(OPEN) {
            // `crate::{a, b::c, d::{e, f}}`: the names at the group's top level.
            let mut depth = 0;
            let mut start = true;
            for (j, c) in group.char_indices() {
                match c {
                    OPEN => depth += 1,
                    CLOSE if depth == 0 => break,
                    CLOSE => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && !c.is_whitespace() => {
                        out.insert(ident_at(&group[j..]).to_string());
                        start = false;
                    }
                    _ => {}
                }
            }
        } else {
            out.insert(ident_at(after).to_string());
        }
    }
    out
}

/// Each top-level module of the crate at `src` and the top-level modules it imports.
fn module_arrows(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let top = |p: &Path| {
        let rel = p.strip_prefix(src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        first.trim_end_matches(".rs").to_string()
    };
    let modules: BTreeSet<String> = files
        .iter()
        .map(|p| top(p))
        .filter(|m| m != "lib" && m != "main")
        .collect();
    let mut arrows: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in &files {
        let from = top(file);
        if !modules.contains(&from) {
            continue;
        }
        let names = named_modules(&code(&fs::read_to_string(file).unwrap()));
        let to: Vec<String> = names
            .into_iter()
            .filter(|n| *n != from && modules.contains(n))
            .collect();
        arrows.entry(from).or_default().extend(to);
    }
    arrows
}

#[test]
fn no_two_modules_of_a_crate_import_each_other() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pairs = Vec::new();
    for krate in CRATES {
        let arrows = module_arrows(&root.join(krate));
        assert!(arrows.len() >= 3, "{krate}: {} modules", arrows.len());
        for (a, targets) in &arrows {
            for b in targets {
                if a < b && arrows.get(b).is_some_and(|t| t.contains(a)) {
                    pairs.push(format!("{krate}: {a} <-> {b}"));
                }
            }
        }
    }
    assert!(pairs.is_empty(), "two-way imports:\n{}", pairs.join("\n"));
}

#[test]
fn imports_are_read_from_paths_and_groups() {
    let uses = "use crate::a::X;\nuse crate::{b, c::{D, e}, f::G};\nfn x() { crate::h::y() }";
    let names: Vec<String> = named_modules(uses).into_iter().collect();
    assert_eq!(names, ["a", "b", "c", "f", "h"]);
    assert!(named_modules(&code("// crate::z\n#[cfg(test)]\nuse crate::t;")).is_empty());
}
