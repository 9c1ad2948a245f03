//! The `[fatigue]` section of the drill-pipe document: the critical
//! sections of a link (where they are, their bores and stress
//! concentration factors) and the S–N curve of its steel. Used only by the
//! fatigue output (`fatigue.parquet`, `ballcage.measures.fatigue`), never
//! by the simulation. Where each default comes from: `provenance.rs`
//! (docs/model.md §8.6).

use serde::{Deserialize, Serialize};

use crate::error::SceneError;
use crate::scene::{FieldDoc, positive};

/// The critical sections of a link and the Basquin–Goodman S–N curve of
/// 35CrMo [m, –, Pa].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FatigueSpec {
    /// Distance from the head's hinge centre toward the link's centre of
    /// the neck section (Ø2·`pipe.neck_radius` over `head_bore_diameter`)
    /// [m]. PROPOSAL: 30 mm, just behind the neck's contact line with the
    /// seat's mouth (25.8 mm at the articulation limit).
    pub neck_offset: f64,
    /// Distance from the seat's hinge centre toward the link's centre of
    /// the seat section (Ø`pipe.link_diameter` over `seat_bore_diameter`),
    /// just behind the seat's sphere [m]. PROPOSAL: 32 mm (R_s 32.01 mm).
    pub seat_offset: f64,
    /// Bore of the ball head and its neck [m]. Paper (Table 1): 30 mm.
    pub head_bore_diameter: f64,
    /// Bore of the ball seat's tube, which carries the link's body and
    /// seat sections [m]. Paper (Table 1): 64 mm.
    pub seat_bore_diameter: f64,
    /// Stress concentration factor K_t of the neck section [–]. PROPOSAL:
    /// 2.0, a shoulder fillet of r/d ≈ 0.05 at D/d = 62/38 (Peterson's).
    pub neck_scf: f64,
    /// Stress concentration factor of the body section, at the link's
    /// centre [–]. PROPOSAL: 1.0, a plain tube.
    pub body_scf: f64,
    /// Stress concentration factor of the seat section [–]. PROPOSAL: 2.0,
    /// the seat's sphere and groove run-outs into its bore (Peterson's).
    pub seat_scf: f64,
    /// Ultimate tensile strength σ_u [Pa], for Goodman's mean-stress
    /// correction. PROPOSAL: 980 MPa, 35CrMo Q&T (GB/T 3077 minimum).
    pub ultimate_strength: f64,
    /// Basquin fatigue strength coefficient σ′_f [Pa]: σ_ar = σ′_f·(2N)^b.
    /// PROPOSAL: 1.5·σ_u = 1470 MPa (Bäumel–Seeger uniform material law).
    pub strength_coefficient: f64,
    /// Basquin fatigue strength exponent b [–]. PROPOSAL: −0.087
    /// (Bäumel–Seeger uniform material law for steels).
    pub strength_exponent: f64,
}

impl FatigueSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number(
            "neck_offset",
            "m",
            "distance of the neck section from the head's hinge centre toward the link's centre",
        ),
        FieldDoc::number(
            "seat_offset",
            "m",
            "distance of the seat section from the seat's hinge centre toward the link's centre",
        ),
        FieldDoc::number(
            "head_bore_diameter",
            "m",
            "bore of the ball head and its neck (the neck section's inner diameter)",
        ),
        FieldDoc::number(
            "seat_bore_diameter",
            "m",
            "bore of the ball seat's tube (the body and seat sections' inner diameter)",
        ),
        FieldDoc::number(
            "neck_scf",
            "-",
            "stress concentration factor K_t of the neck section",
        ),
        FieldDoc::number(
            "body_scf",
            "-",
            "stress concentration factor K_t of the body section (the link's centre)",
        ),
        FieldDoc::number(
            "seat_scf",
            "-",
            "stress concentration factor K_t of the seat section",
        ),
        FieldDoc::number(
            "ultimate_strength",
            "Pa",
            "ultimate tensile strength σ_u of the link steel (Goodman's mean-stress correction)",
        ),
        FieldDoc::number(
            "strength_coefficient",
            "Pa",
            "Basquin fatigue strength coefficient σ′_f: fully reversed amplitude σ′_f·(2N)^b",
        ),
        FieldDoc::number(
            "strength_exponent",
            "-",
            "Basquin fatigue strength exponent b (negative)",
        ),
    ];

    /// Checks each field, and the sections against the link's dimensions
    /// (`pipe.pitch`, `pipe.neck_radius`, `pipe.link_diameter`).
    pub(super) fn validate(&self, pipe: LinkSize) -> Result<(), SceneError> {
        for (name, v) in [
            ("neck_offset", self.neck_offset),
            ("seat_offset", self.seat_offset),
            ("head_bore_diameter", self.head_bore_diameter),
            ("seat_bore_diameter", self.seat_bore_diameter),
            ("ultimate_strength", self.ultimate_strength),
            ("strength_coefficient", self.strength_coefficient),
        ] {
            positive(&format!("fatigue.{name}"), v)?;
        }
        for (name, v) in [
            ("neck_offset", self.neck_offset),
            ("seat_offset", self.seat_offset),
        ] {
            if v >= pipe.pitch {
                return Err(SceneError::new(
                    format!("fatigue.{name}"),
                    v,
                    format!(
                        "must be shorter than the link, pipe.pitch = {} m",
                        pipe.pitch
                    ),
                ));
            }
        }
        for (name, v) in [
            ("neck_scf", self.neck_scf),
            ("body_scf", self.body_scf),
            ("seat_scf", self.seat_scf),
        ] {
            if !(v.is_finite() && v >= 1.0) {
                return Err(SceneError::new(
                    format!("fatigue.{name}"),
                    v,
                    "must be a finite number of at least 1 (a notch raises the nominal stress)",
                ));
            }
        }
        if !(self.strength_exponent.is_finite()
            && self.strength_exponent < 0.0
            && self.strength_exponent > -1.0)
        {
            return Err(SceneError::new(
                "fatigue.strength_exponent",
                self.strength_exponent,
                "must lie in (-1, 0): Basquin's b is negative, about -0.05 to -0.15 for steels",
            ));
        }
        self.validate_bores(pipe)
    }

    fn validate_bores(&self, pipe: LinkSize) -> Result<(), SceneError> {
        if pipe.neck_radius > 0.0 && self.head_bore_diameter >= 2.0 * pipe.neck_radius {
            return Err(SceneError::new(
                "fatigue.head_bore_diameter",
                self.head_bore_diameter,
                format!(
                    "must be smaller than the neck's diameter 2·pipe.neck_radius = {} m",
                    2.0 * pipe.neck_radius
                ),
            ));
        }
        if self.seat_bore_diameter >= pipe.link_diameter {
            return Err(SceneError::new(
                "fatigue.seat_bore_diameter",
                self.seat_bore_diameter,
                format!(
                    "must be smaller than the link's diameter pipe.link_diameter = {} m",
                    pipe.link_diameter
                ),
            ));
        }
        Ok(())
    }
}

/// The link's dimensions the sections are checked against [m].
#[derive(Debug, Clone, Copy)]
pub(super) struct LinkSize {
    /// `pipe.pitch`.
    pub pitch: f64,
    /// `pipe.neck_radius` (0: no neck).
    pub neck_radius: f64,
    /// `pipe.link_diameter`.
    pub link_diameter: f64,
}

impl Default for FatigueSpec {
    fn default() -> Self {
        Self {
            neck_offset: 0.030,
            seat_offset: 0.032,
            head_bore_diameter: 0.030,
            seat_bore_diameter: 0.064,
            neck_scf: 2.0,
            body_scf: 1.0,
            seat_scf: 2.0,
            ultimate_strength: 9.8e8,
            strength_coefficient: 1.47e9,
            strength_exponent: -0.087,
        }
    }
}
