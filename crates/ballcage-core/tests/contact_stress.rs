//! The Hertz models of the drill pipe's contact pairs (`drillpipe::stress`):
//! the groove's track curvature by hand, and which pairs have a model.

use ballcage_core::Document;
use ballcage_core::drillpipe::Feature;
use ballcage_core::drillpipe::stress::{pair_stresses, track_curvature};

fn paper() -> Document {
    Document::from_toml_str("kind = \"drill-pipe\"\n", &[]).unwrap()
}

#[test]
fn the_track_curvature_is_convex_on_the_head_and_concave_in_the_seat() {
    // The key's centre sits at the pitch radius PCR = 31.5 mm on the
    // bisector plane; each groove's centre line is a circle about a point
    // offset c = 4 mm along the axis, so the ball centre runs at
    // R_t = √(PCR² + c²) = 31.753 mm from it. A flank contact at α = 45°
    // lies r_b·cos α = 5.303 mm nearer that centre (head) or farther
    // (seat), with its normal at α to the radial direction; by Meusnier
    // the track curvature is cos α / r there:
    // head +0.70711/(31.753 − 5.303 mm) = 1/37.41 mm,
    // seat −0.70711/(31.753 + 5.303 mm) = −1/52.41 mm.
    let doc = paper();
    let (_, layout) = doc.drill_pipe_parts().unwrap();
    let model = doc.model();
    let key = &layout.hinges[1].keys[0];
    let inner = track_curvature(doc.initial_state(), &model.pairs[key.inner[0]]);
    let outer = track_curvature(doc.initial_state(), &model.pairs[key.outer[0]]);
    let rt = (0.0315_f64.powi(2) + 0.004_f64.powi(2)).sqrt();
    let (cos, rb) = (std::f64::consts::FRAC_1_SQRT_2, 0.0075);
    let (head, seat) = (cos / (rt - rb * cos), -cos / (rt + rb * cos));
    assert!(
        (inner / head - 1.0).abs() < 2e-3,
        "inner track radius {}",
        1.0 / inner
    );
    assert!(
        (outer / seat - 1.0).abs() < 2e-3,
        "outer track radius {}",
        1.0 / outer
    );
}

#[test]
fn every_pair_but_the_neck_has_a_model() {
    let doc = paper();
    let (spec, layout) = doc.drill_pipe_parts().unwrap();
    let stresses = pair_stresses(spec, layout, doc.model(), doc.initial_state());
    for (part, st) in layout.pairs.iter().zip(&stresses) {
        assert_eq!(
            st.has_model(),
            part.feature != Feature::NeckMouth,
            "{part:?}"
        );
    }
}
