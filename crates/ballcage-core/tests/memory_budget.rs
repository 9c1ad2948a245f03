//! The recorded tables' memory is estimated before a run and checked against
//! `record.max_bytes` (docs/reliability.md, "Limits").

use ballcage_core::record::{TableEstimate, table_def};
use ballcage_core::scene::TableKind;
use ballcage_core::{Document, Scene, SceneError, Simulation};

fn paper(overrides: &[&str]) -> Result<Document, SceneError> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Document::from_toml_str("kind = \"drill-pipe\"\n", &o)
}

fn rows_of<'a>(estimate: &'a [TableEstimate], name: &str) -> &'a TableEstimate {
    estimate
        .iter()
        .find(|t| t.name == name)
        .unwrap_or_else(|| panic!("no estimate for {name}"))
}

#[test]
fn the_estimate_counts_the_rows_the_paper_scene_records() {
    // 10 ms at a frame per ms: frames at t = 0, 1, …, 10 ms = 11.
    let doc = paper(&["simulation.duration=0.01"]).unwrap();
    let est = doc.memory_estimate();
    // By hand: 12 links; hinges 0…12 = 13; 6 keys each; bodies recorded by
    // default are the chain: 2 connectors + 12 links; one drive row a frame.
    let by_hand = [
        ("links", 11 * 12),
        ("hinges", 11 * 13),
        ("keys", 11 * 13 * 6),
        ("bodies", 11 * 14),
        ("drive", 11),
    ];
    for (name, rows) in by_hand {
        assert_eq!(rows_of(&est, name).rows, rows, "{name}");
    }
    // The run writes exactly those rows, and no more contact points than slots.
    let mut sim = doc.simulation();
    while !sim.is_done() {
        sim.step().expect("stable");
    }
    let rec = sim.finish();
    for t in &rec.tables {
        let e = rows_of(&est, t.def.name);
        if t.def.name == "contacts" {
            assert!(t.rows as u64 <= e.rows, "contacts {} > {}", t.rows, e.rows);
            assert!(t.rows > 0);
        } else {
            assert_eq!(t.rows as u64, e.rows, "{}", t.def.name);
        }
        assert_eq!(e.bytes, e.rows * t.def.row_bytes(), "{}", t.def.name);
    }
    assert_eq!(est.len(), rec.tables.len());
}

#[test]
fn a_scene_over_the_budget_is_refused_with_the_estimate() {
    let total: u64 = paper(&[])
        .unwrap()
        .memory_estimate()
        .iter()
        .map(|t| t.bytes)
        .sum();
    // The budget binds exactly at the estimate.
    paper(&[&format!("record.max_bytes={total}")]).expect("at the budget");
    let e = paper(&[&format!("record.max_bytes={}", total - 1)]).unwrap_err();
    assert_eq!(e.path, "record.max_bytes");
    assert_eq!(e.value, (total - 1).to_string());
    assert!(e.reason.contains("1801 frames"), "{e}");
    assert!(e.reason.contains("contacts"), "{e}");
    assert!(e.reason.contains("raise simulation.output_interval"), "{e}");
}

#[test]
fn the_generic_engine_refuses_too() {
    // A ball for 1 s with a frame per step: 10 001 frames of one body.
    let scene = Scene::from_toml_str(
        r#"
[simulation]
duration = 1.0
dt = 1e-4
output_interval = 1e-4
[record]
tables = ["bodies", "energy"]
max_bytes = 1000000
[[bodies]]
name = "ball"
shape = { type = "ball", radius = 0.05 }
mass = 1.0
"#,
        &[],
    )
    .unwrap();
    let e = Simulation::new(&scene).unwrap_err();
    // bodies 10 001 × 160 B (step, t: 2 × 8; body id and name: 2 × 4; part
    // label, link, hinge, key: 4 × 8, nullable; 13 × 8) + energy 10 001 × 96 B
    // (12 × 8) = 2.560 MB
    let bytes = 10_001
        * (table_def(TableKind::Bodies).row_bytes() + table_def(TableKind::Energy).row_bytes());
    assert_eq!(bytes, 2_560_256);
    assert!(e.reason.contains("up to 2.560 MB over 10001 frames"), "{e}");
    let ok = Scene::from_toml_str(
        &scene
            .to_toml()
            .replace("max_bytes = 1000000", "max_bytes = 2560256"),
        &[],
    )
    .unwrap();
    Simulation::new(&ok).expect("at the budget");
}
