//! The documentation is true: every relative link of the README, the guide and the other
//! pages resolves (files and `#anchors`), every file, module and test that ARCHITECTURE.md
//! and TESTING.md name exists, and no page points outside the repository or at the
//! machine it was written on.

use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` (absolute paths), build outputs and Git's folder left out.
fn walk_absolute(dir: &Path, out: &mut Vec<PathBuf>) {
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
            walk_absolute(&path, out);
        } else {
            out.push(path);
        }
    }
}

/// Every file under `dir` (relative to the root), build outputs and Git's folder left out.
fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut found = Vec::new();
    walk_absolute(dir, &mut found);
    out.extend(
        found
            .into_iter()
            .map(|p| p.strip_prefix(root()).unwrap().to_path_buf()),
    );
}

/// The text of every file in `all` with one of `extensions`, where tests and functions
/// named by the pages must be found.
fn sources(all: &[PathBuf], extensions: &[&str]) -> String {
    all.iter()
        .filter(|p| {
            p.extension()
                .is_some_and(|e| extensions.iter().any(|x| e == *x))
        })
        .filter_map(|p| fs::read_to_string(root().join(p)).ok())
        .collect::<Vec<_>>()
        .join("\n")
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
        && !first.is_empty()
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
    let sources = sources(&all, &["rs", "py", "sh"]);
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

/// What users read besides the Markdown pages: the scripts (their comments and usage lines)
/// and the doc comments of the crates, the examples and their harness.
fn script_and_crate_docs() -> Vec<(PathBuf, String)> {
    let mut out = Vec::new();
    for file in files() {
        let text = || fs::read_to_string(root().join(&file)).unwrap_or_default();
        if file.starts_with("scripts") {
            out.push((file.clone(), text()));
        } else if file.extension().is_some_and(|e| e == "rs")
            && ["crates", "src", "examples"]
                .iter()
                .any(|top| file.starts_with(top))
        {
            let docs: Vec<String> = text()
                .lines()
                .map(str::trim_start)
                .filter(|l| l.starts_with("//!") || l.starts_with("///"))
                .map(|l| l[3..].to_string())
                .collect();
            out.push((file.clone(), docs.join("\n")));
        }
    }
    out
}

/// The words of `text`, split at spaces, quotes, brackets and punctuation that ends a path.
fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| c.is_whitespace() || "`'\"()[]{}<>,;|=".contains(c))
        .map(|w| w.trim_end_matches(['.', ':']))
        .filter(|w| !w.is_empty())
}

/// The problems with the repository paths, examples, benches and tests that `text` (of the
/// file `at`) names: each must exist.
fn missing_names(text: &str, at: &Path, all: &[PathBuf]) -> Vec<String> {
    const TOPS: [&str; 8] = [
        "scripts/",
        "examples/",
        "tests/",
        "docs/",
        "crates/",
        "assets/",
        "fuzz/",
        "src/",
    ];
    const EXTENSIONS: [&str; 9] = [
        ".rs", ".md", ".sh", ".py", ".ron", ".png", ".toml", ".wgsl", ".pyi",
    ];
    let exists = |path: &str| {
        root().join(path).exists()
            || at
                .parent()
                .is_some_and(|d| root().join(d).join(path).exists())
            || all.iter().any(|f| f.ends_with(path))
    };
    let mut out = Vec::new();
    let tokens: Vec<&str> = words(text).collect();
    for (i, word) in tokens.iter().enumerate() {
        let path = word.trim_start_matches("./");
        if TOPS.iter().any(|t| path.starts_with(t))
            && EXTENSIONS.iter().any(|e| path.ends_with(e))
            && !path.contains(['*', '$'])
            && !exists(path)
        {
            out.push(format!("{}: no file {path}", at.display()));
        }
        let target = |kind: &str| match tokens.get(i + 1) {
            // `NAME` and `$ex` are placeholders.
            Some(name)
                if *word == kind
                    && !name.contains(['$', '-'])
                    && !name.contains(|c: char| c.is_ascii_uppercase()) =>
            {
                Some(*name)
            }
            _ => None,
        };
        let targets = [
            ("--example", "examples"),
            ("--bench", "benches"),
            ("--test", "tests"),
        ];
        for (kind, folder) in targets {
            let Some(name) = target(kind) else { continue };
            let found = all.iter().any(|f| {
                f.components().any(|c| c.as_os_str() == folder)
                    && (f.ends_with(format!("{name}.rs")) || f.ends_with(format!("{name}/main.rs")))
            });
            if !found {
                out.push(format!("{}: no {kind} target {name}", at.display()));
            }
        }
    }
    out
}

#[test]
fn every_script_example_test_and_file_the_docs_name_exists() {
    let all = files();
    let sources = sources(&all, &["rs", "py"]);
    let mut missing = Vec::new();
    let mut texts: Vec<(PathBuf, String)> = pages()
        .into_iter()
        .map(|p| {
            let text = read(&p);
            (p, text)
        })
        .collect();
    texts.extend(script_and_crate_docs());
    for (file, text) in &texts {
        missing.extend(missing_names(text, file, &all));
        // Tests by name, on the users' pages that point at them (ARCHITECTURE, TESTING and
        // CONTRIBUTING are read by the test above; the notes pages also name functions of
        // Mesa and fields the benches print).
        if file.starts_with("docs/guide") || file == Path::new("README.md") {
            for span in code_spans(text).iter().filter(|s| is_test_name(s)) {
                if !mentions(&sources, span) {
                    missing.push(format!("{}: no test or function {span}", file.display()));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "named but missing:\n{}",
        missing.join("\n")
    );
}

/// The names of the types, traits and enum variants that `text` (Rust source) defines:
/// those it makes `pub` go to `public`, all to `defined`.
fn type_names(text: &str, public: &mut BTreeSet<String>, defined: &mut BTreeSet<String>) {
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut in_enum = 0usize;
    let mut depth = 0usize;
    let mut in_public_enum = false;
    for line in text.lines() {
        let line = line.trim();
        let (is_pub, item) = match line.strip_prefix("pub ") {
            Some(rest) => (true, rest),
            None => (false, line.split_once(") ").map_or(line, |(_, r)| r)),
        };
        for keyword in ["struct ", "enum ", "trait ", "type ", "union "] {
            if let Some(rest) = item.strip_prefix(keyword) {
                let name = ident(rest);
                if is_pub {
                    public.insert(name.clone());
                }
                defined.insert(name);
                if keyword == "enum " && line.ends_with('{') {
                    in_enum = depth + 1;
                    in_public_enum = is_pub;
                }
            }
        }
        if let Some((_, alias)) = line
            .strip_prefix("pub use ")
            .and_then(|l| l.split_once(" as "))
        {
            public.insert(ident(alias));
        }
        if in_enum > 0 && depth == in_enum && line.starts_with(|c: char| c.is_ascii_uppercase()) {
            if in_public_enum {
                public.insert(ident(line));
            }
            defined.insert(ident(line));
        }
        depth += line.matches('{').count();
        depth = depth.saturating_sub(line.matches('}').count());
        if in_enum > 0 && depth < in_enum {
            in_enum = 0;
        }
    }
}

/// The type names the docs may use.
struct Known {
    /// Ours that the crates export, the dependencies' (Bevy's and the others whose sources
    /// cargo keeps in its registry), Rust's own and SciPy's.
    public: BTreeSet<String>,
    /// Besides those, our crates' private types, which contributors' pages and doc comments
    /// may name.
    defined: BTreeSet<String>,
}

/// The Rust sources of the dependencies whose names the docs use (Bevy's crates, glam,
/// avian and parry, wgpu and naga, image, noise), from cargo's registry.
fn dependency_sources() -> Vec<PathBuf> {
    const DEPENDENCIES: [&str; 8] = [
        "bevy", "glam-", "avian3d-", "parry3d-", "wgpu-", "naga-", "image-", "noise-",
    ];
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cargo")));
    let registries = home
        .map(|h| h.join("registry/src"))
        .and_then(|r| fs::read_dir(r).ok());
    let mut out = Vec::new();
    for registry in registries.into_iter().flatten().flatten() {
        for package in fs::read_dir(registry.path())
            .into_iter()
            .flatten()
            .flatten()
        {
            let name = package.file_name().to_string_lossy().into_owned();
            if DEPENDENCIES.iter().any(|p| name.starts_with(p)) && !name.starts_with("bevy-") {
                walk_absolute(&package.path().join("src"), &mut out);
            }
        }
    }
    out.retain(|f| f.extension().is_some_and(|e| e == "rs"));
    out
}

/// The names, read once for all the tests that need them.
fn known_names() -> &'static Known {
    static KNOWN: OnceLock<Known> = OnceLock::new();
    KNOWN.get_or_init(read_known_names)
}

fn read_known_names() -> Known {
    const OTHERS: [&str; 25] = [
        "Some",
        "None",
        "Ok",
        "Err",
        "Option",
        "Result",
        "Vec",
        "Box",
        "String",
        "Arc",
        "Rc",
        "HashMap",
        "HashSet",
        "BTreeMap",
        "BTreeSet",
        "Path",
        "PathBuf",
        "File",
        "Instant",
        "Duration",
        "Mutex",
        "Cow",
        "Default",
        "Iterator",
        "PoissonDisk",
    ];
    let mut public: BTreeSet<String> = OTHERS.iter().map(|s| s.to_string()).collect();
    let mut defined = BTreeSet::new();
    let mut ours = Vec::new();
    for top in ["crates", "src", "examples", "fuzz"] {
        walk_absolute(&root().join(top), &mut ours);
    }
    for file in ours
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "rs"))
    {
        let text = fs::read_to_string(file).unwrap_or_default();
        type_names(&text, &mut public, &mut defined);
    }
    // The dependencies' private types are none of the docs' business.
    let mut private = BTreeSet::new();
    for file in dependency_sources() {
        let text = fs::read_to_string(file).unwrap_or_default();
        type_names(&text, &mut public, &mut private);
    }
    defined.extend(public.iter().cloned());
    Known { public, defined }
}

/// The capitalised names in the code spans of `text` followed by `::` or `(`, which must
/// be types, traits or enum variants in `known` (a name with an underscore is not a type:
/// `F_t(k)` is a formula).
fn unknown_types(text: &str, at: &Path, known: &BTreeSet<String>) -> Vec<String> {
    let mut out = Vec::new();
    for span in code_spans(text) {
        let mut rest = span.as_str();
        while let Some(start) = rest.find(|c: char| c.is_ascii_uppercase()) {
            let before = rest[..start].chars().next_back();
            rest = &rest[start..];
            let len = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            let (name, after) = rest.split_at(len);
            let word_start = !before.is_some_and(|c| c.is_alphanumeric() || c == '_');
            if word_start
                && (after.starts_with("::") || after.starts_with('('))
                && !name.contains('_')
                && !known.contains(name)
            {
                out.push(format!("{}: `{span}` names {name}", at.display()));
            }
            rest = after;
        }
    }
    out
}

#[test]
fn no_doc_names_a_type_the_crates_do_not_export() {
    let known = known_names();
    let mut unknown = Vec::new();
    // Contributors' pages may name the crates' private types; users' pages only what the
    // crates export.
    let contributors = [
        "docs/ARCHITECTURE.md",
        "TESTING.md",
        "CONTRIBUTING.md",
        "docs/construction-notes.md",
        "docs/speed-notes.md",
        "docs/rendering-notes.md",
        "docs/lavapipe-notes.md",
        "docs/stippling.md",
    ];
    for page in pages() {
        let names = match contributors.iter().any(|c| page == Path::new(c)) {
            true => &known.defined,
            false => &known.public,
        };
        unknown.extend(unknown_types(&read(&page), &page, names));
    }
    for (file, docs) in script_and_crate_docs() {
        unknown.extend(unknown_types(&docs, &file, &known.defined));
    }
    assert!(unknown.is_empty(), "unknown names:\n{}", unknown.join("\n"));
}

#[test]
fn the_name_checks_catch_a_missing_script_and_an_unknown_type() {
    let all = files();
    let page = Path::new("docs/guide/x.md");
    assert!(missing_names("run scripts/smoke.sh", page, &all).is_empty());
    assert_eq!(
        missing_names("see scripts/screenshots.sh", page, &all),
        ["docs/guide/x.md: no file scripts/screenshots.sh"]
    );
    assert_eq!(
        missing_names("cargo run --example nowhere", page, &all).len(),
        1
    );
    assert!(missing_names("cargo run --example open_world --bench ground", page, &all).is_empty());
    assert_eq!(
        missing_names("cargo test --test no_such_test", page, &all).len(),
        1
    );
    let known = &known_names().public;
    let good = "`ScatterClass::instanced(..)` `Transform::from_xyz(0.0)` `DVec2::ZERO`";
    assert!(unknown_types(good, page, known).is_empty());
    let stale = "a `SceneRoot(handle)` and `InstancedMaterial::default()`";
    assert_eq!(unknown_types(stale, page, known).len(), 2);
    // Variants count as names: layer files write them.
    assert!(unknown_types("`Constant(40.0)` `Within(30.0)`", page, known).is_empty());
    // A private type is not for users' pages.
    assert_eq!(unknown_types("`Generator::points`", page, known).len(), 1);
}

#[test]
fn every_guide_page_is_for_users_and_compiled() {
    let lib = read(Path::new("src/lib.rs"));
    let mut problems = Vec::new();
    for page in pages().into_iter().filter(|p| p.starts_with("docs/guide")) {
        let text = read(&page);
        let name = page.file_name().unwrap().to_string_lossy();
        if !lib.contains(&format!("include_str!(\"../docs/guide/{name}\")")) {
            problems.push(format!(
                "{}: not included as doctests by src/lib.rs",
                page.display()
            ));
        }
        let lines = text.lines().count();
        if lines >= 150 {
            problems.push(format!("{}: {lines} lines (150 at most)", page.display()));
        }
        let months = [
            "January",
            "February",
            "March",
            "April",
            "May",
            "June",
            "July",
            "August",
            "September",
            "October",
            "November",
            "December",
        ];
        let mut fenced = false;
        for (n, line) in text.lines().enumerate() {
            let at = format!("{}:{}", page.display(), n + 1);
            if line.trim_start().starts_with("```") {
                let info = line.trim_start().trim_start_matches('`');
                if !fenced && (info.is_empty() || info.contains("ignore")) {
                    problems.push(format!("{at}: a code block without a language, or ignored"));
                }
                fenced = !fenced;
            }
            if line.contains("this machine") || line.contains("2-core") {
                problems.push(format!("{at}: names the machine it was measured on"));
            }
            if months.iter().any(|m| line.contains(&format!("{m} 20"))) {
                problems.push(format!("{at}: a date"));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
