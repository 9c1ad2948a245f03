//! Where each default of a scene comes from: the paper, a rule applied to
//! the paper's values, a value ballcage chose because the paper gives none
//! (a PROPOSAL, with a plausible range and why), or a setting of the run.
//!
//! Every numeric default of a scene kind is classified once, by its dotted
//! key (the key `--set key=value` takes), in a list of [`FieldOrigin`]s kept
//! beside the spec fields: the engine's own sections here ([`ENGINE`], which
//! every kind shares, and [`GENERIC`]); a scene kind built on the engine
//! keeps its list beside its own spec. The PROPOSAL entries of those lists
//! are the registry of unstated parameters (`ballcage.proposals()`,
//! docs/proposals.md).
//!
//! An entry holds only what nothing else holds: the source, its reference
//! and the range. A field's default comes from the default document, and
//! its unit and meaning from the [`FieldDoc`](super::FieldDoc) tables; the
//! range is in the field's unit as the default document writes it (a
//! contact law's in its N-mm-s field units).
//!
//! | provenance | meaning |
//! |---|---|
//! | [`Provenance::Paper`] | stated in the paper: where (table, section, equation) |
//! | [`Provenance::Derived`] | computed from the paper's values: how |
//! | [`Provenance::Proposal`] | chosen by ballcage: source, reference, range and why |
//! | [`Provenance::Setting`] | how the run is computed or recorded, not the physics |
//! | [`Provenance::Declared`] | a generic scene's own input, neutral when left out |

/// Where a PROPOSAL value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Not in the paper, nor read from it: our choice, argued in the reference.
    Invented,
    /// Our reading of something the paper states unclearly (a garbled unit,
    /// a dimension implied by others).
    PaperReading,
    /// A handbook or standard value for the material or the part.
    Handbook,
}

impl Source {
    /// The name `ballcage.proposals()` gives: `invented`, `paper-reading`, `handbook`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Invented => "invented",
            Self::PaperReading => "paper-reading",
            Self::Handbook => "handbook",
        }
    }

    /// How `scene show` says it, after the range.
    fn phrase(self) -> &'static str {
        match self {
            Self::Invented => "not in the paper",
            Self::PaperReading => "a reading of the paper",
            Self::Handbook => "a handbook value, not in the paper",
        }
    }
}

/// A value ballcage chose: its source, a plausible range and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proposal {
    /// Where the value comes from.
    pub source: Source,
    /// The argument or the citation for the default.
    pub reference: &'static str,
    /// Lowest plausible value, in the field's unit (as the default document writes it).
    pub low: f64,
    /// Highest plausible value, in the field's unit.
    pub high: f64,
    /// One line on why the range is plausible.
    pub range_reason: &'static str,
}

impl Proposal {
    /// The comment `scene show` prints above the field, e.g.
    /// `PROPOSAL, 17.5–21 mm: not in the paper`, for a field in `unit`.
    pub fn mark(&self, unit: &str) -> String {
        format!(
            "PROPOSAL, {}: {}",
            format_range(self.low, self.high, unit),
            self.source.phrase()
        )
    }
}

/// Where one default comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Provenance {
    /// Stated in the paper; the reference says where (table, section, equation).
    Paper(&'static str),
    /// Computed from the paper's values; the text says how.
    Derived(&'static str),
    /// Not given by the paper: a registry entry.
    Proposal(Proposal),
    /// How the run is computed, stopped or recorded, not the physics; the text says why.
    Setting(&'static str),
    /// A generic scene's own input, declared by its author; neutral when left out.
    Declared(&'static str),
}

/// The provenance of the field at a dotted key.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldOrigin {
    /// Dotted key, as `--set key=value` takes it (`pipe.neck_radius`).
    pub key: &'static str,
    /// Where its default comes from.
    pub provenance: Provenance,
}

impl FieldOrigin {
    /// Stated in the paper, at `reference`.
    pub const fn paper(key: &'static str, reference: &'static str) -> Self {
        Self {
            key,
            provenance: Provenance::Paper(reference),
        }
    }

    /// Computed from the paper's values, as `how` says.
    pub const fn derived(key: &'static str, how: &'static str) -> Self {
        Self {
            key,
            provenance: Provenance::Derived(how),
        }
    }

    /// A setting of the run, for the reason `why`.
    pub const fn setting(key: &'static str, why: &'static str) -> Self {
        Self {
            key,
            provenance: Provenance::Setting(why),
        }
    }

    /// A generic scene's own input.
    pub const fn declared(key: &'static str, why: &'static str) -> Self {
        Self {
            key,
            provenance: Provenance::Declared(why),
        }
    }

    /// A PROPOSAL: `source` with its `reference`, plausible between `low`
    /// and `high` (the field's unit) because of `range_reason`.
    pub const fn proposal(
        key: &'static str,
        source: Source,
        reference: &'static str,
        (low, high): (f64, f64),
        range_reason: &'static str,
    ) -> Self {
        Self {
            key,
            provenance: Provenance::Proposal(Proposal {
                source,
                reference,
                low,
                high,
                range_reason,
            }),
        }
    }

    /// The registry entry, for a PROPOSAL.
    pub fn proposal_entry(&self) -> Option<&Proposal> {
        match &self.provenance {
            Provenance::Proposal(p) => Some(p),
            _ => None,
        }
    }
}

/// The entry for dotted `key` in `lists` (list elements by index or in
/// brackets, `a.0.b` or `a[0].b`, never appear in these lists).
pub fn origin_of<'a>(lists: &[&'a [FieldOrigin]], key: &str) -> Option<&'a FieldOrigin> {
    let key = key.trim();
    lists.iter().flat_map(|l| l.iter()).find(|o| o.key == key)
}

/// The smallest generic scene: one body. Every other field takes the
/// engine's default, so its resolved document holds the defaults a generic
/// scene gets ([`GENERIC`] and [`ENGINE`] classify them).
pub const MINIMAL_GENERIC_SCENE: &str = r#"
[simulation]
duration = 1.0
dt = 1e-3
output_interval = 1e-3

[[bodies]]
name = "ball"
mass = 1.0
shape = { type = "ball", radius = 0.1 }
"#;

/// The engine's sections every scene kind shares (`simulation`, `record`):
/// settings of the run, and the two divergence thresholds, PROPOSALs.
pub const ENGINE: &[FieldOrigin] = &[
    FieldOrigin::setting(
        "simulation.duration",
        "how long to simulate; the paper's run is 1.8 s (§3.1)",
    ),
    FieldOrigin::setting(
        "simulation.dt",
        "the fixed integrator step, chosen for accuracy (docs/accuracy.md); unused with adaptive steps",
    ),
    FieldOrigin::setting(
        "simulation.output_interval",
        "how often a frame is recorded; the paper's \"step size 0.001 s\" (§3.1) is Adams' output interval",
    ),
    FieldOrigin::setting(
        "simulation.threads",
        "threads per force evaluation; results are bitwise the same for any count",
    ),
    FieldOrigin::setting(
        "simulation.max_steps",
        "a guard against a typo in the duration or the step",
    ),
    FieldOrigin::setting(
        "simulation.rtol",
        "tolerance of the adaptive steps, chosen for accuracy (docs/accuracy.md)",
    ),
    FieldOrigin::setting(
        "simulation.atol",
        "absolute tolerance of the adaptive steps",
    ),
    FieldOrigin::setting(
        "simulation.atol_position",
        "absolute tolerance of the adaptive steps on positions",
    ),
    FieldOrigin::setting(
        "simulation.atol_rotation",
        "absolute tolerance of the adaptive steps on rotations",
    ),
    FieldOrigin::setting(
        "simulation.atol_velocity",
        "absolute tolerance of the adaptive steps on velocities",
    ),
    FieldOrigin::setting(
        "simulation.atol_angular_velocity",
        "absolute tolerance of the adaptive steps on angular velocities",
    ),
    FieldOrigin::setting("simulation.max_step", "largest adaptive step"),
    FieldOrigin::setting(
        "simulation.newton.tolerance",
        "Newton convergence; the paper scene's results agree to three digits at 1e-8 (docs/performance.md)",
    ),
    FieldOrigin::setting(
        "simulation.newton.max_iterations",
        "Newton iterations before a step is retried",
    ),
    FieldOrigin::setting(
        "simulation.newton.reuse_iterations",
        "when the factorized Jacobian is kept",
    ),
    FieldOrigin::proposal(
        "simulation.divergence.penetration_fraction",
        Source::Invented,
        "docs/model.md §5 (divergence detection): the paper's most loaded ball key sinks about 0.05 of \
         its radius",
        (0.1, 0.5),
        "twice the paper run's deepest contact (0.05) up to half a radius, where no contact law holds; \
         only decides when a run is stopped as diverged",
    ),
    FieldOrigin::setting(
        "simulation.divergence.max_penetration",
        "an absolute penetration limit, unset by default",
    ),
    FieldOrigin::proposal(
        "simulation.divergence.energy_growth",
        Source::Invented,
        "docs/model.md §5 (divergence detection): the integrator has made as much energy again as the \
         system holds or was given",
        (0.5, 2.0),
        "a diverging run passes any of these within a few steps, a stable one stays far below; only \
         decides when a run is stopped as diverged",
    ),
    FieldOrigin::setting(
        "record.summary_window",
        "the time window of the summary statistics",
    ),
    FieldOrigin::setting(
        "record.max_bytes",
        "a guard on the memory the recorded tables take",
    ),
];

/// The generic scene's own scene-wide defaults (its bodies, pairs, loads
/// and joints are declared one by one by the scene).
pub const GENERIC: &[FieldOrigin] = &[FieldOrigin::declared(
    "world.gravity",
    "the scene's gravity; none unless it declares one",
)];

/// `low–high unit` for a PROPOSAL's range, readable: lengths below 1 mm in
/// µm and below 1 m in mm, pressures in MPa or GPa, angles in °, pure numbers without a unit,
/// at most six significant digits (`17.5–21 mm`, `1e4–1e6 N/mm^2.2`).
pub fn format_range(low: f64, high: f64, unit: &str) -> String {
    let (scale, unit) = match unit {
        "m" if high.abs() < 1e-3 => (1e6, "µm"),
        "m" if high.abs() < 1.0 => (1e3, "mm"),
        "Pa" if low.abs() >= 1e9 => (1e-9, "GPa"),
        "Pa" if low.abs() >= 1e6 => (1e-6, "MPa"),
        "deg" => (1.0, "°"),
        "-" | "" => (1.0, ""),
        other => (1.0, other),
    };
    let space = if unit.is_empty() || unit == "°" {
        ""
    } else {
        " "
    };
    let (low, high) = (low * scale, high * scale);
    // one notation for both ends: scientific when either needs it
    let plain = |x: f64| x == 0.0 || (1e-3..1e5).contains(&x.abs());
    let scientific = !(plain(low) && plain(high));
    format!(
        "{}–{}{space}{unit}",
        short(low, scientific),
        short(high, scientific)
    )
}

/// A number in at most six significant digits, trailing zeros dropped, or
/// `scientific` with at most four (`1e4`, `2.6e5`).
fn short(x: f64, scientific: bool) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if scientific {
        let s = format!("{x:.3e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exponent}");
    }
    let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{x:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_read_in_the_units_an_engineer_uses() {
        assert_eq!(format_range(0.0175, 0.021, "m"), "17.5–21 mm");
        assert_eq!(format_range(0.03095, 0.030995, "m"), "30.95–30.995 mm");
        assert_eq!(format_range(5e-6, 3e-5, "m"), "5–30 µm");
        assert_eq!(format_range(1e4, 1e6, "N/mm^2.2"), "1e4–1e6 N/mm^2.2");
        assert_eq!(format_range(2.75e9, 3.14e9, "Pa"), "2.75–3.14 GPa");
        assert_eq!(format_range(35.0, 50.0, "deg"), "35–50°");
        assert_eq!(format_range(0.1, 0.5, "-"), "0.1–0.5");
        assert_eq!(format_range(0.1, 0.5, "s"), "0.1–0.5 s");
        assert_eq!(format_range(1e-9, 1e-6, "-"), "1e-9–1e-6");
        assert_eq!(format_range(6.5e4, 2.6e5, "N·s/m"), "6.5e4–2.6e5 N·s/m");
        assert_eq!(format_range(4.655, 8.01, "kg"), "4.655–8.01 kg");
        assert_eq!(format_range(1e-5, 1e-3, "-"), "1e-5–1e-3");
        assert_eq!(format_range(6.9e4, 1.7e5, "N·m/rad"), "6.9e4–1.7e5 N·m/rad");
        assert_eq!(format_range(30.0, 120.0, "N·m·s/rad"), "30–120 N·m·s/rad");
    }

    #[test]
    fn a_mark_says_the_range_and_the_source() {
        let p = Proposal {
            source: Source::Invented,
            reference: "",
            low: 0.0175,
            high: 0.021,
            range_reason: "",
        };
        assert_eq!(p.mark("m"), "PROPOSAL, 17.5–21 mm: not in the paper");
    }

    #[test]
    fn every_entry_of_the_engine_lists_is_classified_once() {
        let all: Vec<&str> = ENGINE.iter().chain(GENERIC).map(|o| o.key).collect();
        for (i, key) in all.iter().enumerate() {
            assert!(!all[..i].contains(key), "{key} twice");
        }
        assert!(origin_of(&[ENGINE], "simulation.dt").is_some());
        assert!(origin_of(&[ENGINE], "simulation.nope").is_none());
    }
}
