//! The drill-pipe scene document: engineering parameters with the paper's
//! defaults, and their validation. Units are SI (lengths in m, masses in kg)
//! except where a field name says `_deg` or `_rpm`; contact laws keep the
//! paper's N-mm-s field units, converted once on assembly. Where each
//! default comes from (the paper, a rule, or a PROPOSAL with its plausible
//! range) is listed once, by dotted key, in `provenance.rs`.

use serde::{Deserialize, Serialize};

use super::fatigue::{FatigueSpec, LinkSize};
use crate::error::SceneError;
use crate::scene::{
    DivergenceSpec, FieldDoc, FieldUnits, FrictionLawSpec, IntegratorKind, LineLawSpec, NewtonSpec,
    NormalLawSpec, RecordSpec, SimulationSpec, TableChoice, TableKind, finite, law_field,
    non_negative, positive,
};

/// The guide tube (borehole) [m, deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BoreholeSpec {
    /// Centreline curvature radius R [m]. Paper: 1.5.
    pub curvature_radius: f64,
    /// Build angle of the arc, from vertical [deg]. Paper: 90.
    pub build_angle_deg: f64,
    /// Guide tube inner diameter [m]. Paper (Table 1): 0.116.
    pub inner_diameter: f64,
    /// Length [m] of a link's part inside over which its wall contact is
    /// taken up where it crosses an open end of the tube. PROPOSAL: the
    /// paper's tube has sharp ends, whose contact jumps.
    pub end_engagement: f64,
}

impl BoreholeSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number(
            "curvature_radius",
            "m",
            "centreline curvature radius R of the guide tube",
        ),
        FieldDoc::number(
            "build_angle_deg",
            "deg",
            "build angle of the arc, from vertical",
        ),
        FieldDoc::number("inner_diameter", "m", "guide tube inner diameter D"),
        FieldDoc::number(
            "end_engagement",
            "m",
            "the tube's open ends: length of a link's part inside over which its wall contact is \
             taken up (an Adams STEP from 0; 0 = at once, a jump)",
        ),
    ];
}

impl Default for BoreholeSpec {
    fn default() -> Self {
        Self {
            curvature_radius: 1.5,
            build_angle_deg: 90.0,
            inner_diameter: 0.116,
            end_engagement: crate::scene::DEFAULT_END_ENGAGEMENT,
        }
    }
}

/// Hinge model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum HingeModel {
    /// The paper's model: cage and six ball keys per hinge, all contacts analytic.
    #[default]
    BallKeys,
    /// Reduced model: ideal constant-velocity joints, link–tube contacts only.
    IdealCv,
    /// The paper's hinge with its cage and keys quasi-static (issue 28):
    /// the same bodies, contacts and laws as `ball-keys`, but at every force
    /// evaluation the cage and keys are solved for equilibrium between the
    /// two links, which they act on as a force element; they move with the
    /// mean of the links' motions (the bisecting plane). Experimental: the
    /// paper's scene stops at 22 ms (docs/engine.md, "Quasi-static bodies").
    BallKeysQs,
}

/// How the lower connector is held (docs/paper.md, "The chain's end restraint").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum LowerEnd {
    /// The paper's: the centre of mass is held, the connector only spins
    /// about the tube's end tangent.
    #[default]
    Fixed,
    /// The connector also slides along the tube's end tangent and carries
    /// `load.axial_force` (weight on bit or overpull): the chain's length
    /// is free at its lower end.
    AxiallyFree,
}

/// Ball-cage joint dimensions and masses (docs/model.md §3) [m, kg, kg·m², deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BallKeySpec {
    /// Ball key radius r_b [m]: Ø15 mm.
    pub ball_radius: f64,
    /// Ball key mass [kg]: steel Ø15 sphere.
    pub ball_mass: f64,
    /// Pitch radius of the ball set, PCR [m]. PROPOSAL: 31.5 mm (cage mid-surface).
    pub pitch_radius: f64,
    /// Groove-centre offset per race, c [m]. PROPOSAL: 4 mm.
    pub groove_offset: f64,
    /// Gothic-arch flank radius ρ_g [m]. PROPOSAL: 30 mm (flank offset
    /// a = ρ_g − r_b − s = 22.49 mm, nearly straight flanks at ±45°): under
    /// the paper's soft law a key sinks 0.61 mm at its 33.5 kN peak, and the
    /// contact angle opens as cos α′ = a·cos α/(a + s + δ), so a close arch
    /// (7.8 mm, a = 0.29 mm) runs at 75–80°; this one stays within 4° of 45°
    /// (docs/model.md §3). The IMPACT law's stiffness does not depend on the
    /// conformity, so only the angle changes.
    pub groove_radius: f64,
    /// Flank contact angle α [deg]. PROPOSAL: 45.
    pub contact_angle_deg: f64,
    /// Ball–flank clearance per flank [m]. PROPOSAL: 0.01 mm.
    pub flank_clearance: f64,
    /// Ball head sphere radius [m]. PROPOSAL: 30.99 mm.
    pub head_radius: f64,
    /// Cage inner sphere radius [m] (Table 1: 31 mm).
    pub cage_inner_radius: f64,
    /// Cage outer sphere radius [m] (Table 1: 32 mm).
    pub cage_outer_radius: f64,
    /// Ball seat sphere radius [m]. PROPOSAL: 32.01 mm.
    pub seat_radius: f64,
    /// Cage mass [kg] (64/62 × 40 mm shell less six windows).
    pub cage_mass: f64,
    /// Cage principal inertia, axial then transverse [kg·m²].
    pub cage_inertia: [f64; 3],
    /// Window width along the cage axis [m]. PROPOSAL: 15.03 mm.
    pub window_axial_width: f64,
    /// Window length around the cage [m]. PROPOSAL: 16.1 mm.
    pub window_length: f64,
    /// Cage length along its axis [m] (Table 1: 40 mm): its end openings,
    /// cut at ±half of it, must let the neck pass farther than the seat's
    /// mouth does (checked).
    pub cage_length: f64,
    /// Distance from the hinge centre to the seat's mouth, toward the head
    /// [m]. PROPOSAL (a reading of Table 1): 20 mm, the head (104 mm) and
    /// seat (136 mm) overlapping by 40 mm in the 200 mm pitch, read as
    /// centred on the hinge (docs/model.md §3). The mouth
    /// is the seat's sphere cut there: radius √(seat_radius² − offset²).
    pub mouth_offset: f64,
}

impl BallKeySpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number("ball_radius", "m", "ball key radius r_b"),
        FieldDoc::number("ball_mass", "kg", "ball key mass"),
        FieldDoc::number("pitch_radius", "m", "pitch radius of the ball set, PCR"),
        FieldDoc::number("groove_offset", "m", "groove-centre offset per race, c"),
        FieldDoc::number("groove_radius", "m", "Gothic-arch flank radius ρ_g"),
        FieldDoc::number("contact_angle_deg", "deg", "flank contact angle α"),
        FieldDoc::number("flank_clearance", "m", "ball-flank clearance per flank"),
        FieldDoc::number("head_radius", "m", "ball head sphere radius"),
        FieldDoc::number("cage_inner_radius", "m", "cage inner sphere radius"),
        FieldDoc::number("cage_outer_radius", "m", "cage outer sphere radius"),
        FieldDoc::number("seat_radius", "m", "ball seat sphere radius"),
        FieldDoc::number("cage_mass", "kg", "cage mass"),
        FieldDoc::number(
            "cage_inertia",
            "kg·m²",
            "cage principal inertia, axial then transverse",
        ),
        FieldDoc::number(
            "window_axial_width",
            "m",
            "window width along the cage axis",
        ),
        FieldDoc::number("window_length", "m", "window length around the cage"),
        FieldDoc::number("cage_length", "m", "cage length along its axis"),
        FieldDoc::number(
            "mouth_offset",
            "m",
            "distance from the hinge centre to the seat's mouth, toward the head",
        ),
    ];
}

impl Default for BallKeySpec {
    fn default() -> Self {
        Self {
            ball_radius: 0.0075,
            ball_mass: 0.013872,
            pitch_radius: 0.0315,
            groove_offset: 0.004,
            groove_radius: 0.030,
            contact_angle_deg: 45.0,
            flank_clearance: 1e-5,
            head_radius: 0.03099,
            cage_inner_radius: 0.031,
            cage_outer_radius: 0.032,
            seat_radius: 0.03201,
            cage_mass: 0.0515,
            cage_inertia: [5.1e-5, 3.2e-5, 3.2e-5],
            window_axial_width: 0.01503,
            window_length: 0.0161,
            cage_length: 0.040,
            mouth_offset: 0.020,
        }
    }
}

/// Ideal constant-velocity hinge: penalty joint parameters [SI, deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IdealCvSpec {
    /// Hinge-point spring [N/m]. PROPOSAL: 1e9 (1.2 µm under the 1.2 kN hinge shear).
    pub stiffness: f64,
    /// Hinge-point damper [N·s/m]. PROPOSAL: 1.3e5 (about critical for two 8 kg links).
    pub damping: f64,
    /// Twist spring [N·m/rad]. PROPOSAL: 1.1e5, the ball-key hinge's tangent stiffness at 1.8 kN·m if the 45° contact angle held (docs/model.md §7.9; with the default groove the angle opens and the section model gives about 1.7e5 tangent, 6.9e4 secant).
    pub twist_stiffness: f64,
    /// Twist damper [N·m·s/rad]. PROPOSAL: 60 (about critical for a link's spin inertia).
    pub twist_damping: f64,
}

impl IdealCvSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number("stiffness", "N/m", "hinge-point spring"),
        FieldDoc::number("damping", "N·s/m", "hinge-point damper"),
        FieldDoc::number("twist_stiffness", "N·m/rad", "twist spring"),
        FieldDoc::number("twist_damping", "N·m·s/rad", "twist damper"),
    ];
}

impl Default for IdealCvSpec {
    fn default() -> Self {
        Self {
            stiffness: 1e9,
            damping: 1.3e5,
            twist_stiffness: 1.1e5,
            twist_damping: 60.0,
        }
    }
}

/// The chain [m, kg, kg·m²].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PipeSpec {
    /// Number of flexible joints (links). Paper: 12.
    pub joints: usize,
    /// Hinge model.
    pub hinge: HingeModel,
    /// Hinge-to-hinge pitch, one link's length [m]. Paper: 0.2.
    pub pitch: f64,
    /// Link outer diameter for tube contact [m]. Paper (Table 1): 0.086.
    pub link_diameter: f64,
    /// Link mass [kg]. PROPOSAL (a reading: the paper gives no mass): the
    /// 86/30 × 200 mm steel envelope.
    pub link_mass: f64,
    /// Link principal inertia, axial then transverse [kg·m²].
    pub link_inertia: [f64; 3],
    /// Connector length [m] (Table 1: 200 mm).
    pub connector_length: f64,
    /// Connector outer diameter [m] (Table 1: 122 mm).
    pub connector_diameter: f64,
    /// Connector mass [kg].
    pub connector_mass: f64,
    /// Connector principal inertia, axial then transverse [kg·m²].
    pub connector_inertia: [f64; 3],
    /// Sample points along each link (rims included) that bracket the
    /// extrema of its depth in the tube (or, with `"patches"`, locate its
    /// contact patches); the force does not depend on this count once each
    /// extremum has a bracket of its own, and a maximum–minimum pair born
    /// between two samples is found from the samples' slopes. Default 9
    /// (25 mm apart), a numerical setting, not a PROPOSAL. On the paper run
    /// at the default integrator (2026-11-26) every compared quantity at 5,
    /// 9, 17 and 33 samples is within 0.35 % of the two-method reference
    /// computed at 33 (0.6 s and 1.8 s; at 9: 0.11 % and 0.042 %), the
    /// spread of the counts no larger than the run's own error, with the
    /// same number of rejected steps within 6 %; 9 instead of 33 takes 10 %
    /// fewer instructions (docs/performance.md).
    pub tube_contact_points: u32,
    /// How a link's line contact with the tube becomes point laws:
    /// `"level-sets"` (the IMPACT law at every depth maximum minus the law
    /// at every interior depth minimum: continuous in the link's pose, the
    /// gradient of an energy) or `"patches"` (Adams' one law per patch,
    /// which jumps when patches merge). PROPOSAL: level-sets
    /// (docs/model.md §4).
    pub tube_contact_law: LineLawSpec,
    /// Radius of the ball head's neck, the shaft between the head sphere and
    /// its link [m]. PROPOSAL: 19 mm (Ø38 over the Ø30 bore).
    /// The neck meets the seat's mouth at the articulation limit
    /// β_max = acos(r_neck/R_s) − asin(d_m/R_s) (14.92° by default;
    /// docs/model.md §3), through a contact pair with the joint's internal
    /// law, in both hinge models. 0 builds no neck contact: the hinges bend
    /// freely.
    pub neck_radius: f64,
    /// Radius of the rounded edge of each link's end rim [m], for the
    /// contact pressure of a rim on the tube (a sharp edge has no Hertz
    /// solution). PROPOSAL: 2 mm; the rim pressure goes as about
    /// r_e^(−0.4) (docs/model.md, "Contact pressure"). Used only by the
    /// pressure and wear outputs.
    pub link_edge_radius: f64,
    /// Ball-cage joint details (used by `hinge = "ball-keys"`; its seat
    /// and cage dimensions also set the articulation limit of both models).
    pub ball_keys: BallKeySpec,
    /// Ideal CV joint details (used by `hinge = "ideal-cv"`).
    pub ideal_cv: IdealCvSpec,
    /// How the lower connector is held: `"fixed"` (the paper's: its centre
    /// of mass held, spin only) or `"axially-free"` (it also slides along
    /// the tube's end tangent, loaded by `load.axial_force`).
    pub lower_end: LowerEnd,
}

impl PipeSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number("joints", "-", "number of flexible joints (links)"),
        FieldDoc::text(
            "hinge",
            "hinge model: ball-keys, ideal-cv, or ball-keys-qs (cage and keys quasi-static; experimental: \
             stops at 22 ms on the paper's scene, docs/engine.md)",
        ),
        FieldDoc::number("pitch", "m", "hinge-to-hinge pitch, one link's length"),
        FieldDoc::number("link_diameter", "m", "link outer diameter for tube contact"),
        FieldDoc::number("link_mass", "kg", "link mass"),
        FieldDoc::number(
            "link_inertia",
            "kg·m²",
            "link principal inertia, axial then transverse",
        ),
        FieldDoc::number("connector_length", "m", "connector length"),
        FieldDoc::number("connector_diameter", "m", "connector outer diameter"),
        FieldDoc::number("connector_mass", "kg", "connector mass"),
        FieldDoc::number(
            "connector_inertia",
            "kg·m²",
            "connector principal inertia, axial then transverse",
        ),
        FieldDoc::number(
            "tube_contact_points",
            "-",
            "sample points along each link that bracket the extrema of its depth in the tube",
        ),
        FieldDoc::text(
            "tube_contact_law",
            "link-tube line contact as points: level-sets (continuous) or patches (Adams, jumps)",
        ),
        FieldDoc::number(
            "neck_radius",
            "m",
            "radius of the ball head's neck; 0 builds no neck contact",
        ),
        FieldDoc::number(
            "link_edge_radius",
            "m",
            "radius of the rounded edge of each link's end rim (pressure and wear outputs)",
        ),
        FieldDoc::table(
            "ball_keys",
            "ball-cage joint dimensions and masses",
            BallKeySpec::FIELDS,
        ),
        FieldDoc::table(
            "ideal_cv",
            "ideal constant-velocity hinge parameters",
            IdealCvSpec::FIELDS,
        ),
        FieldDoc::text(
            "lower_end",
            "how the lower connector is held: fixed (centre held, spin only; the paper's) or \
             axially-free (also slides along the tube's end tangent, loaded by load.axial_force)",
        ),
    ];
}

impl Default for PipeSpec {
    fn default() -> Self {
        Self {
            joints: 12,
            hinge: HingeModel::BallKeys,
            pitch: 0.2,
            link_diameter: 0.086,
            link_mass: 8.010,
            link_inertia: [8.306e-3, 3.085e-2, 3.085e-2],
            connector_length: 0.2,
            connector_diameter: 0.122,
            connector_mass: 17.243,
            connector_inertia: [3.402e-2, 7.449e-2, 7.449e-2],
            tube_contact_points: 9,
            tube_contact_law: LineLawSpec::LevelSets,
            neck_radius: 0.019,
            link_edge_radius: 0.002,
            ball_keys: BallKeySpec::default(),
            ideal_cv: IdealCvSpec::default(),
            lower_end: LowerEnd::Fixed,
        }
    }
}

/// The drive on the upper connector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DriveSpec {
    /// Drive speed [rpm]. Paper: 100.
    pub speed_rpm: f64,
    /// STEP ramp from rest to full speed [s]. PROPOSAL: 0.3 (the paper gives none).
    pub ramp: f64,
}

impl DriveSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number("speed_rpm", "rpm", "drive speed of the upper connector"),
        FieldDoc::number("ramp", "s", "STEP ramp from rest to full speed"),
    ];
}

impl Default for DriveSpec {
    fn default() -> Self {
        Self {
            speed_rpm: 100.0,
            ramp: 0.3,
        }
    }
}

/// The loads on the lower connector: the resisting moment and an axial force.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ResistingMomentSpec {
    /// Resisting moment, opposing the spin [N·m]. Paper: 1800.
    pub resisting_moment: f64,
    /// STEP ramp of both loads [s]; 0 applies them at once. PROPOSAL: 0.3.
    pub ramp: f64,
    /// Axial force on the lower connector along the tube's end tangent [N]:
    /// positive pulls it downhole, away from the chain (tension, overpull),
    /// negative pushes it uphole into the chain (compression, weight on
    /// bit). Needs `pipe.lower_end = "axially-free"`. Default 0 (the paper
    /// applies none).
    pub axial_force: f64,
}

impl ResistingMomentSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number(
            "resisting_moment",
            "N·m",
            "resisting moment on the lower connector, opposing the spin",
        ),
        FieldDoc::number(
            "ramp",
            "s",
            "STEP ramp of the moment and the axial force; 0 applies them at once",
        ),
        FieldDoc::number(
            "axial_force",
            "N",
            "axial force on the lower connector along the tube's end tangent: positive = tension \
             (overpull, pulls it downhole), negative = compression (weight on bit); needs \
             pipe.lower_end = \"axially-free\"",
        ),
    ];

    /// The axial force: finite, and only on an axially free lower end.
    fn validate_axial_force(&self, lower_end: LowerEnd) -> Result<(), SceneError> {
        finite("load.axial_force", self.axial_force)?;
        if self.axial_force != 0.0 && lower_end == LowerEnd::Fixed {
            return Err(SceneError::new(
                "load.axial_force",
                self.axial_force,
                "needs pipe.lower_end = \"axially-free\": with the fixed lower end the connector's \
                 centre is held, so the force would only be carried by that restraint and change nothing",
            ));
        }
        Ok(())
    }
}

impl Default for ResistingMomentSpec {
    fn default() -> Self {
        Self {
            resisting_moment: 1800.0,
            ramp: 0.3,
            axial_force: 0.0,
        }
    }
}

/// A contact material: normal law and friction. The paper's (§2.3 eqs.
/// (6)–(7)); its stiffness K is a PROPOSAL (a reading: the paper prints
/// 1e5 N/mm, with n = 2.2 Adams' default 1e5 N/mm^2.2; docs/model.md §1.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Normal law.
    pub normal: NormalLawSpec,
    /// Friction law.
    pub friction: FrictionLawSpec,
}

impl MaterialSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::law("normal", "normal force law", law_field),
        FieldDoc::law("friction", "friction law", law_field),
    ];
}

fn paper_impact() -> NormalLawSpec {
    NormalLawSpec::Impact {
        stiffness: 1e5,
        exponent: 2.2,
        damping: 10.0,
        depth_max: 0.1,
        units: FieldUnits::NMmS,
    }
}

fn adams(mu_static: f64, mu_dynamic: f64) -> FrictionLawSpec {
    FrictionLawSpec::Adams {
        mu_static,
        mu_dynamic,
        v_static: 100.0,
        v_dynamic: 1000.0,
        units: FieldUnits::NMmS,
    }
}

/// A solid of the pipe's parts: elasticity for the Hertz contact pressure,
/// hardness for Archard wear, and the pressure it may carry [Pa, –]. Used
/// only by the pressure and wear outputs, never by the contact laws.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolidSpec {
    /// Young's modulus E [Pa].
    pub youngs_modulus: f64,
    /// Poisson's ratio ν [–].
    pub poisson_ratio: f64,
    /// Indentation hardness H [Pa] (Vickers hardness as a pressure: HV × 9.807 MPa).
    pub hardness: f64,
    /// Largest static peak contact pressure p₀ the surface may carry [Pa].
    pub allowable_pressure: f64,
}

impl SolidSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number("youngs_modulus", "Pa", "Young's modulus E"),
        FieldDoc::number("poisson_ratio", "-", "Poisson's ratio ν"),
        FieldDoc::number("hardness", "Pa", "indentation hardness H, for Archard wear"),
        FieldDoc::number(
            "allowable_pressure",
            "Pa",
            "largest static peak contact pressure p₀ the surface may carry",
        ),
    ];

    /// 35CrMo, quenched and tempered, the paper's material for the guide
    /// tube and the drill pipe: E 210 GPa and ν 0.3 as the paper gives them.
    /// PROPOSAL: hardness HV 300 (2.94 GPa; Q&T 35CrMo is HB 270–300) and
    /// the allowable p₀ = 1.60·σ_y = 1.336 GPa, where a Hertz point contact
    /// first yields below the surface (Johnson, *Contact Mechanics*, 1985,
    /// §6.2, ν = 0.3), with σ_y ≥ 835 MPa (GB/T 3077).
    fn pipe_steel() -> Self {
        Self {
            youngs_modulus: 2.1e11,
            poisson_ratio: 0.3,
            hardness: 2.94e9,
            allowable_pressure: 1.336e9,
        }
    }

    /// Through-hardened bearing steel (GCr15 / 100Cr6, 60–64 HRC) for the
    /// ball keys. PROPOSAL: E 208 GPa, ν 0.3, hardness HV 750 (7.36 GPa),
    /// allowable p₀ 4.2 GPa, the static rating of ball bearings (ISO 76).
    fn key_steel() -> Self {
        Self {
            youngs_modulus: 2.08e11,
            poisson_ratio: 0.3,
            hardness: 7.36e9,
            allowable_pressure: 4.2e9,
        }
    }

    fn validate(&self, path: &str) -> Result<(), SceneError> {
        positive(&format!("{path}.youngs_modulus"), self.youngs_modulus)?;
        finite(&format!("{path}.poisson_ratio"), self.poisson_ratio)?;
        if !(0.0..0.5).contains(&self.poisson_ratio) {
            return Err(SceneError::new(
                format!("{path}.poisson_ratio"),
                self.poisson_ratio,
                "must lie in [0, 0.5)",
            ));
        }
        positive(&format!("{path}.hardness"), self.hardness)?;
        if self.hardness < MIN_HARDNESS {
            // Found by fuzzing (fuzz/regressions/tiny-hardness-nan-wear.toml):
            // 3e-319 Pa made the wear rate k/H infinite and the wear volume NaN.
            return Err(SceneError::new(
                format!("{path}.hardness"),
                self.hardness,
                format!(
                    "must be at least {MIN_HARDNESS:e} Pa (1 MPa: any solid that carries a contact is far \
                     harder, HV 300 steel is 2.94e9 Pa; a smaller value makes the Archard wear rate k/H overflow)"
                ),
            ));
        }
        positive(
            &format!("{path}.allowable_pressure"),
            self.allowable_pressure,
        )
    }
}

/// The smallest indentation hardness a material may have [Pa].
const MIN_HARDNESS: f64 = 1e6;

/// The two contact materials of the paper, and the two solids.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MaterialsSpec {
    /// Link–guide tube (dry): μs 0.3, μd 0.1.
    pub tube: MaterialSpec,
    /// Inside the joints (lubricated): μs 0.1, μd 0.01.
    pub internal: MaterialSpec,
    /// The links, connectors, ball heads and seats, cages and the guide
    /// tube: 35CrMo (the paper).
    pub pipe_steel: SolidSpec,
    /// The ball keys: bearing steel (PROPOSAL).
    pub key_steel: SolidSpec,
}

impl MaterialsSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::table(
            "tube",
            "link-guide tube contact (dry)",
            MaterialSpec::FIELDS,
        ),
        FieldDoc::table(
            "internal",
            "contacts inside the joints (lubricated)",
            MaterialSpec::FIELDS,
        ),
        FieldDoc::table(
            "pipe_steel",
            "the solid of the links, connectors, heads, seats, cages and tube",
            SolidSpec::FIELDS,
        ),
        FieldDoc::table("key_steel", "the solid of the ball keys", SolidSpec::FIELDS),
    ];
}

impl Default for MaterialsSpec {
    fn default() -> Self {
        Self {
            tube: MaterialSpec {
                normal: paper_impact(),
                friction: adams(0.3, 0.1),
            },
            internal: MaterialSpec {
                normal: paper_impact(),
                friction: adams(0.1, 0.01),
            },
            pipe_steel: SolidSpec::pipe_steel(),
            key_steel: SolidSpec::key_steel(),
        }
    }
}

/// Archard wear coefficients k [–] of the `wear` table: wear volume
/// V = k·∫F_n ds / H. The wear figures scale with k, which spans orders of
/// magnitude between conditions and no simulation sets; ∫F_n ds is the
/// simulated quantity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WearSpec {
    /// Link–guide tube, dry steel on steel in mild wear. PROPOSAL: 1e-4
    /// (mild wear of metals, 1e-5–1e-3: Hutchings & Shipway, *Tribology*,
    /// 2nd ed., 2017, §5.3).
    pub tube_coefficient: f64,
    /// Inside the joints, boundary-lubricated steel. PROPOSAL: 1e-7
    /// (lubricated, 1e-6–1e-9: ibid.).
    pub internal_coefficient: f64,
    /// Mean contact pressure [Pa] below which a contact wears nothing in
    /// the wear map (`wear_map.parquet`). Setting: 0, no threshold.
    pub threshold_pressure: f64,
    /// Length [m] of a wear map cell along the tube's centreline, a link's
    /// axis and a race's axis. Setting: 0.01.
    pub map_cell_length: f64,
    /// Angle [deg] of a wear map cell around the tube's wall and a link's
    /// surface. Setting: 5.
    pub map_cell_angle_deg: f64,
    /// Wear depth [m] whose hours the wear map reports. Setting: 1e-4.
    pub map_depth: f64,
}

impl Default for WearSpec {
    fn default() -> Self {
        Self {
            tube_coefficient: 1e-4,
            internal_coefficient: 1e-7,
            threshold_pressure: 0.0,
            map_cell_length: 0.01,
            map_cell_angle_deg: 5.0,
            map_depth: 1e-4,
        }
    }
}

impl WearSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number(
            "tube_coefficient",
            "-",
            "Archard wear coefficient k of the link-guide tube contacts",
        ),
        FieldDoc::number(
            "internal_coefficient",
            "-",
            "Archard wear coefficient k of the contacts inside the joints",
        ),
        FieldDoc::number(
            "threshold_pressure",
            "Pa",
            "mean contact pressure below which a contact wears nothing (wear map; 0: no threshold)",
        ),
        FieldDoc::number(
            "map_cell_length",
            "m",
            "wear map cell length along the tube's centreline, a link's axis and a race's axis",
        ),
        FieldDoc::number(
            "map_cell_angle_deg",
            "deg",
            "wear map cell angle around the tube's wall and a link's surface",
        ),
        FieldDoc::number(
            "map_depth",
            "m",
            "wear depth whose hours of the run's duty the wear map reports",
        ),
    ];

    fn validate(&self) -> Result<(), SceneError> {
        for (key, k) in [
            ("wear.tube_coefficient", self.tube_coefficient),
            ("wear.internal_coefficient", self.internal_coefficient),
        ] {
            non_negative(key, k)?;
            if k > 1.0 {
                return Err(SceneError::new(
                    key,
                    k,
                    "must not exceed 1 (Archard's k is the fraction of asperity contacts that make a wear \
                     particle: 1e-4 dry, 1e-7 lubricated steel)",
                ));
            }
        }
        non_negative("wear.threshold_pressure", self.threshold_pressure)?;
        positive("wear.map_cell_length", self.map_cell_length)?;
        positive("wear.map_cell_angle_deg", self.map_cell_angle_deg)?;
        if self.map_cell_angle_deg > 360.0 {
            return Err(SceneError::new(
                "wear.map_cell_angle_deg",
                self.map_cell_angle_deg,
                "must not exceed 360 (a cell cannot go round the wall more than once)",
            ));
        }
        positive("wear.map_depth", self.map_depth)
    }
}

/// Gravity magnitude, pointing along −z (z up).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GravitySpec {
    /// [m/s²]. Paper: 9.8.
    pub gravity: f64,
}

impl GravitySpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[FieldDoc::number(
        "gravity",
        "m/s²",
        "gravity's magnitude, pointing along -z",
    )];
}

impl Default for GravitySpec {
    fn default() -> Self {
        Self { gravity: 9.8 }
    }
}

/// A drill-pipe scene. Every section has the paper's defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DrillPipeSpec {
    /// Always `"drill-pipe"`.
    pub kind: String,
    /// Scene name; empty (the default) names the scene after its chain,
    /// tube and loads ([`DrillPipeSpec::title`]).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub name: String,
    /// Time stepping. The paper's 1 ms is the output interval, not the step.
    /// Default: the adaptive ESDIRK3(2) at `simulation.rtol` = 1e-4, steps
    /// up to the output interval; every compared quantity within 0.2 % of
    /// the two-method reference over 0.6 s and 1.8 s (docs/accuracy.md).
    /// `simulation.rtol = 0` gives fixed steps of `simulation.dt` (100 µs).
    /// `ballcage run --verify` and `ballcage accuracy` measure a run's
    /// error. Explicit
    /// integrators need 0.1 µs here: at 1 µs the lubricated key friction (a
    /// damper of rate ~4e6 1/s at 10 kN) chatters, and even 0.2 µs drifts
    /// once the keys carry their full load (docs/paper.md).
    pub simulation: SimulationSpec,
    /// Gravity.
    pub world: GravitySpec,
    /// Guide tube.
    pub borehole: BoreholeSpec,
    /// Chain.
    pub pipe: PipeSpec,
    /// Drive.
    pub drive: DriveSpec,
    /// Resisting moment and axial force.
    pub load: ResistingMomentSpec,
    /// Contact materials and solids.
    pub materials: MaterialsSpec,
    /// Archard wear coefficients of the `wear` table.
    pub wear: WearSpec,
    /// The critical sections of a link and its S–N curve (the fatigue output).
    pub fatigue: FatigueSpec,
    /// What to record.
    pub record: PipeRecordSpec,
}

/// The `kind` of a drill-pipe scene document.
pub const KIND: &str = "drill-pipe";

/// `simulation.rtol` of the paper's scene: ESDIRK3(2)'s adaptive steps (the
/// frames between them interpolated) at this tolerance keep every compared
/// quantity within 0.06 % of a reference two integrators agree on over the
/// 1.8 s and within 0.2 % over the first 0.6 s (3e-4 would keep 0.11 % and
/// 1.2 %: a peak tube force of the ramp misses the 1 %), at about three
/// times the speed of SDIRK2 at 100 µs (docs/accuracy.md,
/// `scripts/work_precision.py`). `simulation.dt` stays the 100 µs fixed step
/// a fixed-step integrator takes with `simulation.rtol = 0`.
pub const DEFAULT_RTOL: f64 = 1e-4;

impl DrillPipeSpec {
    /// The unit and meaning of every field of a drill-pipe document.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("kind", "always \"drill-pipe\""),
        FieldDoc::text(
            "name",
            "scene name; empty names the scene after its chain, tube and loads",
        ),
        FieldDoc::table("simulation", "time stepping", SimulationSpec::FIELDS),
        FieldDoc::table("world", "gravity", GravitySpec::FIELDS),
        FieldDoc::table("borehole", "the guide tube", BoreholeSpec::FIELDS),
        FieldDoc::table("pipe", "the chain", PipeSpec::FIELDS),
        FieldDoc::table(
            "drive",
            "the drive on the upper connector",
            DriveSpec::FIELDS,
        ),
        FieldDoc::table(
            "load",
            "the resisting moment and the axial force on the lower connector",
            ResistingMomentSpec::FIELDS,
        ),
        FieldDoc::table(
            "materials",
            "contact materials and solids",
            MaterialsSpec::FIELDS,
        ),
        FieldDoc::table(
            "wear",
            "Archard wear coefficients of the wear table",
            WearSpec::FIELDS,
        ),
        FieldDoc::table(
            "fatigue",
            "the critical sections of a link and its S-N curve (fatigue output)",
            FatigueSpec::FIELDS,
        ),
        FieldDoc::table("record", "what to record", PipeRecordSpec::FIELDS),
    ];

    /// The scene's name: `name` if set, else its chain, tube and loads, e.g.
    /// "12 ball-cage joints, R 1.5 m, 100 rpm, 1.8 kN·m", prefixed with
    /// "Zhu et al. 2023: " when those are the paper's.
    pub fn title(&self) -> String {
        if !self.name.is_empty() {
            return self.name.clone();
        }
        let hinge = match self.pipe.hinge {
            HingeModel::BallKeys => "ball-cage",
            HingeModel::BallKeysQs => "quasi-static ball-cage",
            HingeModel::IdealCv => "ideal-CV",
        };
        let what = format!(
            "{} {hinge} joints, R {} m, {} rpm, {} kN·m",
            self.pipe.joints,
            self.borehole.curvature_radius,
            self.drive.speed_rpm,
            self.load.resisting_moment / 1000.0
        );
        let paper = Self::default();
        let as_paper = self.pipe.joints == paper.pipe.joints
            && self.pipe.hinge == paper.pipe.hinge
            && self.borehole.curvature_radius == paper.borehole.curvature_radius
            && self.drive.speed_rpm == paper.drive.speed_rpm
            && self.load.resisting_moment == paper.load.resisting_moment;
        if as_paper {
            format!("Zhu et al. 2023: {what}")
        } else {
            what
        }
    }
}

impl Default for DrillPipeSpec {
    /// The paper's scene.
    fn default() -> Self {
        Self {
            kind: KIND.to_string(),
            name: String::new(),
            simulation: SimulationSpec {
                duration: 1.8,
                dt: 1e-4,
                output_interval: 1e-3,
                integrator: IntegratorKind::Esdirk32,
                newton: NewtonSpec::default(),
                divergence: DivergenceSpec::default(),
                threads: 1,
                max_steps: crate::scene::default_max_steps(),
                rtol: Some(DEFAULT_RTOL),
                atol: None,
                atol_position: None,
                atol_rotation: None,
                atol_velocity: None,
                atol_angular_velocity: None,
                max_step: None,
            },
            world: GravitySpec::default(),
            borehole: BoreholeSpec::default(),
            pipe: PipeSpec::default(),
            drive: DriveSpec::default(),
            load: ResistingMomentSpec::default(),
            materials: MaterialsSpec::default(),
            wear: WearSpec::default(),
            fatigue: FatigueSpec::default(),
            record: PipeRecordSpec::default(),
        }
    }
}

/// An output table of a drill-pipe scene: the engine's, or the drill pipe's own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PipeTable {
    /// The engine's `bodies` table.
    Bodies,
    /// The engine's `contacts` table.
    Contacts,
    /// The engine's `energy` table.
    Energy,
    /// The engine's `summary` table.
    Summary,
    /// Per link per frame: the paper's eq. (4) angles, position, offsets and tube force.
    Links,
    /// Per hinge per frame: bend angle and cage forces.
    Hinges,
    /// Per ball key per frame: race and window forces.
    Keys,
    /// Per frame: input/output torque, speed, power and efficiency.
    Drive,
    /// Once per run: what each contact pair is (feature, link, hinge, key, face).
    Pairs,
    /// Once per run, per contact pair: friction work, sliding, Archard wear
    /// and the peak contact pressure against the allowable.
    Wear,
}

impl PipeTable {
    /// The engine table this is, if it is one.
    pub fn engine(self) -> Option<TableKind> {
        match self {
            Self::Bodies => Some(TableKind::Bodies),
            Self::Contacts => Some(TableKind::Contacts),
            Self::Energy => Some(TableKind::Energy),
            Self::Summary => Some(TableKind::Summary),
            Self::Links | Self::Hinges | Self::Keys | Self::Drive | Self::Pairs | Self::Wear => {
                None
            }
        }
    }
}

impl TableChoice for PipeTable {
    /// Everything an engineer reads: the engine's bodies and contacts and
    /// the drill pipe's links, hinges, keys, drive, summary and pairs.
    fn defaults() -> Vec<Self> {
        vec![
            PipeTable::Bodies,
            PipeTable::Contacts,
            PipeTable::Links,
            PipeTable::Hinges,
            PipeTable::Keys,
            PipeTable::Drive,
            PipeTable::Summary,
            PipeTable::Pairs,
            PipeTable::Wear,
        ]
    }

    fn table_name(self) -> &'static str {
        match self {
            Self::Links => "links",
            Self::Hinges => "hinges",
            Self::Keys => "keys",
            Self::Drive => "drive",
            Self::Pairs => "pairs",
            Self::Wear => "wear",
            engine => engine.engine().map_or("", TableKind::name),
        }
    }
}

/// What a drill-pipe scene records: the engine's tables and the drill
/// pipe's (`links`, `hinges`, `keys`, `drive`, `pairs`, `wear`). `bodies` names parts (e.g.
/// `link03`); empty means the connectors and the links.
pub type PipeRecordSpec = RecordSpec<PipeTable>;

impl DrillPipeSpec {
    /// The document as TOML, every default written out.
    pub fn to_toml(&self) -> String {
        crate::scene::to_toml_text(self)
    }

    /// Checks every section; the first problem of each independent section
    /// is returned with its path, the first of them in the error and the
    /// others in its `more`.
    pub fn validate(&self) -> Result<(), SceneError> {
        if self.kind != KIND {
            return Err(SceneError::new(
                "kind",
                &self.kind,
                format!("a drill-pipe scene has kind = \"{KIND}\""),
            ));
        }
        SceneError::all([
            // the pipe is checked against the borehole: only once the borehole is valid
            self.borehole
                .validate()
                .and_then(|()| self.pipe.validate(&self.borehole)),
            non_negative("drive.ramp", self.drive.ramp),
            finite("drive.speed_rpm", self.drive.speed_rpm),
            finite("load.resisting_moment", self.load.resisting_moment),
            non_negative("load.ramp", self.load.ramp),
            self.load.validate_axial_force(self.pipe.lower_end),
            finite("world.gravity", self.world.gravity),
            self.materials.pipe_steel.validate("materials.pipe_steel"),
            self.materials.key_steel.validate("materials.key_steel"),
            self.wear.validate(),
            self.fatigue.validate(LinkSize {
                pitch: self.pipe.pitch,
                neck_radius: self.pipe.neck_radius,
                link_diameter: self.pipe.link_diameter,
            }),
            self.record.validate_tables(self.simulation.duration),
        ])
    }
}

/// Largest `borehole.curvature_radius` [m] accepted: 100 km, a bend no
/// drill pipe notices over its length, with f64 still resolving 1e-11 of it.
const MAX_CURVATURE_RADIUS: f64 = 1e5;

impl BoreholeSpec {
    fn validate(&self) -> Result<(), SceneError> {
        positive("borehole.curvature_radius", self.curvature_radius)?;
        if self.curvature_radius > MAX_CURVATURE_RADIUS {
            return Err(SceneError::new(
                "borehole.curvature_radius",
                self.curvature_radius,
                format!(
                    "must be at most {MAX_CURVATURE_RADIUS:e} m: beyond that the bend's geometry loses the \
                     micrometres contact needs (found by fuzzing: 1e308 m overflowed)"
                ),
            ));
        }
        positive("borehole.build_angle_deg", self.build_angle_deg)?;
        if self.build_angle_deg > 180.0 {
            return Err(SceneError::new(
                "borehole.build_angle_deg",
                self.build_angle_deg,
                "must be at most 180",
            ));
        }
        positive("borehole.inner_diameter", self.inner_diameter)?;
        non_negative("borehole.end_engagement", self.end_engagement)
    }
}

impl PipeSpec {
    fn validate(&self, borehole: &BoreholeSpec) -> Result<(), SceneError> {
        if self.joints == 0 {
            return Err(SceneError::new(
                "pipe.joints",
                self.joints,
                "needs at least one flexible joint",
            ));
        }
        if self.joints > 200 {
            return Err(SceneError::new(
                "pipe.joints",
                self.joints,
                "more than 200 joints is not a drill pipe this tool models",
            ));
        }
        positive("pipe.pitch", self.pitch)?;
        positive("pipe.link_diameter", self.link_diameter)?;
        positive("pipe.link_edge_radius", self.link_edge_radius)?;
        if self.link_diameter >= borehole.inner_diameter {
            return Err(SceneError::new(
                "pipe.link_diameter",
                self.link_diameter,
                format!(
                    "does not fit the guide tube (borehole.inner_diameter = {})",
                    borehole.inner_diameter
                ),
            ));
        }
        if 2.0 * borehole.curvature_radius <= self.pitch {
            return Err(SceneError::new(
                "borehole.curvature_radius",
                borehole.curvature_radius,
                format!("a {} m link cannot follow a bend this tight", self.pitch),
            ));
        }
        positive("pipe.connector_length", self.connector_length)?;
        positive("pipe.connector_diameter", self.connector_diameter)?;
        self.ideal_cv.validate()?;
        self.ball_keys.validate()?;
        non_negative("pipe.neck_radius", self.neck_radius)?;
        let (kb, r) = (&self.ball_keys, self.neck_radius);
        let mouth = kb.mouth_radius();
        if r >= mouth {
            return Err(SceneError::new(
                "pipe.neck_radius",
                r,
                format!(
                    "must be smaller than the seat's mouth, radius {mouth:.5} m \
                     (√(seat_radius² − mouth_offset²)), or the head cannot bend"
                ),
            ));
        }
        if r > 0.0 && kb.cage_rim_limit(r) < kb.mouth_limit(r) {
            return Err(SceneError::new(
                "pipe.neck_radius",
                r,
                format!(
                    "so thick a neck meets the cage's end rim at {:.2}° before the seat's mouth \
                     at {:.2}°; the model limits the bend at the mouth only: use a thinner neck",
                    kb.cage_rim_limit(r).to_degrees(),
                    kb.mouth_limit(r).to_degrees()
                ),
            ));
        }
        Ok(())
    }
}

impl IdealCvSpec {
    fn validate(&self) -> Result<(), SceneError> {
        for (name, v) in [
            ("stiffness", self.stiffness),
            ("twist_stiffness", self.twist_stiffness),
        ] {
            positive(&format!("pipe.ideal_cv.{name}"), v)?;
        }
        non_negative("pipe.ideal_cv.damping", self.damping)?;
        non_negative("pipe.ideal_cv.twist_damping", self.twist_damping)
    }
}

impl BallKeySpec {
    fn validate(&self) -> Result<(), SceneError> {
        for (name, v) in [
            ("ball_radius", self.ball_radius),
            ("ball_mass", self.ball_mass),
            ("pitch_radius", self.pitch_radius),
            ("groove_offset", self.groove_offset),
            ("groove_radius", self.groove_radius),
            ("contact_angle_deg", self.contact_angle_deg),
            ("head_radius", self.head_radius),
            ("cage_inner_radius", self.cage_inner_radius),
            ("cage_outer_radius", self.cage_outer_radius),
            ("seat_radius", self.seat_radius),
            ("cage_mass", self.cage_mass),
            ("window_axial_width", self.window_axial_width),
            ("window_length", self.window_length),
            ("cage_length", self.cage_length),
            ("mouth_offset", self.mouth_offset),
        ] {
            positive(&format!("pipe.ball_keys.{name}"), v)?;
        }
        non_negative("pipe.ball_keys.flank_clearance", self.flank_clearance)?;
        for (k, v) in self.cage_inertia.iter().enumerate() {
            positive(&format!("pipe.ball_keys.cage_inertia[{k}]"), *v)?;
        }
        self.validate_keys_in_place()?;
        if self.groove_radius <= self.ball_radius + self.flank_clearance {
            return Err(SceneError::new(
                "pipe.ball_keys.groove_radius",
                self.groove_radius,
                "must exceed ball_radius + flank_clearance (a Gothic arch wider than the ball)",
            ));
        }
        if !(self.head_radius < self.cage_inner_radius
            && self.cage_inner_radius < self.cage_outer_radius
            && self.cage_outer_radius < self.seat_radius)
        {
            return Err(SceneError::new(
                "pipe.ball_keys.head_radius",
                self.head_radius,
                "needs head_radius < cage_inner_radius < cage_outer_radius < seat_radius",
            ));
        }
        if self.mouth_offset >= self.seat_radius {
            return Err(SceneError::new(
                "pipe.ball_keys.mouth_offset",
                self.mouth_offset,
                format!(
                    "must be smaller than seat_radius = {} m, or the seat has no mouth",
                    self.seat_radius
                ),
            ));
        }
        if self.cage_length >= 2.0 * self.cage_inner_radius {
            return Err(SceneError::new(
                "pipe.ball_keys.cage_length",
                self.cage_length,
                format!(
                    "must be shorter than the cage's inner diameter {} m, or the cage has no end openings",
                    2.0 * self.cage_inner_radius
                ),
            ));
        }
        Ok(())
    }

    /// The keys sit in the cage's wall and meet their races at less than 90°.
    fn validate_keys_in_place(&self) -> Result<(), SceneError> {
        let (low, high) = (
            self.cage_inner_radius - self.ball_radius,
            self.cage_outer_radius + self.ball_radius,
        );
        if !(self.pitch_radius > low && self.pitch_radius < high) {
            return Err(SceneError::new(
                "pipe.ball_keys.pitch_radius",
                self.pitch_radius,
                format!(
                    "must put the keys through the cage's wall: between cage_inner_radius − ball_radius = {low} \
                     and cage_outer_radius + ball_radius = {high} m"
                ),
            ));
        }
        if self.contact_angle_deg >= 90.0 {
            return Err(SceneError::new(
                "pipe.ball_keys.contact_angle_deg",
                self.contact_angle_deg,
                "must be below 90 (the angle between the race's contact normal and the radial direction)",
            ));
        }
        Ok(())
    }
}
