//! Imports point one way: no two top-level modules of a crate import each other, nor two
//! sibling files or folders at any depth (what docs/ARCHITECTURE.md promises for every
//! crate); the instanced renderer's `mod.rs` files declare, document and re-export only;
//! quickstart, the game users copy, names no crate but `bevy` and `bevy_rwt`.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

const CRATES: [&str; 5] = [
    "crates/rwt_core/src",
    "crates/bevy_rwt/src",
    "crates/bevy_rwt_net/src",
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

/// A file's code with its inline test module (`#[cfg(test)] mod tests { .. }`, at the end
/// by convention) and comment lines left out; declarations such as `#[cfg(test)] mod x;`
/// stay, as does what follows them.
fn code_outside_tests(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests {").next().unwrap_or("");
    text.lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The module path of a file under `src` (`a/b/mod.rs` and `a/b.rs` are both `a::b`).
fn module_path(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap();
    let mut parts: Vec<String> = rel
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().unwrap_or_default();
    if !matches!(last.as_str(), "mod.rs" | "lib.rs" | "main.rs") {
        parts.push(last.trim_end_matches(".rs").to_string());
    }
    parts
}

/// The identifiers of a path from `text` on: `a::b::c`, or `a::{b, c::d}` (the group's
/// top-level names each appended).
fn paths_from(text: &str) -> Vec<Vec<String>> {
    let mut prefix = Vec::new();
    let mut rest = text;
    loop {
        let ident = ident_at(rest);
        if ident.is_empty() {
            break;
        }
        prefix.push(ident.to_string());
        rest = rest.trim_start()[ident.len()..].trim_start();
        match rest.strip_prefix("::") {
            Some(after) => rest = after.trim_start(),
            None => return vec![prefix],
        }
    }
    let Some(group) = rest.strip_prefix(OPEN) else {
        return vec![prefix];
    };
    // The group alone, to its closing brace.
    let mut depth = 0;
    let end = group
        .char_indices()
        .find(|&(_, c)| {
            match c {
                OPEN => depth += 1,
                CLOSE if depth == 0 => return true,
                CLOSE => depth -= 1,
                _ => {}
            }
            false
        })
        .map_or(group.len(), |(i, _)| i);
    named_modules(&format!("crate::{{{}}}", &group[..end]))
        .into_iter()
        .map(|n| prefix.iter().cloned().chain([n]).collect())
        .collect()
}

/// The module paths a file at `module` names through `crate::`, `super::` and `self::`,
/// resolved from the crate's root.
fn resolved_paths(code: &str, module: &[String]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for start in ["crate::", "super::", "self::"] {
        for (i, _) in code.match_indices(start) {
            let before = code[..i].chars().next_back().unwrap_or(' ');
            if before.is_alphanumeric() || before == '_' || before == ':' {
                continue;
            }
            for path in paths_from(&code[i..]) {
                let mut base: Vec<String> = module.to_vec();
                let mut segments = path.into_iter().peekable();
                match segments.peek().map(String::as_str) {
                    Some("crate") => {
                        base.clear();
                        segments.next();
                    }
                    _ => {
                        while let Some(s) = segments.next_if(|s| s == "super" || s == "self") {
                            if s == "super" {
                                base.pop();
                            }
                        }
                    }
                }
                base.extend(segments);
                out.push(base);
            }
        }
    }
    out
}

/// Each module (file or folder) of the crate at `src` and the sibling modules it imports:
/// a file's import of another module counts for the two siblings under their nearest
/// common parent.
fn sibling_arrows(src: &Path) -> BTreeSet<(Vec<String>, Vec<String>)> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let is_module = |m: &[String]| {
        let path: PathBuf = m.iter().collect();
        src.join(&path).is_dir() || src.join(path).with_extension("rs").is_file()
    };
    let mut arrows = BTreeSet::new();
    for file in &files {
        let module = module_path(src, file);
        let code = code_outside_tests(&fs::read_to_string(file).unwrap());
        for target in resolved_paths(&code, &module) {
            let common = module
                .iter()
                .zip(&target)
                .take_while(|(a, b)| a == b)
                .count();
            if common >= module.len() || common >= target.len() {
                continue;
            }
            let from = module[..=common].to_vec();
            let to = target[..=common].to_vec();
            if is_module(&to) {
                arrows.insert((from, to));
            }
        }
    }
    arrows
}

#[test]
fn no_two_sibling_files_or_folders_import_each_other() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pairs = Vec::new();
    for krate in CRATES {
        let arrows = sibling_arrows(&root.join(krate));
        for (a, b) in &arrows {
            if a < b && arrows.contains(&(b.clone(), a.clone())) {
                pairs.push(format!("{krate}: {} <-> {}", a.join("/"), b.join("/")));
            }
        }
    }
    assert!(pairs.is_empty(), "two-way imports:\n{}", pairs.join("\n"));
}

#[test]
fn sibling_imports_are_resolved_from_super_and_crate_paths() {
    let module: Vec<String> = ["x", "render", "draw"].map(String::from).into();
    let code = "use super::{extract::A, prepare::B};\nuse crate::x::render::slab::C;\nuse super::super::chunk::D;";
    let paths = resolved_paths(code, &module);
    let joined: Vec<String> = paths.iter().map(|p| p.join("::")).collect();
    assert_eq!(
        joined,
        [
            "x::render::slab::C",
            "x::render::extract",
            "x::render::prepare",
            "x::chunk::D"
        ]
    );
}

/// The instanced renderer's `mod.rs` files hold declarations, documentation and
/// re-exports: every type and function lives in a leaf module of its stage.
#[test]
fn the_instanced_renderer_mod_files_define_nothing() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/bevy_rwt/src/instancing");
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    let item = [
        "struct ", "enum ", "fn ", "impl", "type ", "const ", "static ", "trait ",
    ];
    let mut defined = Vec::new();
    for file in files.iter().filter(|f| f.ends_with("mod.rs")) {
        for line in code_outside_tests(&fs::read_to_string(file).unwrap()).lines() {
            let bare = match line.strip_prefix("pub") {
                Some(rest) => rest.trim_start_matches(|c| c != ' ').trim_start(),
                None => line,
            };
            if item.iter().any(|k| bare.starts_with(k)) {
                defined.push(format!("{}: {line}", file.display()));
            }
        }
    }
    assert!(files.len() > 20, "{} files", files.len());
    assert!(
        defined.is_empty(),
        "items in mod.rs:\n{}",
        defined.join("\n")
    );
}

/// The crates a file's code names at the start of its paths: `use x::…` and `x::…`.
fn crates_named(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("::") {
        let before = &code[..i];
        let start = before
            .rfind(|c: char| !(c.is_alphanumeric() || c == '_'))
            .map_or(0, |s| s + 1);
        let preceded_by_path = before[..start].ends_with("::");
        let name = &before[start..];
        if !preceded_by_path && name.starts_with(|c: char| c.is_ascii_lowercase()) {
            out.insert(name.to_string());
        }
    }
    out
}

#[test]
fn the_smallest_game_uses_only_bevy_and_bevy_rwt() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = fs::read_to_string(root.join("examples/quickstart.rs")).unwrap();
    let named = crates_named(&code(&text));
    let allowed: BTreeSet<String> = ["bevy", "bevy_rwt", "std", "self", "super", "crate"]
        .into_iter()
        .map(String::from)
        .collect();
    assert!(named.contains("bevy") && named.contains("bevy_rwt"));
    let others: Vec<&String> = named.difference(&allowed).collect();
    assert!(others.is_empty(), "quickstart names {others:?}");
    // The check sees a harness import.
    let harness = crates_named("use rwt_examples::prelude::*; let x = glam::Vec2::ZERO;");
    assert!(harness.contains("rwt_examples") && harness.contains("glam"));
}
