//! Every numeric default of a scene says where it comes from: the paper
//! (with its section, table or equation), a rule applied to the paper's
//! values, a PROPOSAL of the registry (source, reference, plausible range
//! and why), or a setting of the run. A default added without an entry in
//! its kind's lists (`scene/provenance.rs`, `drillpipe/provenance.rs`)
//! fails here, and so does a registry entry whose range does not hold its
//! default or whose values a scene refuses.

use ballcage_core::loader::{self, Document, Kind, ProposalEntry};
use ballcage_core::scene::provenance::MINIMAL_GENERIC_SCENE;
use ballcage_core::scene::{Provenance, Source, describe, flatten, numeric_keys};

/// Sections of a generic scene its author declares item by item (their
/// fields are the scene's own input, not defaults of the engine).
const DECLARED_ITEMS: [&str; 4] = ["bodies.", "contacts.", "loads.", "joints."];

/// The default document of `kind`, as loading it resolves it.
fn default_text(kind: Kind) -> &'static str {
    match kind {
        Kind::DrillPipe => "kind = \"drill-pipe\"",
        Kind::Generic => MINIMAL_GENERIC_SCENE,
    }
}

fn registry() -> Vec<ProposalEntry> {
    loader::proposals(None).expect("the registry resolves")
}

#[test]
fn every_numeric_default_of_each_kind_is_classified() {
    for kind in Kind::ALL {
        let root = kind.default_value().unwrap();
        let keys = numeric_keys(&root, "");
        assert!(keys.len() > 10, "{}: {} numbers", kind.name(), keys.len());
        let missing: Vec<&String> = keys
            .iter()
            .filter(|k| !DECLARED_ITEMS.iter().any(|p| k.starts_with(p)))
            .filter(|k| loader::provenance_of(kind, k).is_none())
            .collect();
        assert!(
            missing.is_empty(),
            "{} defaults without a provenance (add each to its kind's list: the paper with its \
             reference, a rule, a PROPOSAL with its range, or a setting): {missing:?}",
            kind.name()
        );
    }
}

#[test]
fn the_default_values_are_those_a_loaded_default_document_holds() {
    for kind in Kind::ALL {
        let doc = Document::from_toml_str(default_text(kind), &[]).unwrap();
        assert_eq!(doc.value("").unwrap(), kind.default_value().unwrap());
    }
}

#[test]
fn every_classified_key_is_a_documented_field_listed_once() {
    for kind in Kind::ALL {
        let root = kind.default_value().unwrap();
        let documented: Vec<String> = flatten(kind.field_docs())
            .into_iter()
            .map(|(k, _)| k)
            .collect();
        let keys: Vec<&str> = kind
            .provenance()
            .iter()
            .flat_map(|(_, list)| list.iter().map(|o| o.key))
            .collect();
        for (i, key) in keys.iter().enumerate() {
            assert!(!keys[..i].contains(key), "{}: {key} twice", kind.name());
            // a contact law's fields are documented by its rule, for the law the document has
            assert!(
                documented.iter().any(|d| d == key)
                    || describe(kind.field_docs(), &root, key).is_ok(),
                "{}: {key} is not a field of its FIELDS table",
                kind.name()
            );
        }
    }
}

#[test]
fn every_paper_value_names_where_the_paper_gives_it() {
    for kind in Kind::ALL {
        for (_, list) in kind.provenance() {
            for origin in list {
                let text = match origin.provenance {
                    Provenance::Paper(r) => {
                        assert!(
                            r.starts_with('§') || r.starts_with("Table"),
                            "{}: {r}",
                            origin.key
                        );
                        r
                    }
                    Provenance::Derived(t) | Provenance::Setting(t) | Provenance::Declared(t) => t,
                    Provenance::Proposal(p) => p.reference,
                };
                assert!(!text.trim().is_empty(), "{} says nothing", origin.key);
            }
        }
    }
}

#[test]
fn every_registry_entry_is_a_number_of_its_default_document_inside_its_range() {
    let all = registry();
    assert!(all.len() >= 30, "{} entries", all.len());
    for kind in Kind::ALL {
        assert!(
            all.iter().any(|e| e.kind == kind),
            "{} has none",
            kind.name()
        );
        let only = loader::proposals(Some(kind)).unwrap();
        assert!(only.iter().all(|e| e.kind == kind));
        assert_eq!(only.len(), all.iter().filter(|e| e.kind == kind).count());
    }
    for e in &all {
        let p = e.proposal;
        let key = e.key;
        assert!(p.low.is_finite() && p.high.is_finite(), "{key}");
        assert!(p.low < p.high, "{key}: low {} ≥ high {}", p.low, p.high);
        assert!(
            p.low <= e.default && e.default <= p.high,
            "{key}: default {} outside [{}, {}] {}",
            e.default,
            p.low,
            p.high,
            e.unit
        );
        assert!(!e.unit.is_empty(), "{key} has no unit");
        assert!(!e.meaning.is_empty(), "{key} has no meaning");
        assert!(!p.reference.trim().is_empty(), "{key} has no reference");
        assert!(
            !p.range_reason.trim().is_empty(),
            "{key} has no range reason"
        );
        assert!(
            matches!(
                loader::provenance_of(e.kind, key),
                Some(Provenance::Proposal(_))
            ),
            "{key}"
        );
    }
    let neck = all.iter().find(|e| e.key == "pipe.neck_radius").unwrap();
    assert_eq!(
        (neck.kind, neck.default, neck.unit.as_str()),
        (Kind::DrillPipe, 0.019, "m")
    );
    assert_eq!(neck.proposal.source, Source::Invented);
    let k = all
        .iter()
        .find(|e| e.key == "materials.internal.normal.stiffness")
        .unwrap();
    assert_eq!((k.default, k.unit.as_str()), (1e5, "N/mm^2.2"));
    let growth = all
        .iter()
        .find(|e| e.key == "simulation.divergence.energy_growth")
        .unwrap();
    assert_eq!(growth.kind, Kind::Generic);
}

/// A scene of the entry's kind with `key` set to each end of its range
/// loads (validated, expanded, assembled) and holds the value; the ideal-CV
/// hinge's fields with that hinge.
#[test]
fn every_registry_value_at_either_end_of_its_range_loads() {
    for e in registry() {
        for v in [e.proposal.low, e.proposal.high] {
            let mut overrides = vec![format!("{}={v:?}", e.key)];
            if e.key.starts_with("pipe.ideal_cv.") {
                overrides.push("pipe.hinge=\"ideal-cv\"".to_string());
            }
            let doc = Document::from_toml_str(default_text(e.kind), &overrides)
                .unwrap_or_else(|err| panic!("{overrides:?}: {err}"));
            let held = doc.value(e.key).unwrap();
            assert_eq!(held.as_float(), Some(v), "{}", e.key);
        }
    }
}

#[test]
fn scene_show_marks_each_proposal_above_its_line() {
    let doc = Document::from_toml_str("kind = \"drill-pipe\"", &[]).unwrap();
    let text = doc.to_toml_with_units();
    assert!(
        text.contains("# PROPOSAL, 17.5–21 mm: not in the paper\nneck_radius = 0.019  # m\n"),
        "{text}"
    );
    assert!(
        text.contains(
            "# PROPOSAL, 1e4–1e6 N/mm^2.2: a reading of the paper\nstiffness = 100000.0  # N/mm^2.2\n"
        ),
        "{text}"
    );
    assert!(text.contains("# PROPOSAL, 0.1–0.5 s: not in the paper\nramp = 0.3  # s\n"));
    assert!(text.contains("# PROPOSAL, 2.75–3.14 GPa: a handbook value, not in the paper\n"));
    assert!(
        text.contains("# PROPOSAL, 0.1–0.5: not in the paper\npenetration_fraction = 0.25  # -\n")
    );
    // one mark per drill-pipe entry and per engine entry, each above a line of its field
    let lines: Vec<&str> = text.lines().collect();
    let marks: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("# PROPOSAL, "))
        .collect();
    let expected = registry()
        .iter()
        .filter(|e| e.kind == Kind::DrillPipe || e.key.starts_with("simulation."))
        .count();
    assert_eq!(marks.len(), expected, "{text}");
    for i in marks {
        assert!(lines[i + 1].contains(" = "), "{}", lines[i + 1]);
    }
    // not on paper values
    assert!(
        text.contains("\n[borehole]\ncurvature_radius = 1.5  # m\n"),
        "{text}"
    );
    let back: toml::Table = text.parse().unwrap();
    assert_eq!(toml::Value::Table(back), doc.value("").unwrap());
}

#[test]
fn a_law_written_in_other_units_is_not_marked_with_the_registrys_range() {
    let si = ["materials.tube.normal.units=\"SI\"".to_string()];
    let doc = Document::from_toml_str("kind = \"drill-pipe\"", &si).unwrap();
    let text = doc.to_toml_with_units();
    assert!(
        text.contains("law = \"impact\"\nstiffness = 100000.0  # N/m^2.2\n"),
        "{text}"
    );
    assert_eq!(
        text.matches("# PROPOSAL, 1e4–1e6 N/mm^2.2").count(),
        1,
        "{text}"
    );
}

#[test]
fn a_generic_scene_marks_its_divergence_thresholds() {
    let doc = Document::from_toml_str(MINIMAL_GENERIC_SCENE, &[]).unwrap();
    let text = doc.to_toml_with_units();
    assert_eq!(text.matches("# PROPOSAL, ").count(), 2, "{text}");
    assert!(
        text.contains("# PROPOSAL, 0.5–2: not in the paper\nenergy_growth = 1.0  # -\n"),
        "{text}"
    );
}

#[test]
fn a_document_answers_where_each_default_comes_from() {
    let doc = Document::from_toml_str("kind = \"drill-pipe\"", &[]).unwrap();
    assert!(matches!(
        doc.provenance("borehole.curvature_radius"),
        Some(Provenance::Paper(r)) if r.contains("1.5 m")
    ));
    assert!(matches!(
        doc.provenance("pipe.neck_radius"),
        Some(Provenance::Proposal(p)) if p.low == 0.0175 && p.high == 0.021
    ));
    assert!(matches!(
        doc.provenance("simulation.dt"),
        Some(Provenance::Setting(_))
    ));
    assert!(matches!(
        doc.provenance("pipe.ball_keys.ball_mass"),
        Some(Provenance::Derived(_))
    ));
    assert!(doc.provenance("pipe.nope").is_none());
    let generic = Document::from_toml_str(MINIMAL_GENERIC_SCENE, &[]).unwrap();
    assert!(matches!(
        generic.provenance("world.gravity"),
        Some(Provenance::Declared(_))
    ));
    assert!(generic.provenance("pipe.neck_radius").is_none());
    assert!(generic.provenance("bodies.0.mass").is_none());
}
