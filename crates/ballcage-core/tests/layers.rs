//! The engine's modules form layers: each names only the modules below it,
//! so there is no cycle and the drill pipe sits on top of a generic engine
//! that never names it (docs/architecture.md).
//!
//! The test reads every source file under `src/` and collects each
//! `crate::<module>` path it contains (code and doc links alike) and each
//! sibling reached through `super::` from a module's root file.
//!
//! The same limits hold beyond the engine: no source files of the core,
//! the shapes crate, the bench crate or the fuzz crate name each other
//! round a loop (`LOOP_CHECKED`), and the bench and fuzz crates name only
//! the engine stages and library modules listed for them (`USERS`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The stages, bottom first, with the modules each may name.
const LAYERS: &[(&str, &[&str])] = &[
    ("error", &[]),
    ("math", &[]),
    ("force", &["error", "math"]),
    ("geometry", &["error", "math"]),
    ("scene", &["error", "math"]),
    ("model", &["error", "math", "force", "geometry", "scene"]),
    (
        "assembly",
        &["error", "math", "force", "geometry", "scene", "model"],
    ),
    (
        "dynamics",
        &["error", "math", "force", "geometry", "scene", "model"],
    ),
    (
        "integrate",
        &[
            "error", "math", "force", "geometry", "scene", "model", "dynamics",
        ],
    ),
    ("record", &["error", "math", "scene", "model", "dynamics"]),
    (
        "sim",
        &[
            "error",
            "math",
            "scene",
            "model",
            "assembly",
            "dynamics",
            "integrate",
            "record",
        ],
    ),
    ("output", &["error", "record"]),
    (
        "drillpipe",
        &[
            "error",
            "math",
            "force",
            "geometry",
            "scene",
            "model",
            "assembly",
            "dynamics",
            "integrate",
            "record",
            "sim",
        ],
    ),
    (
        "loader",
        &[
            "error",
            "math",
            "force",
            "geometry",
            "scene",
            "model",
            "assembly",
            "dynamics",
            "integrate",
            "record",
            "sim",
            "drillpipe",
        ],
    ),
];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Top-level module of a source file (`src/scene/body.rs` → `scene`).
fn module_of(path: &Path) -> String {
    let rel = path.strip_prefix(src()).expect("under src");
    let first = rel.components().next().expect("non-empty").as_os_str();
    first.to_string_lossy().trim_end_matches(".rs").to_string()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("readable src") {
        let path = entry.expect("entry").path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every `crate::<name>` in `text`.
fn named_modules(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut rest = text;
    while let Some(i) = rest.find("crate::") {
        let after = &rest[i + "crate::".len()..];
        let name: String = after
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        // `ballcage_crate::x` or `somecrate::x` are not this crate; items of
        // the crate root (`crate::VERSION`) are not modules.
        let before = rest[..i].chars().last();
        let module = name.chars().next().is_some_and(|c| c.is_lowercase());
        if !before.is_some_and(|c| c.is_alphanumeric() || c == '_') && module {
            out.insert(name);
        }
        rest = after;
    }
    out
}

/// Every source file under `src/` but the crate root: (path, module, text).
fn sources() -> Vec<(PathBuf, String, String)> {
    let mut files = vec![];
    rust_files(&src(), &mut files);
    files
        .into_iter()
        .map(|f| {
            let text = std::fs::read_to_string(&f).expect("readable file");
            (f.clone(), module_of(&f), text)
        })
        .filter(|(_, module, _)| module != "lib")
        .collect()
}

/// (file, module, named module) for every cross-module reference.
fn references() -> Vec<(PathBuf, String, String)> {
    let mut out = vec![];
    for (f, module, text) in sources() {
        for named in named_modules(&text) {
            if named != module {
                out.push((f.clone(), module.clone(), named));
            }
        }
    }
    out
}

#[test]
fn every_module_names_only_the_layers_below_it() {
    let mut bad = vec![];
    for (file, module, named) in references() {
        let Some((_, allowed)) = LAYERS.iter().find(|(m, _)| *m == module) else {
            bad.push(format!(
                "{}: module `{module}` is not in LAYERS",
                file.display()
            ));
            continue;
        };
        if !allowed.contains(&named.as_str()) {
            bad.push(format!(
                "{}: `{module}` names `crate::{named}`",
                file.display()
            ));
        }
    }
    assert!(bad.is_empty(), "layer violations:\n{}", bad.join("\n"));
}

#[test]
fn the_layers_are_ordered_so_there_is_no_cycle() {
    for (i, (module, allowed)) in LAYERS.iter().enumerate() {
        for a in *allowed {
            let j = LAYERS.iter().position(|(m, _)| m == a).expect("listed");
            assert!(j < i, "`{module}` may name `{a}`, which is not below it");
        }
    }
}

#[test]
fn no_generic_module_names_the_drill_pipe() {
    let generic: Vec<&str> = LAYERS
        .iter()
        .map(|(m, _)| *m)
        .filter(|m| !["drillpipe", "loader"].contains(m))
        .collect();
    for (f, module, text) in sources() {
        if generic.contains(&module.as_str()) {
            assert!(
                !text.contains("drillpipe") && !text.contains("DrillPipe"),
                "{} names the drill pipe",
                f.display()
            );
        }
    }
}

#[test]
fn the_checker_sees_a_crate_path() {
    // The scanner itself: finds `crate::x` and ignores `other_crate::y`.
    let found = named_modules("use crate::scene::Scene; use my_crate::z; [`crate::record`]");
    assert_eq!(
        found.into_iter().collect::<Vec<_>>(),
        vec!["record".to_string(), "scene".to_string()]
    );
}

/// The crates whose source files the file-loop check reads: (crate, its
/// `src/` relative to this crate's manifest, the fewest leaf files it has).
/// The bench and fuzz crates' `benches/`, `examples/`, `tests/` and
/// `fuzz_targets/` files are crate roots of their own (see [`USERS`]).
const LOOP_CHECKED: &[(&str, &str, usize)] = &[
    ("ballcage-core", "src", 6),
    ("ballcage-shapes", "../ballcage-shapes/src", 6),
    ("ballcage-bench", "../ballcage-bench/src", 1),
    ("ballcage-fuzz", "../../fuzz/src", 1),
];

/// Module path of a leaf source file under `src` (`drillpipe/stress.rs` →
/// `drillpipe::stress`); `None` for a module root (`lib.rs`, `main.rs`,
/// `mod.rs`), which declares and re-exports its children rather than
/// depending on them.
fn leaf_module(src: &Path, file: &Path) -> Option<Vec<String>> {
    let rel = file.strip_prefix(src).expect("under src");
    let stem = rel.file_stem()?.to_string_lossy().to_string();
    if ["lib", "main", "mod"].contains(&stem.as_str()) {
        return None;
    }
    let mut path: Vec<String> = rel
        .parent()
        .into_iter()
        .flat_map(|p| p.components())
        .map(|c| c.as_os_str().to_string_lossy().to_string())
        .collect();
    path.push(stem);
    Some(path)
}

/// An identifier at the start of `s`.
fn ident(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The module paths a `keyword::` path at the start of `s` reaches: its
/// segments, and for a `{…}` group each item's first segment appended.
fn path_segments(s: &str) -> Vec<Vec<String>> {
    let (mut base, mut rest) = (vec![], s);
    loop {
        let name = ident(rest);
        if name.is_empty() {
            break;
        }
        base.push(name.to_string());
        rest = &rest[name.len()..];
        match rest.strip_prefix("::") {
            Some(r) => rest = r,
            None => return vec![base],
        }
    }
    let Some(group) = rest.strip_prefix('{') else {
        return vec![base];
    };
    let group = &group[..group.find('}').unwrap_or(group.len())];
    let items = group
        .split(',')
        .map(|i| ident(i.trim()))
        .filter(|i| !i.is_empty());
    let mut out: Vec<Vec<String>> = items
        .map(|i| base.iter().cloned().chain([i.to_string()]).collect())
        .collect();
    out.push(base);
    out
}

/// The leaf files that the leaf file at module path `me` names through
/// `crate::` and `super::` paths in `text` (code and doc links alike).
fn named_files(me: &[String], text: &str, leaves: &BTreeSet<Vec<String>>) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    for (keyword, root) in [
        ("crate::", vec![]),
        ("super::", me[..me.len() - 1].to_vec()),
    ] {
        let mut rest = text;
        while let Some(i) = rest.find(keyword) {
            let before = rest[..i].chars().last();
            rest = &rest[i + keyword.len()..];
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            for segments in path_segments(rest) {
                let full: Vec<String> = root.iter().cloned().chain(segments).collect();
                // the longest prefix that is a leaf file (`tube::tests::x` → tube.rs)
                let file = (1..=full.len())
                    .rev()
                    .map(|k| full[..k].to_vec())
                    .find(|p| leaves.contains(p));
                if let Some(file) = file.filter(|f| f.as_slice() != me) {
                    out.insert(file);
                }
            }
        }
    }
    out
}

/// A loop of `graph`, as the files around it, if it has one.
fn find_loop(graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Option<Vec<Vec<String>>> {
    fn visit(
        node: &Vec<String>,
        graph: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>,
        done: &mut BTreeSet<Vec<String>>,
        stack: &mut Vec<Vec<String>>,
    ) -> Option<Vec<Vec<String>>> {
        if let Some(i) = stack.iter().position(|n| n == node) {
            return Some(stack[i..].iter().cloned().chain([node.clone()]).collect());
        }
        if done.contains(node) {
            return None;
        }
        stack.push(node.clone());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(found) = visit(next, graph, done, stack) {
                return Some(found);
            }
        }
        stack.pop();
        done.insert(node.clone());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| visit(n, graph, &mut done, &mut vec![]))
}

/// Which leaf files each leaf file of the crate at `src` names.
fn file_graph(src: &Path) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let mut files = vec![];
    rust_files(src, &mut files);
    let modules: Vec<(Vec<String>, PathBuf)> = files
        .into_iter()
        .filter_map(|f| leaf_module(src, &f).map(|m| (m, f)))
        .collect();
    let leaves: BTreeSet<Vec<String>> = modules.iter().map(|(m, _)| m.clone()).collect();
    modules
        .iter()
        .map(|(m, f)| {
            let text = std::fs::read_to_string(f).expect("readable file");
            (m.clone(), named_files(m, &text, &leaves))
        })
        .collect()
}

#[test]
fn no_source_files_name_each_other_round_a_loop() {
    // Module layers keep modules acyclic; this keeps files within a module
    // so too (e.g. `drillpipe/stress.rs` ↔ `drillpipe/tables.rs`, or the
    // shapes crate's `line.rs` ↔ `tube.rs`, before issue 24).
    for (krate, dir, fewest) in LOOP_CHECKED {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
        let graph = file_graph(&src);
        assert!(
            graph.len() >= *fewest,
            "{krate}: read {} files",
            graph.len()
        );
        if let Some(files) = find_loop(&graph) {
            let names: Vec<String> = files.iter().map(|f| f.join("/") + ".rs").collect();
            panic!("{krate}: source files in a loop: {}", names.join(" → "));
        }
    }
}

#[test]
fn the_loop_check_sees_a_loop_and_paths_through_super_and_groups() {
    let leaves: BTreeSet<Vec<String>> = [["m", "a"], ["m", "b"], ["m", "c"], ["x", "y"]]
        .iter()
        .map(|p| p.iter().map(|s| s.to_string()).collect())
        .collect();
    let me: Vec<String> = vec!["m".into(), "a".into()];
    let found = named_files(
        &me,
        "use super::{b, Item};\n/// [`crate::x::y::f`]\nuse other_crate::m::c;",
        &leaves,
    );
    let found: Vec<String> = found.iter().map(|f| f.join("/")).collect();
    assert_eq!(found, ["m/b", "x/y"]);
    let path = |s: &str| -> Vec<String> { s.split('/').map(String::from).collect() };
    let mut graph = BTreeMap::new();
    graph.insert(path("m/a"), BTreeSet::from([path("m/b")]));
    graph.insert(path("m/b"), BTreeSet::from([path("m/c")]));
    graph.insert(path("m/c"), BTreeSet::new());
    assert_eq!(find_loop(&graph), None);
    graph.insert(path("m/c"), BTreeSet::from([path("m/a")]));
    assert!(find_loop(&graph).is_some_and(|l| l.len() == 4));
}

/// The source folders of the crates built on the engine (the bench crate
/// and the fuzz crate, paths relative to this crate's manifest), each with
/// the modules it may name: `ballcage_core::<stage>` (a stage of [`LAYERS`])
/// and a library module of its own crate (`ballcage_bench::rapier_chain`).
/// Items the engine re-exports at its root (`ballcage_core::Scene`) are
/// free. Every file of `benches/`, `examples/`, `tests/` and `fuzz_targets/`
/// is a crate root of its own, reaching its library by name only, so no two
/// of them can form a loop; their library's files are in the loop check.
const USERS: &[(&str, &[&str])] = &[
    (
        "../ballcage-bench/src",
        &[
            "ballcage_core::assembly",
            "ballcage_core::force",
            "ballcage_core::geometry",
            "ballcage_core::math",
            "ballcage_core::model",
            "ballcage_core::scene",
        ],
    ),
    (
        "../ballcage-bench/benches",
        &["ballcage_core::force", "ballcage_bench::rapier_chain"],
    ),
    (
        "../ballcage-bench/examples",
        &["ballcage_core::scene", "ballcage_bench::rapier_chain"],
    ),
    (
        "../../fuzz/src",
        &["ballcage_core::output", "ballcage_core::record"],
    ),
    ("../../fuzz/fuzz_targets", &["ballcage_fuzz::overrides"]),
    ("../../fuzz/tests", &["ballcage_fuzz::overrides"]),
    ("../../fuzz/examples", &["ballcage_fuzz::overrides"]),
];

/// The crates whose modules [`USERS`] lists, each with its `src/`.
const USED_CRATES: &[(&str, &str)] = &[
    ("ballcage_core", "src"),
    ("ballcage_shapes", "../ballcage-shapes/src"),
    ("ballcage_bench", "../ballcage-bench/src"),
    ("ballcage_fuzz", "../../fuzz/src"),
];

/// Every `<crate>::<module>::` in `text` for the crates of [`USED_CRATES`]:
/// a lowercase path segment followed by `::` is a module
/// (`ballcage_core::scene::X`); any other is a root item
/// (`ballcage_core::Scene`, `ballcage_core::Document::from_toml_str`,
/// `ballcage_fuzz::check_text`).
fn used_modules(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for (krate, _) in USED_CRATES {
        let prefix = format!("{krate}::");
        let mut rest = text;
        while let Some(i) = rest.find(&prefix) {
            let before = rest[..i].chars().last();
            rest = &rest[i + prefix.len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            let own_name = before.is_some_and(|c| c.is_alphanumeric() || c == '_');
            let module = name.chars().next().is_some_and(|c| c.is_lowercase());
            if !own_name && module && rest[name.len()..].starts_with("::") {
                out.insert(format!("{krate}::{name}"));
            }
        }
    }
    out
}

#[test]
fn the_bench_and_fuzz_crates_name_only_the_modules_listed_for_them() {
    let mut bad = vec![];
    for (dir, allowed) in USERS {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
        let mut files = vec![];
        rust_files(&dir, &mut files);
        assert!(!files.is_empty(), "no source files in {}", dir.display());
        for f in files {
            let text = std::fs::read_to_string(&f).expect("readable file");
            for named in used_modules(&text) {
                if !allowed.contains(&named.as_str()) {
                    bad.push(format!("{}: names `{named}`", f.display()));
                }
            }
        }
    }
    assert!(
        bad.is_empty(),
        "modules not listed in USERS:\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_modules_listed_for_the_bench_and_fuzz_crates_exist() {
    for (dir, allowed) in USERS {
        for named in *allowed {
            let (krate, module) = named.split_once("::").expect("crate::module");
            let (_, src) = USED_CRATES
                .iter()
                .find(|(k, _)| *k == krate)
                .unwrap_or_else(|| panic!("{dir}: unknown crate in `{named}`"));
            if krate == "ballcage_core" {
                assert!(
                    LAYERS.iter().any(|(m, _)| *m == module),
                    "{dir}: `{named}` is not a stage of LAYERS"
                );
            }
            let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(src);
            assert!(
                src.join(format!("{module}.rs")).is_file() || src.join(module).is_dir(),
                "{dir}: no module file for `{named}` in {}",
                src.display()
            );
        }
    }
}

#[test]
fn the_user_checker_tells_modules_from_root_items() {
    let found = used_modules(
        "use ballcage_core::{Document, Scene}; use ballcage_core::scene::{A, B};\n\
         ballcage_fuzz::check_text(t); ballcage_core::force::step(t); my_ballcage_core::x::y\n\
         ballcage_core::Document::from_toml_str(t)",
    );
    assert_eq!(
        found.into_iter().collect::<Vec<_>>(),
        ["ballcage_core::force", "ballcage_core::scene"]
    );
}
