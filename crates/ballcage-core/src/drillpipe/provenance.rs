//! Where each default of the drill-pipe document comes from
//! ([`crate::scene::provenance`]): the paper (Zhu et al., *Machines* 2023,
//! 11, 357: its section, table or equation), a rule applied to its values,
//! or a PROPOSAL with a plausible range and why. The `simulation` and
//! `record` sections are the engine's ([`crate::scene::provenance::ENGINE`]).
//!
//! One entry per numeric field of [`DrillPipeSpec`](super::DrillPipeSpec)
//! outside those sections; `tests/provenance.rs` fails when a default is
//! added without one. Ranges are in the field's unit as the default
//! document writes it: SI, degrees for `_deg`, N-mm-s for the contact laws.
//! The PROPOSAL entries are listed, with their defaults, in docs/proposals.md.
//! Masses and inertias take steel at ρ = 7850 kg/m³: the paper's "density
//! 76.93 kg/m³" is steel's specific weight, 76.93 kN/m³ (docs/model.md §0).

use crate::scene::{FieldOrigin, Source};

/// The provenance of every numeric default of the drill-pipe document
/// outside `simulation` and `record`.
pub const PROVENANCE: &[FieldOrigin] = &[
    // world, borehole
    FieldOrigin::paper("world.gravity", "§3: gravitational acceleration 9.8 m/s²"),
    FieldOrigin::paper(
        "borehole.curvature_radius",
        "§3: borehole curvature radius R = 1.5 m",
    ),
    FieldOrigin::paper(
        "borehole.build_angle_deg",
        "Table 1 row 2: the guide tube is 750π mm long, a quarter arc at R = 1.5 m",
    ),
    FieldOrigin::paper(
        "borehole.inner_diameter",
        "Table 1 row 2: guide tube ID 116 mm",
    ),
    FieldOrigin::proposal(
        "borehole.end_engagement",
        Source::Invented,
        "docs/model.md §4: the paper's tube has sharp open ends, where a link's wall contact vanishes \
         at once (a jump) as its last section inside leaves; taken up instead over 2 mm of the link's \
         part inside, about a broken edge's size",
        (0.0005, 0.01),
        "0.5 mm, a barely broken edge, to 10 mm, a generous entry chamfer; it acts only while a link \
         crossing an open end presses the wall, which in the paper's scene never happens",
    ),
    // pipe
    FieldOrigin::paper("pipe.joints", "§3: 12 flexible joints"),
    FieldOrigin::paper("pipe.pitch", "Table 1 row 4: flexible joint length 200 mm"),
    FieldOrigin::paper(
        "pipe.link_diameter",
        "Table 1 row 4: flexible joint OD 86 mm",
    ),
    FieldOrigin::proposal(
        "pipe.link_mass",
        Source::PaperReading,
        "the 86/30 × 200 mm envelope of Table 1 row 4 at ρ = 7850 kg/m³; the paper gives no link mass \
         and its density's unit is garbled (docs/model.md §0, §4)",
        (4.655, 8.01),
        "from the real link's head and seat alone (1.888 + 2.767 kg, docs/model.md §4) up to the \
         envelope; pipe.link_inertia stays the envelope's",
    ),
    FieldOrigin::derived(
        "pipe.link_inertia",
        "the 86/30 × 200 mm envelope tube of Table 1 row 4 at ρ = 7850 kg/m³, as pipe.link_mass",
    ),
    FieldOrigin::paper(
        "pipe.connector_length",
        "Table 1 row 3: connector length 200 mm",
    ),
    FieldOrigin::paper(
        "pipe.connector_diameter",
        "Table 1 row 3: connector OD 122 mm",
    ),
    FieldOrigin::derived(
        "pipe.connector_mass",
        "the 122/30 × 200 mm tube of Table 1 row 3 at ρ = 7850 kg/m³",
    ),
    FieldOrigin::derived(
        "pipe.connector_inertia",
        "the 122/30 × 200 mm tube of Table 1 row 3 at ρ = 7850 kg/m³",
    ),
    FieldOrigin::setting(
        "pipe.tube_contact_points",
        "samples that bracket the depth extrema of the link-tube line contact: a discretization whose \
         effect is numerical (0.08 % between 5 and 17 samples, docs/model.md §4)",
    ),
    FieldOrigin::proposal(
        "pipe.neck_radius",
        Source::Invented,
        "docs/model.md §3: a Ø38 neck over the head's Ø30 bore (4 mm wall, 273 MPa shear at 1.8 kN·m); \
         it sets the articulation limit, 14.92°",
        (0.0175, 0.021),
        "17.5 mm, the thinnest neck over the Ø30 bore that carries 1.8 kN·m below shear yield (465 \
         against 480 MPa), to 21 mm, near the 10° limit that gives the paper's included angles \
         (docs/paper.md); limit 18.2° to 10.3°",
    ),
    FieldOrigin::proposal(
        "pipe.link_edge_radius",
        Source::Invented,
        "docs/model.md §8.1: a sharp rim has no Hertz solution; the paper gives no edge radius",
        (0.001, 0.005),
        "the radii measured, 1 to 5 mm (rim peak pressure 7.90 to 3.74 GPa, about r_e^-0.47); moves \
         only the pressure and wear outputs",
    ),
    // pipe.ball_keys
    FieldOrigin::paper(
        "pipe.ball_keys.ball_radius",
        "Table 1 row 7: ball key Ø15 mm (§2.1 calls r_b a diameter; only a radius gives its contact \
         points, docs/model.md §1.1)",
    ),
    FieldOrigin::derived(
        "pipe.ball_keys.ball_mass",
        "a Ø15 steel sphere (Table 1 row 7) at ρ = 7850 kg/m³",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.pitch_radius",
        Source::PaperReading,
        "the keys at the mid-surface of Table 1's 64/62 mm cage (docs/model.md §3); the paper's PCR_b \
         has no value",
        (0.031, 0.032),
        "the key centre anywhere in the cage's 1 mm wall, from its inner (31 mm) to its outer sphere \
         (32 mm)",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.groove_offset",
        Source::PaperReading,
        "eq. (1)'s δ has no value; c = 4 mm makes the cage-key thrust 2F·cos α·c/ρ 5.97 kN at the \
         paper's 33.5 kN key force, against its 5.8 kN cage-key peak (docs/model.md §3)",
        (0.003, 0.005),
        "a thrust of 4.5 to 7.4 kN at 33.5 kN, bracketing the paper's 5.8 kN; the cage-key force \
         scales with c",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.groove_radius",
        Source::Invented,
        "docs/model.md §3 (groove conformity): nearly straight flanks hold the 45° contact angle under \
         the paper's soft contact law",
        (0.0078, 0.030),
        "from a close steel Gothic arch (conformity 1.04; runs at 74-77° under the paper's law) to the \
         nearly straight default; docs/paper.md ran 7.8, 15 and 30 mm: seat-cage peak 3.7 to 15.6 kN",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.contact_angle_deg",
        Source::Handbook,
        "the design angle of Gothic-arch ball races, 45° as in ball screws (docs/model.md §3)",
        (35.0, 50.0),
        "from 35°, the angle of four-point-contact ball bearings, to 50°, just above the 48-49° the \
         default groove runs at under the paper's peak load (docs/model.md §3)",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.flank_clearance",
        Source::Invented,
        "docs/model.md §3: a small play per flank; the paper gives none",
        (5e-6, 3e-5),
        "5 to 30 µm per flank, a close to a loose ball fit; small beside the 0.35-0.61 mm a loaded key \
         sinks under the paper's law",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.head_radius",
        Source::Invented,
        "Table 1's Ø62 head with 10 µm radial clearance in the cage: Table 1's zero clearance makes the \
         cage contact ill-posed (docs/model.md §3)",
        (0.03095, 0.030995),
        "5 to 50 µm radial clearance to the cage's 31 mm inner sphere, a precision to a loose sliding fit",
    ),
    FieldOrigin::paper(
        "pipe.ball_keys.cage_inner_radius",
        "Table 1 row 6: ball cage ID 62 mm",
    ),
    FieldOrigin::paper(
        "pipe.ball_keys.cage_outer_radius",
        "Table 1 row 6: ball cage OD 64 mm",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.seat_radius",
        Source::Invented,
        "Table 1's Ø64 seat bore with 10 µm radial clearance over the cage: Table 1's zero clearance \
         makes the cage contact ill-posed (docs/model.md §3)",
        (0.032005, 0.03205),
        "5 to 50 µm radial clearance over the cage's 32 mm outer sphere, a precision to a loose \
         sliding fit",
    ),
    FieldOrigin::derived(
        "pipe.ball_keys.cage_mass",
        "Table 1 row 6's 64/62 × 40 mm shell less six 15 × 15 mm windows, at ρ = 7850 kg/m³",
    ),
    FieldOrigin::derived(
        "pipe.ball_keys.cage_inertia",
        "Table 1 row 6's 64/62 × 40 mm shell less six 15 × 15 mm windows, at ρ = 7850 kg/m³",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.window_axial_width",
        Source::Invented,
        "docs/model.md §3: 30 µm over the Ø15 key, so the windows hold the keys near the bisector plane; \
         the paper's \"square hole\" has no size",
        (0.01501, 0.0151),
        "5 to 50 µm per side over the Ø15 key",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.window_length",
        Source::Invented,
        "docs/model.md §3: a key travels 0.12 mm around the cage at a 15° bend, so 16.1 mm is ample",
        (0.0153, 0.017),
        "from the key's travel at 15° plus 30 µm per side (15.3 mm) to 1 mm of slack per side; the key \
         never reaches a window's end",
    ),
    FieldOrigin::paper(
        "pipe.ball_keys.cage_length",
        "Table 1 row 6: ball cage length 40 mm",
    ),
    FieldOrigin::proposal(
        "pipe.ball_keys.mouth_offset",
        Source::PaperReading,
        "Table 1: head 104 + seat 136 − 200 mm pitch = 40 mm of overlap, read as centred on the hinge \
         (docs/model.md §3)",
        (0.018, 0.022),
        "the overlap's centring is our reading: ±2 mm (5 % of it) moves the articulation limit from \
         19.4° to 10.2° with the default neck, about −2.3° per mm",
    ),
    // pipe.ideal_cv: the reduced hinge model
    FieldOrigin::proposal(
        "pipe.ideal_cv.stiffness",
        Source::Invented,
        "docs/model.md §3 (ideal-CV hinge): 1.2 µm of offset under the 1.2 kN hinge shear",
        (1e8, 1e10),
        "×0.1 to ×10: 12 to 0.12 µm under 1.2 kN, a penalty that keeps the hinge points together \
         either way (ideal-CV hinges only)",
    ),
    FieldOrigin::proposal(
        "pipe.ideal_cv.damping",
        Source::Invented,
        "docs/model.md §3 (ideal-CV hinge): about critical for two 8 kg links on the hinge spring",
        (6.5e4, 2.6e5),
        "half to twice critical (ideal-CV hinges only)",
    ),
    FieldOrigin::proposal(
        "pipe.ideal_cv.twist_stiffness",
        Source::Invented,
        "docs/model.md §7.9: the ball-key hinge's tangent stiffness at 1.8 kN·m if the 45° contact \
         angle held",
        (6.9e4, 1.7e5),
        "the ball-key hinge's secant (6.9e4) to tangent (1.7e5) stiffness at 1.8 kN·m with the default \
         groove, from the section model (docs/model.md §7.9; ideal-CV hinges only)",
    ),
    FieldOrigin::proposal(
        "pipe.ideal_cv.twist_damping",
        Source::Invented,
        "docs/model.md §3 (ideal-CV hinge): about critical for a link's spin inertia on the twist spring",
        (30.0, 120.0),
        "half to twice critical (ideal-CV hinges only)",
    ),
    // drive, load
    FieldOrigin::paper("drive.speed_rpm", "§3.1: driving speed 100 r/min"),
    FieldOrigin::proposal(
        "drive.ramp",
        Source::Invented,
        "§3.1 mentions an acceleration stage but gives no ramp (docs/model.md §4)",
        (0.1, 0.5),
        "a sixth to most of the first revolution (0.6 s at 100 rpm), over before the last revolution \
         that the comparisons read; the acceleration-stage peaks depend on it",
    ),
    FieldOrigin::paper(
        "load.resisting_moment",
        "§3: resisting moment 1.8 kN·m on the lower connector",
    ),
    FieldOrigin::proposal(
        "load.ramp",
        Source::Invented,
        "the paper gives no load history (docs/model.md §4)",
        (0.1, 0.5),
        "as drive.ramp, the moment rising with the speed; 0 (at once) is possible too but loads a chain \
         at rest",
    ),
    FieldOrigin::paper(
        "load.axial_force",
        "§3: the lower connector carries a rotating constraint and the resisting moment, no axial force",
    ),
    // materials: the contact laws (N-mm-s)
    FieldOrigin::proposal(
        "materials.tube.normal.stiffness",
        Source::PaperReading,
        "§2.3 eq. (6) prints K = 1 × 10⁵ N/mm; with n = 2.2 it is Adams' default 1e5 N/mm^2.2 \
         (docs/model.md §1.3, §2.1)",
        (1e4, 1e6),
        "×0.1 to ×10: Adams' default is tuned for steel parts of about 1 kg, not fitted to these \
         surfaces (Hertz is about 6× stiffer in the grooves, docs/model.md §2.1)",
    ),
    FieldOrigin::paper(
        "materials.tube.normal.exponent",
        "§2.3 eq. (6): elastic force index n = 2.2",
    ),
    FieldOrigin::paper(
        "materials.tube.normal.damping",
        "§2.3 eq. (6): damping coefficient c = 10 N·s/mm",
    ),
    FieldOrigin::paper(
        "materials.tube.normal.depth_max",
        "§2.3 eq. (6): \"penetration depth 0.1 mm\", Adams' d_max (docs/model.md §0)",
    ),
    FieldOrigin::paper(
        "materials.tube.friction.mu_static",
        "§2.3 eq. (7): pipe-guide tube μs = 0.3",
    ),
    FieldOrigin::paper(
        "materials.tube.friction.mu_dynamic",
        "§2.3 eq. (7): pipe-guide tube μd = 0.1",
    ),
    FieldOrigin::paper(
        "materials.tube.friction.v_static",
        "§2.3 eq. (7): critical speed v_s = 100 mm/s",
    ),
    FieldOrigin::paper(
        "materials.tube.friction.v_dynamic",
        "§2.3 eq. (7): v_d = 1000 mm/s",
    ),
    FieldOrigin::proposal(
        "materials.internal.normal.stiffness",
        Source::PaperReading,
        "§2.3 eq. (6) prints K = 1 × 10⁵ N/mm; with n = 2.2 it is Adams' default 1e5 N/mm^2.2 \
         (docs/model.md §1.3, §2.1)",
        (1e4, 1e6),
        "×0.1 to ×10: Adams' default is tuned for steel parts of about 1 kg; Hertz for a Ø15 key in \
         its groove is about 6× stiffer (docs/model.md §2.1); ×100 halved the summed tube force \
         (docs/paper.md)",
    ),
    FieldOrigin::paper(
        "materials.internal.normal.exponent",
        "§2.3 eq. (6): elastic force index n = 2.2",
    ),
    FieldOrigin::paper(
        "materials.internal.normal.damping",
        "§2.3 eq. (6): damping coefficient c = 10 N·s/mm",
    ),
    FieldOrigin::paper(
        "materials.internal.normal.depth_max",
        "§2.3 eq. (6): \"penetration depth 0.1 mm\", Adams' d_max (docs/model.md §0)",
    ),
    FieldOrigin::paper(
        "materials.internal.friction.mu_static",
        "§2.3 eq. (7): inside the pipe (lubricated) μs = 0.1",
    ),
    FieldOrigin::paper(
        "materials.internal.friction.mu_dynamic",
        "§2.3 eq. (7): inside the pipe (lubricated) μd = 0.01",
    ),
    FieldOrigin::paper(
        "materials.internal.friction.v_static",
        "§2.3 eq. (7): critical speed v_s = 100 mm/s",
    ),
    FieldOrigin::paper(
        "materials.internal.friction.v_dynamic",
        "§2.3 eq. (7): v_d = 1000 mm/s",
    ),
    // materials: the solids (pressure and wear outputs only)
    FieldOrigin::paper(
        "materials.pipe_steel.youngs_modulus",
        "§3: 35CrMo, Young's modulus 210 GPa",
    ),
    FieldOrigin::paper(
        "materials.pipe_steel.poisson_ratio",
        "§3: 35CrMo, Poisson's ratio 0.3",
    ),
    FieldOrigin::proposal(
        "materials.pipe_steel.hardness",
        Source::Handbook,
        "quenched and tempered 35CrMo, HB 270-300: HV 300 (docs/model.md §8.2)",
        (2.75e9, 3.14e9),
        "HV 280-320, Q&T 35CrMo's HB 270-300 with the conversion's spread; the wear figures go as 1/H",
    ),
    FieldOrigin::proposal(
        "materials.pipe_steel.allowable_pressure",
        Source::Handbook,
        "first yield of a Hertz point contact, p₀ = 1.60·σ_y (Johnson, Contact Mechanics, 1985, §6.2, \
         ν = 0.3), with σ_y ≥ 835 MPa (GB/T 3077)",
        (1.336e9, 1.568e9),
        "σ_y from GB/T 3077's minimum yield 835 MPa to its minimum tensile strength 980 MPa; moves only \
         the pressure margins",
    ),
    FieldOrigin::proposal(
        "materials.key_steel.youngs_modulus",
        Source::Handbook,
        "through-hardened bearing steel GCr15/100Cr6 (docs/model.md §8.2)",
        (2.04e11, 2.12e11),
        "±2 % about 208 GPa, the spread of published moduli of hardened bearing steels; the Hertz \
         pressure goes as E^(2/3)",
    ),
    FieldOrigin::proposal(
        "materials.key_steel.poisson_ratio",
        Source::Handbook,
        "through-hardened bearing steel GCr15/100Cr6 (docs/model.md §8.2)",
        (0.27, 0.3),
        "the range given for hardened steels; moves the Hertz pressure by under 1 %",
    ),
    FieldOrigin::proposal(
        "materials.key_steel.hardness",
        Source::Handbook,
        "GCr15/100Cr6 through-hardened to 60-64 HRC: HV 750 (docs/model.md §8.2)",
        (6.84e9, 7.85e9),
        "60-64 HRC, about HV 697-800; the key wear figures go as 1/H",
    ),
    FieldOrigin::proposal(
        "materials.key_steel.allowable_pressure",
        Source::Handbook,
        "ISO 76: the static load rating of ball bearings, 4.2 GPa at the most loaded contact",
        (4.0e9, 4.6e9),
        "ISO 76's reference pressures, 4.0 GPa (roller bearings) to 4.6 GPa (self-aligning ball \
         bearings); moves only the key pressure margins",
    ),
    // wear
    FieldOrigin::proposal(
        "wear.tube_coefficient",
        Source::Handbook,
        "dry steel on steel in mild wear (Hutchings & Shipway, Tribology, 2nd ed., 2017, §5.3)",
        (1e-5, 1e-3),
        "the handbook's mild-wear span, 1e-5 to 1e-3; every tube wear figure scales with it",
    ),
    FieldOrigin::proposal(
        "wear.internal_coefficient",
        Source::Handbook,
        "boundary-lubricated steel (Hutchings & Shipway, Tribology, 2nd ed., 2017, §5.3)",
        (1e-9, 1e-6),
        "the handbook's lubricated span, 1e-9 to 1e-6; every joint wear figure scales with it",
    ),
    FieldOrigin::setting(
        "wear.threshold_pressure",
        "0, no threshold: Archard's law as the handbooks state it; a casing-wear threshold is a choice of \
         the user's (docs/model.md §8.3)",
    ),
    FieldOrigin::setting(
        "wear.map_cell_length",
        "10 mm, the resolution of the wear map along the tube and the links (docs/model.md §8.3)",
    ),
    FieldOrigin::setting(
        "wear.map_cell_angle_deg",
        "5°, the resolution of the wear map around the wall: 5.1 mm on the paper's 116 mm bore",
    ),
    FieldOrigin::setting(
        "wear.map_depth",
        "0.1 mm, the depth whose hours the report gives",
    ),
    // fatigue (docs/model.md §8.6)
    FieldOrigin::proposal(
        "fatigue.neck_offset",
        Source::Invented,
        "docs/model.md §8.6: the neck section just behind the neck's contact line with the seat's mouth \
         (25.8 mm from the hinge centre at the articulation limit), where the mouth's load has its arm",
        (0.026, 0.05),
        "from the contact line to the head's Ø62 body; the bending moment grows with the offset",
    ),
    FieldOrigin::proposal(
        "fatigue.seat_offset",
        Source::PaperReading,
        "docs/model.md §8.6: just behind the seat's sphere (R_s = 32.01 mm), where the seat's tube \
         carries every load of its hinge",
        (0.03, 0.05),
        "from the sphere's end to the link's side of the seat's grooves; the moment grows with the offset",
    ),
    FieldOrigin::paper(
        "fatigue.head_bore_diameter",
        "Table 1 row 4: ball head bore 30 mm",
    ),
    FieldOrigin::paper(
        "fatigue.seat_bore_diameter",
        "Table 1 row 4: ball seat bore 64 mm",
    ),
    FieldOrigin::proposal(
        "fatigue.neck_scf",
        Source::Handbook,
        "a shoulder fillet in bending, D/d = 62/38, r/d = 0.05 (a 2 mm fillet): K_t = 2.0 (Pilkey & \
         Pilkey, Peterson's Stress Concentration Factors, 3rd ed., 2008, Chart 3.10)",
        (1.5, 2.6),
        "fillet radii from 5 mm (r/d = 0.13) down to 1 mm (r/d = 0.026) in the same chart; the damage \
         goes as K_t^(-1/b), about K_t^11.5",
    ),
    FieldOrigin::proposal(
        "fatigue.body_scf",
        Source::Handbook,
        "a plain tube away from any change of section: K_t = 1 (Peterson's, 3rd ed., 2008)",
        (1.0, 1.5),
        "up to a mild circumferential groove or a small radial hole at mid-link",
    ),
    FieldOrigin::proposal(
        "fatigue.seat_scf",
        Source::Handbook,
        "the seat's sphere and its six groove run-outs ending in the Ø64 bore, read as an internal \
         shoulder: K_t = 2.0 (Peterson's, 3rd ed., 2008, Chart 3.10 as for the neck)",
        (1.5, 3.0),
        "the run-out's radius is not given; a sharp groove end could reach 3",
    ),
    FieldOrigin::proposal(
        "fatigue.ultimate_strength",
        Source::Handbook,
        "35CrMo quenched and tempered: R_m ≥ 980 MPa (GB/T 3077-2015)",
        (9.8e8, 1.13e9),
        "the standard's minimum to a typical delivered strength; moves only Goodman's correction",
    ),
    FieldOrigin::proposal(
        "fatigue.strength_coefficient",
        Source::Handbook,
        "σ′_f = 1.5·R_m = 1470 MPa, the uniform material law for unalloyed and low-alloy steels \
         (Bäumel & Seeger, Materials Data for Cyclic Loading, Supplement 1, Elsevier, 1990)",
        (1.2e9, 1.8e9),
        "the scatter of measured σ′_f of Q&T Cr-Mo steels about the uniform law (SAE 4130-4142, \
         Boller & Seeger, 1987); the life goes as σ′_f^(-1/b)",
    ),
    FieldOrigin::proposal(
        "fatigue.strength_exponent",
        Source::Handbook,
        "b = −0.087, the uniform material law for steels (Bäumel & Seeger, 1990)",
        (-0.12, -0.07),
        "measured b of Q&T Cr-Mo steels (Boller & Seeger, 1987); the life at a given amplitude is \
         very sensitive to it",
    ),
];
