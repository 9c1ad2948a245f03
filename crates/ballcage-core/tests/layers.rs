//! The engine's modules form layers: each names only the modules below it,
//! so there is no cycle and the drill pipe sits on top of a generic engine
//! that never names it (docs/architecture.md).
//!
//! The test reads every source file under `src/` and collects each
//! `crate::<module>` path it contains (code and doc links alike) and each
//! sibling reached through `super::` from a module's root file.

use std::collections::BTreeSet;
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
