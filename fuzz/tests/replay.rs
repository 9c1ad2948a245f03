//! Replays the seed corpora and every saved regression input through the
//! fuzz targets' checks, on a stable toolchain without libFuzzer:
//! `cargo test --manifest-path fuzz/Cargo.toml`.
//!
//! A regression input is a TOML scene document (`fuzz/regressions/*.toml`);
//! lines `#set key=value` in it are overrides applied to it, as the
//! `overrides` target applies them.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

fn files(dir: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_file() && p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    out.sort();
    out
}

/// Runs every file through the checks; fails naming every file that panicked.
fn replay(paths: &[PathBuf]) {
    let mut failed = Vec::new();
    for path in paths {
        let bytes = std::fs::read(path).expect("read input");
        let Ok(text) = String::from_utf8(bytes) else {
            continue; // the `scene` target skips non-UTF-8 input too
        };
        let overrides = ballcage_fuzz::set_lines(&text);
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            ballcage_fuzz::check_text(&text, &overrides)
        }));
        match outcome {
            Ok(o) => eprintln!("{}: {}", path.display(), summary(&o)),
            Err(_) => failed.push(path.display().to_string()),
        }
    }
    assert!(
        failed.is_empty(),
        "inputs that fail the checks: {failed:#?}"
    );
}

fn summary(o: &ballcage_fuzz::Outcome) -> String {
    match o {
        ballcage_fuzz::Outcome::Rejected(e) => format!("rejected: {e}"),
        ballcage_fuzz::Outcome::Skipped(why) => format!("over the {why} cap, not run"),
        ballcage_fuzz::Outcome::Diverged(e) => format!("diverged: {e}"),
        ballcage_fuzz::Outcome::Ran => "ran".to_string(),
    }
}

#[test]
fn scene_seeds_pass_the_checks() {
    replay(&files("seeds/scene"));
}

#[test]
fn regression_inputs_pass_the_checks() {
    replay(&files("regressions"));
}

#[test]
fn every_base_scene_of_the_overrides_target_runs() {
    for text in ballcage_fuzz::overrides::BASES {
        let o = ballcage_fuzz::check_text(text, &[]);
        assert!(matches!(o, ballcage_fuzz::Outcome::Ran), "{text}: {o:?}");
    }
}
