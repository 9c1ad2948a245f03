//! The paper's ball-cage flexible drill pipe (Zhu et al., Machines 2023),
//! declared with engineering parameters and expanded into a generic [`Scene`].
//!
//! Defaults reproduce the paper's scene (physics.md §4): a 12-joint chain of
//! 200 mm links in a guide tube bent to R = 1.5 m over 90°, driven at 100 rpm
//! against 1.8 kN·m, MSC Adams IMPACT contacts, Adams friction. Values the
//! paper does not give are marked PROPOSAL in the field docs.
//!
//! Bodies: `tube` (fixed), `upper` (kinematic spin: the drive), `link01`…,
//! `lower` (spin only, resisting moment), and per hinge `hNN.cage` and
//! `hNN.keyJ`. Each link carries a ball seat at its uphole end and a ball head
//! at its downhole end; hinge k joins the head of body k to the seat of body k+1.

pub mod chain;
pub mod cv;
mod layout;

pub use layout::{HingeLayout, KeyLayout, Layout};

use serde::{Deserialize, Serialize};

use crate::error::SceneError;
use crate::geometry::TubePath;
use crate::math::{Mat3, Quat, Vec3};
use crate::scene::{
    BodySpec, ContactSpec, DivergenceSpec, FeatureSpec, FrictionLawSpec, IntegratorKind, JointSpec,
    LoadSpec, MotionKind, NewtonSpec, NormalLawSpec, RecordSpec, Scene, ShapeSpec, SimulationSpec,
    TubeSegmentSpec, WorldSpec, positive,
};
use cv::CvGeometry;

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
}

impl Default for BoreholeSpec {
    fn default() -> Self {
        Self {
            curvature_radius: 1.5,
            build_angle_deg: 90.0,
            inner_diameter: 0.116,
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
}

/// Ball-cage joint dimensions and masses (physics.md §3) [m, kg, kg·m², deg].
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
    /// Gothic-arch flank radius ρ_g [m]. PROPOSAL: 7.8 mm (conformity 1.04).
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
    /// Articulation stop (head–seat cone contact) [deg]. PROPOSAL: 15.
    pub bend_limit_deg: f64,
    /// Stop stiffness [N·m/rad]. PROPOSAL: 1e6.
    pub stop_stiffness: f64,
}

impl Default for BallKeySpec {
    fn default() -> Self {
        Self {
            ball_radius: 0.0075,
            ball_mass: 0.013872,
            pitch_radius: 0.0315,
            groove_offset: 0.004,
            groove_radius: 0.0078,
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
            bend_limit_deg: 15.0,
            stop_stiffness: 1e6,
        }
    }
}

/// Ideal constant-velocity hinge: penalty joint parameters [SI, deg].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IdealCvSpec {
    /// Hinge-point spring [N/m]. PROPOSAL: 1e9 (0.03 mm under the 1.2 kN hinge shear).
    pub stiffness: f64,
    /// Hinge-point damper [N·s/m]. PROPOSAL: 1.3e5 (about critical for two 8 kg links).
    pub damping: f64,
    /// Twist spring [N·m/rad]. PROPOSAL: 1.1e5, the ball-key hinge's tangent stiffness at 1.8 kN·m (physics.md §7.9).
    pub twist_stiffness: f64,
    /// Twist damper [N·m·s/rad]. PROPOSAL: 60 (about critical for a link's spin inertia).
    pub twist_damping: f64,
    /// Articulation stop [deg]. PROPOSAL: 15.
    pub bend_limit_deg: f64,
    /// Stop spring [N·m/rad]. PROPOSAL: 1e6.
    pub stop_stiffness: f64,
}

impl Default for IdealCvSpec {
    fn default() -> Self {
        Self {
            stiffness: 1e9,
            damping: 1.3e5,
            twist_stiffness: 1.1e5,
            twist_damping: 60.0,
            bend_limit_deg: 15.0,
            stop_stiffness: 1e6,
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
    /// Link mass [kg]: 86/30 × 200 mm steel envelope.
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
    /// Sample points along each link for link–tube contact. PROPOSAL: 5.
    pub tube_contact_points: u32,
    /// Ball-cage joint details (used by `hinge = "ball-keys"`).
    pub ball_keys: BallKeySpec,
    /// Ideal CV joint details (used by `hinge = "ideal-cv"`).
    pub ideal_cv: IdealCvSpec,
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
            tube_contact_points: 5,
            ball_keys: BallKeySpec::default(),
            ideal_cv: IdealCvSpec::default(),
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

impl Default for DriveSpec {
    fn default() -> Self {
        Self {
            speed_rpm: 100.0,
            ramp: 0.3,
        }
    }
}

/// The resisting moment on the lower connector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LoadSpecDp {
    /// Resisting moment, opposing the spin [N·m]. Paper: 1800.
    pub resisting_moment: f64,
    /// STEP ramp [s]; 0 applies it at once. PROPOSAL: 0.3.
    pub ramp: f64,
}

impl Default for LoadSpecDp {
    fn default() -> Self {
        Self {
            resisting_moment: 1800.0,
            ramp: 0.3,
        }
    }
}

/// A contact material: normal law and friction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    /// Normal law.
    pub normal: NormalLawSpec,
    /// Friction law.
    pub friction: FrictionLawSpec,
}

fn paper_impact() -> NormalLawSpec {
    NormalLawSpec::Impact {
        stiffness: 1e5,
        exponent: 2.2,
        damping: 10.0,
        depth_max: 0.1,
        units: crate::scene::FieldUnits::NMmS,
    }
}

fn adams(mu_static: f64, mu_dynamic: f64) -> FrictionLawSpec {
    FrictionLawSpec::Adams {
        mu_static,
        mu_dynamic,
        v_static: 100.0,
        v_dynamic: 1000.0,
        units: crate::scene::FieldUnits::NMmS,
    }
}

/// The two contact materials of the paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MaterialsSpec {
    /// Link–guide tube (dry): μs 0.3, μd 0.1.
    pub tube: MaterialSpec,
    /// Inside the joints (lubricated): μs 0.1, μd 0.01.
    pub internal: MaterialSpec,
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
        }
    }
}

/// Gravity magnitude, pointing along −z (z up).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GravitySpec {
    /// [m/s²]. Paper: 9.8.
    pub gravity: f64,
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
    /// Scene name.
    pub name: String,
    /// Time stepping. The paper's 1 ms is the output interval, not the step.
    /// Default: SDIRK2 at 100 µs, within 0.1 % of a converged reference on
    /// every quantity of `ballcage accuracy` (docs/accuracy.md). Explicit
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
    /// Resisting moment.
    pub load: LoadSpecDp,
    /// Contact materials.
    pub materials: MaterialsSpec,
    /// What to record.
    pub record: RecordSpec,
}

/// The `kind` of a drill-pipe scene document.
pub const KIND: &str = "drill-pipe";

impl Default for DrillPipeSpec {
    fn default() -> Self {
        Self {
            kind: KIND.to_string(),
            name: "Zhu et al. 2023: 12 ball-cage joints, R 1.5 m, 100 rpm, 1.8 kN·m".to_string(),
            simulation: SimulationSpec {
                duration: 1.8,
                dt: 1e-4,
                output_interval: 1e-3,
                integrator: IntegratorKind::Sdirk2,
                newton: NewtonSpec::default(),
                divergence: DivergenceSpec::default(),
            },
            world: GravitySpec::default(),
            borehole: BoreholeSpec::default(),
            pipe: PipeSpec::default(),
            drive: DriveSpec::default(),
            load: LoadSpecDp::default(),
            materials: MaterialsSpec::default(),
            record: RecordSpec::default(),
        }
    }
}

fn rotation_from_axes(x: Vec3, z: Vec3) -> Quat {
    let y = z.cross(&x);
    Quat::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(
        Mat3::from_columns(&[x, y, z]),
    ))
}

fn quat_array(q: &Quat) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

fn arr(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

impl DrillPipeSpec {
    /// The scene as TOML, every default written out.
    pub fn to_toml(&self) -> String {
        toml::to_string_pretty(self)
            .unwrap_or_else(|e| format!("# scene could not be written: {e}\n"))
    }

    fn validate(&self) -> Result<(), SceneError> {
        if self.kind != KIND {
            return Err(SceneError::new(
                "kind",
                &self.kind,
                format!("a drill-pipe scene has kind = \"{KIND}\""),
            ));
        }
        let b = &self.borehole;
        positive("borehole.curvature_radius", b.curvature_radius)?;
        positive("borehole.build_angle_deg", b.build_angle_deg)?;
        if b.build_angle_deg > 180.0 {
            return Err(SceneError::new(
                "borehole.build_angle_deg",
                b.build_angle_deg,
                "must be at most 180",
            ));
        }
        positive("borehole.inner_diameter", b.inner_diameter)?;
        let p = &self.pipe;
        if p.joints == 0 {
            return Err(SceneError::new(
                "pipe.joints",
                p.joints,
                "needs at least one flexible joint",
            ));
        }
        if p.joints > 200 {
            return Err(SceneError::new(
                "pipe.joints",
                p.joints,
                "more than 200 joints is not a drill pipe this tool models",
            ));
        }
        positive("pipe.pitch", p.pitch)?;
        positive("pipe.link_diameter", p.link_diameter)?;
        if p.link_diameter >= b.inner_diameter {
            return Err(SceneError::new(
                "pipe.link_diameter",
                p.link_diameter,
                format!(
                    "does not fit the guide tube (borehole.inner_diameter = {})",
                    b.inner_diameter
                ),
            ));
        }
        if 2.0 * b.curvature_radius <= p.pitch {
            return Err(SceneError::new(
                "borehole.curvature_radius",
                b.curvature_radius,
                format!("a {} m link cannot follow a bend this tight", p.pitch),
            ));
        }
        positive("pipe.connector_length", p.connector_length)?;
        positive("pipe.connector_diameter", p.connector_diameter)?;
        crate::scene::non_negative("drive.ramp", self.drive.ramp)?;
        crate::scene::finite("drive.speed_rpm", self.drive.speed_rpm)?;
        crate::scene::finite("load.resisting_moment", self.load.resisting_moment)?;
        crate::scene::non_negative("load.ramp", self.load.ramp)?;
        crate::scene::finite("world.gravity", self.world.gravity)?;
        let cv = &p.ideal_cv;
        for (name, v) in [
            ("stiffness", cv.stiffness),
            ("twist_stiffness", cv.twist_stiffness),
            ("bend_limit_deg", cv.bend_limit_deg),
            ("stop_stiffness", cv.stop_stiffness),
        ] {
            positive(&format!("pipe.ideal_cv.{name}"), v)?;
        }
        crate::scene::non_negative("pipe.ideal_cv.damping", cv.damping)?;
        crate::scene::non_negative("pipe.ideal_cv.twist_damping", cv.twist_damping)?;
        let k = &p.ball_keys;
        for (name, v) in [
            ("ball_radius", k.ball_radius),
            ("ball_mass", k.ball_mass),
            ("pitch_radius", k.pitch_radius),
            ("groove_offset", k.groove_offset),
            ("groove_radius", k.groove_radius),
            ("contact_angle_deg", k.contact_angle_deg),
            ("head_radius", k.head_radius),
            ("cage_inner_radius", k.cage_inner_radius),
            ("cage_outer_radius", k.cage_outer_radius),
            ("seat_radius", k.seat_radius),
            ("cage_mass", k.cage_mass),
            ("window_axial_width", k.window_axial_width),
            ("window_length", k.window_length),
            ("bend_limit_deg", k.bend_limit_deg),
            ("stop_stiffness", k.stop_stiffness),
        ] {
            positive(&format!("pipe.ball_keys.{name}"), v)?;
        }
        crate::scene::non_negative("pipe.ball_keys.flank_clearance", k.flank_clearance)?;
        if k.groove_radius <= k.ball_radius + k.flank_clearance {
            return Err(SceneError::new(
                "pipe.ball_keys.groove_radius",
                k.groove_radius,
                "must exceed ball_radius + flank_clearance (a Gothic arch wider than the ball)",
            ));
        }
        if !(k.head_radius < k.cage_inner_radius
            && k.cage_inner_radius < k.cage_outer_radius
            && k.cage_outer_radius < k.seat_radius)
        {
            return Err(SceneError::new(
                "pipe.ball_keys.head_radius",
                k.head_radius,
                "needs head_radius < cage_inner_radius < cage_outer_radius < seat_radius",
            ));
        }
        Ok(())
    }

    /// The tube's centreline, extended straight past the arc for placement.
    pub(crate) fn centreline(&self, extension: f64) -> TubePath {
        let b = &self.borehole;
        let mut segs = vec![TubeSegmentSpec::Arc {
            radius: b.curvature_radius,
            angle_deg: b.build_angle_deg,
            bend: [1.0, 0.0, 0.0],
        }];
        if extension > 0.0 {
            segs.push(TubeSegmentSpec::Straight { length: extension });
        }
        TubePath::new(
            b.inner_diameter / 2.0,
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, -1.0),
            &segs,
        )
    }

    /// Hinge centres in world coordinates (physics.md §4, Option A) [m].
    pub fn hinge_positions(&self) -> Vec<Vec3> {
        let n = self.pipe.joints;
        chain::place_hinges(
            &self.centreline(2.0 * n as f64 * self.pipe.pitch),
            self.pipe.pitch,
            n + 1,
        )
    }

    /// Expands into the generic scene.
    pub fn expand(&self) -> Result<Scene, SceneError> {
        self.validate()?;
        let p = &self.pipe;
        let n = p.joints;
        let hinges = self.hinge_positions();
        let z_b = Vec3::new(0.0, -1.0, 0.0); // bend-plane normal: every body's z axis
        // Axes of the bodies in chain order: upper, link 1..n, lower.
        let mut axes = vec![Vec3::new(0.0, 0.0, -1.0)];
        for k in 1..=n {
            axes.push((hinges[k] - hinges[k - 1]).normalize());
        }
        let extended = self.centreline(2.0 * n as f64 * p.pitch);
        let lower_axis = {
            // Tangent of the centreline at the last hinge.
            let (mut lo, mut hi) = (0.0, extended.length());
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                let c = extended.point_at(mid);
                if (c.point - hinges[n]).dot(&c.tangent) < 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            extended.point_at(0.5 * (lo + hi)).tangent
        };
        axes.push(lower_axis);
        let rotations: Vec<Quat> = axes.iter().map(|x| rotation_from_axes(*x, z_b)).collect();

        let names: Vec<String> = std::iter::once("upper".to_string())
            .chain((1..=n).map(|k| format!("link{k:02}")))
            .chain(std::iter::once("lower".to_string()))
            .collect();
        let half_c = p.connector_length / 2.0;
        let omega = self.drive.speed_rpm * std::f64::consts::TAU / 60.0;

        let mut bodies = vec![BodySpec {
            name: "tube".into(),
            motion: MotionKind::Fixed,
            shape: ShapeSpec::Tube {
                inner_radius: self.borehole.inner_diameter / 2.0,
                start: [0.0; 3],
                direction: [0.0, 0.0, -1.0],
                segments: vec![TubeSegmentSpec::Arc {
                    radius: self.borehole.curvature_radius,
                    angle_deg: self.borehole.build_angle_deg,
                    bend: [1.0, 0.0, 0.0],
                }],
            },
            ..blank_body()
        }];
        let connector =
            |name: &str, centre: Vec3, q: Quat, axis: Vec3, motion: MotionKind| BodySpec {
                name: name.into(),
                motion,
                shape: ShapeSpec::Cylinder {
                    radius: p.connector_diameter / 2.0,
                    half_length: half_c,
                    inner_radius: 0.0,
                },
                mass: Some(p.connector_mass),
                inertia: Some(p.connector_inertia),
                position: arr(&centre),
                orientation: quat_array(&q),
                spin_axis: Some(arr(&axis)),
                spin_speed: if motion == MotionKind::KinematicSpin {
                    omega
                } else {
                    0.0
                },
                spin_ramp: if motion == MotionKind::KinematicSpin {
                    self.drive.ramp
                } else {
                    0.0
                },
                ..blank_body()
            };
        bodies.push(connector(
            "upper",
            hinges[0] - half_c * axes[0],
            rotations[0],
            axes[0],
            MotionKind::KinematicSpin,
        ));
        // The reduced model keeps the chain's mass: each link carries one hinge's
        // cage and keys (half of each of its two hinges).
        let hinge_parts = if p.hinge == HingeModel::IdealCv {
            p.ball_keys.cage_mass + 6.0 * p.ball_keys.ball_mass
        } else {
            0.0
        };
        for k in 1..=n {
            bodies.push(BodySpec {
                name: names[k].clone(),
                motion: MotionKind::Dynamic,
                shape: ShapeSpec::Cylinder {
                    radius: p.link_diameter / 2.0,
                    half_length: p.pitch / 2.0,
                    inner_radius: 0.0,
                },
                mass: Some(p.link_mass + hinge_parts),
                inertia: Some(p.link_inertia),
                position: arr(&(0.5 * (hinges[k - 1] + hinges[k]))),
                orientation: quat_array(&rotations[k]),
                ..blank_body()
            });
        }
        bodies.push(connector(
            "lower",
            hinges[n] + half_c * axes[n + 1],
            rotations[n + 1],
            axes[n + 1],
            MotionKind::Spin,
        ));

        let tube_material = &self.materials.tube;
        let internal = &self.materials.internal;
        let mut contacts = vec![];
        for name in names.iter().take(n + 1).skip(1) {
            contacts.push(ContactSpec {
                name: Some(format!("{name}/tube")),
                bodies: ["tube".into(), name.clone()],
                normal: tube_material.normal.clone(),
                friction: Some(tube_material.friction.clone()),
                geometry: None,
                points: p.tube_contact_points,
            });
        }

        let mut joints = vec![];
        let kb = &p.ball_keys;
        let cv = CvGeometry {
            pitch_radius: kb.pitch_radius,
            groove_offset: kb.groove_offset,
        };
        let rho = cv.track_radius();
        let alpha = kb.contact_angle_deg.to_radians();
        let a = kb.groove_radius - kb.ball_radius - kb.flank_clearance;
        let key_inertia = 0.4 * kb.ball_mass * kb.ball_radius * kb.ball_radius;
        for h in 0..=n {
            let (head, seat) = (&names[h], &names[h + 1]);
            if p.hinge == HingeModel::IdealCv {
                let head_half = if h == 0 { half_c } else { p.pitch / 2.0 };
                let seat_half = if h == n { half_c } else { p.pitch / 2.0 };
                let c = &p.ideal_cv;
                joints.push(JointSpec::Cv {
                    name: Some(format!("h{h:02}")),
                    bodies: [head.clone(), seat.clone()],
                    anchors: [[head_half, 0.0, 0.0], [-seat_half, 0.0, 0.0]],
                    stiffness: c.stiffness,
                    damping: c.damping,
                    twist_stiffness: c.twist_stiffness,
                    twist_damping: c.twist_damping,
                    bend_limit_deg: c.bend_limit_deg,
                    stop_stiffness: c.stop_stiffness,
                });
                continue;
            }
            // Hinge centre in each body's frame: the head end is downhole (+x), the seat end uphole (−x).
            let head_half = if h == 0 { half_c } else { p.pitch / 2.0 };
            let seat_half = if h == n { half_c } else { p.pitch / 2.0 };
            let c_head = Vec3::new(head_half, 0.0, 0.0);
            let c_seat = Vec3::new(-seat_half, 0.0, 0.0);
            let beta = chain::bend_angle(&axes[h], &axes[h + 1], &z_b);
            joints.push(JointSpec::BendStop {
                name: Some(format!("h{h:02}.stop")),
                bodies: [head.clone(), seat.clone()],
                bend_limit_deg: kb.bend_limit_deg,
                stop_stiffness: kb.stop_stiffness,
            });
            let r_head = rotations[h];
            let r_cage = r_head * Quat::from_axis_angle(&Vec3::z_axis(), beta / 2.0);
            let cage = format!("h{h:02}.cage");
            bodies.push(BodySpec {
                name: cage.clone(),
                motion: MotionKind::Dynamic,
                shape: ShapeSpec::Ball {
                    radius: kb.cage_outer_radius,
                },
                mass: Some(kb.cage_mass),
                inertia: Some(kb.cage_inertia),
                position: arr(&hinges[h]),
                orientation: quat_array(&r_cage),
                ..blank_body()
            });
            let mut push = |name: String, a_body: &str, b_body: &str, geometry: FeatureSpec| {
                contacts.push(ContactSpec {
                    name: Some(name),
                    bodies: [a_body.into(), b_body.into()],
                    normal: internal.normal.clone(),
                    friction: Some(internal.friction.clone()),
                    geometry: Some(geometry),
                    points: 5,
                });
            };
            push(
                format!("h{h:02}.cage/head"),
                &cage,
                head,
                FeatureSpec::CavitySphere {
                    cavity_centre: [0.0; 3],
                    cavity_radius: kb.cage_inner_radius,
                    sphere_centre: arr(&c_head),
                    sphere_radius: kb.head_radius,
                },
            );
            push(
                format!("h{h:02}.cage/seat"),
                seat,
                &cage,
                FeatureSpec::CavitySphere {
                    cavity_centre: arr(&c_seat),
                    cavity_radius: kb.seat_radius,
                    sphere_centre: [0.0; 3],
                    sphere_radius: kb.cage_outer_radius,
                },
            );
            for j in 0..6 {
                let psi = j as f64 * std::f64::consts::FRAC_PI_3;
                let key = format!("h{h:02}.key{j}");
                let p_hinge = cv.ball_centre_in_groove(beta, psi);
                bodies.push(BodySpec {
                    name: key.clone(),
                    motion: MotionKind::Dynamic,
                    shape: ShapeSpec::Ball {
                        radius: kb.ball_radius,
                    },
                    mass: Some(kb.ball_mass),
                    inertia: Some([key_inertia; 3]),
                    position: arr(&(hinges[h] + r_head * p_hinge)),
                    ..blank_body()
                });
                let e_t = Vec3::new(0.0, -psi.sin(), psi.cos());
                for (sign, tag) in [(1.0, "+"), (-1.0, "-")] {
                    push(
                        format!("{key}/head{tag}"),
                        head,
                        &key,
                        FeatureSpec::TorusBall {
                            centre: arr(&(c_head - kb.groove_offset * Vec3::x()
                                + sign * a * alpha.sin() * e_t)),
                            axis: arr(&e_t),
                            core_radius: rho + a * alpha.cos(),
                            tube_radius: kb.groove_radius,
                        },
                    );
                    push(
                        format!("{key}/seat{tag}"),
                        seat,
                        &key,
                        FeatureSpec::TorusBall {
                            centre: arr(&(c_seat
                                + kb.groove_offset * Vec3::x()
                                + sign * a * alpha.sin() * e_t)),
                            axis: arr(&e_t),
                            core_radius: rho - a * alpha.cos(),
                            tube_radius: kb.groove_radius,
                        },
                    );
                }
                push(
                    format!("{key}/window-axial"),
                    &cage,
                    &key,
                    FeatureSpec::SlotBall {
                        centre: [0.0; 3],
                        normal: [1.0, 0.0, 0.0],
                        half_width: kb.window_axial_width / 2.0,
                    },
                );
                push(
                    format!("{key}/window-side"),
                    &cage,
                    &key,
                    FeatureSpec::SlotBall {
                        centre: [0.0; 3],
                        normal: arr(&e_t),
                        half_width: kb.window_length / 2.0,
                    },
                );
            }
        }

        let mut record = self.record.clone();
        if record.bodies.is_empty() {
            record.bodies = names.clone();
        }
        let scene = Scene {
            name: self.name.clone(),
            simulation: self.simulation.clone(),
            world: WorldSpec {
                gravity: [0.0, 0.0, -self.world.gravity],
            },
            record,
            bodies,
            contacts,
            loads: vec![LoadSpec::Torque {
                body: "lower".into(),
                axis: arr(&axes[n + 1]),
                magnitude: -self.load.resisting_moment,
                ramp: self.load.ramp,
            }],
            joints,
            origin: Some(Box::new(self.clone())),
        };
        scene.validate()?;
        Ok(scene)
    }
}

fn blank_body() -> BodySpec {
    BodySpec {
        name: String::new(),
        motion: MotionKind::Dynamic,
        shape: ShapeSpec::Ball { radius: 1.0 },
        mass: None,
        density: None,
        inertia: None,
        position: [0.0; 3],
        orientation: [1.0, 0.0, 0.0, 0.0],
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        spin_axis: None,
        spin_speed: 0.0,
        spin_ramp: 0.0,
    }
}
