//! A running simulation: model, state, integrator scratch and recorder.

use std::time::{Duration, Instant};

use crate::assembly::assemble;
use crate::dynamics::{ContactEval, Dynamics};
use crate::error::{SceneError, SimulationError};
use crate::integrate::{self, Workspace};
use crate::math::Vec3;
use crate::model::{Model, State};
use crate::record::{Cell, Recording, TableBuffer};
use crate::scene::{Scene, TableKind};

/// Energy of the system at one instant [J].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    /// Kinetic energy of the integrated bodies.
    pub kinetic: f64,
    /// Gravitational potential energy, zero at the world origin.
    pub potential_gravity: f64,
    /// Elastic energy stored in the contacts.
    pub potential_contact: f64,
}

impl Energy {
    /// Sum of all parts.
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential_gravity + self.potential_contact
    }
}

/// A simulation of one scene.
#[derive(Debug, Clone)]
pub struct Simulation {
    model: Model,
    state: State,
    dynamics: Dynamics,
    workspace: Workspace,
    tables: Vec<TableBuffer>,
    scene_toml: String,
    step: u64,
    wall: Duration,
    evals: Vec<ContactEval>,
}

impl Simulation {
    /// Validates and assembles `scene`, and records the frame at t = 0.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        let (model, state) = assemble(scene)?;
        let dynamics = Dynamics::new(&model);
        let workspace = Workspace::new(&state);
        let tables = model
            .record
            .tables
            .iter()
            .map(|k| TableBuffer::new(*k))
            .collect();
        let mut sim = Self {
            model,
            state,
            dynamics,
            workspace,
            tables,
            scene_toml: scene.to_toml(),
            step: 0,
            wall: Duration::ZERO,
            evals: Vec::new(),
        };
        sim.record_frame();
        Ok(sim)
    }

    /// The assembled model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Simulated time [s].
    pub fn time(&self) -> f64 {
        self.state.t
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Force evaluations so far.
    pub fn force_evaluations(&self) -> u64 {
        self.dynamics.evaluations
    }

    /// Whether the scene's duration has been reached.
    pub fn is_done(&self) -> bool {
        self.step >= self.model.total_steps
    }

    /// Position of the named body's centre of mass [m].
    pub fn position(&self, body: &str) -> Option<Vec3> {
        self.model
            .bodies
            .iter()
            .position(|b| b.name == body)
            .map(|i| self.state.pos[i])
    }

    /// Takes one integrator step and records a frame when one is due.
    pub fn step(&mut self) -> Result<(), SimulationError> {
        let h = self.model.dt;
        integrate::step(
            self.model.integrator,
            &self.model,
            &mut self.dynamics,
            &mut self.workspace,
            &mut self.state,
            h,
        );
        self.step += 1;
        self.state.t = self.step as f64 * h;
        self.check_finite()?;
        if self.step.is_multiple_of(self.model.steps_per_output) {
            self.record_frame();
        }
        Ok(())
    }

    /// Steps until the time reaches `t_end` [s] or the scene's duration.
    pub fn advance_to(&mut self, t_end: f64) -> Result<(), SimulationError> {
        let start = Instant::now();
        let target = ((t_end / self.model.dt).round() as u64).min(self.model.total_steps);
        let mut result = Ok(());
        while self.step < target {
            if let Err(e) = self.step() {
                result = Err(e);
                break;
            }
        }
        self.wall += start.elapsed();
        result
    }

    /// Runs to the end of the scene's duration.
    pub fn run(&mut self) -> Result<(), SimulationError> {
        self.advance_to(self.model.duration())
    }

    /// Energy at the current state.
    pub fn energy(&mut self) -> Energy {
        let (m, s) = (&self.model, &self.state);
        let mut kinetic = 0.0;
        let mut potential_gravity = 0.0;
        for &i in &m.integrated {
            let b = &m.bodies[i];
            let w = s.omega[i];
            kinetic +=
                0.5 * b.mass * s.vel[i].norm_squared() + 0.5 * w.dot(&b.inertia.component_mul(&w));
            potential_gravity -= b.mass * m.gravity.dot(&s.pos[i]);
        }
        let potential_contact = self.dynamics.contact_energy(&self.model, &self.state);
        Energy {
            kinetic,
            potential_gravity,
            potential_contact,
        }
    }

    /// Ends the run and hands over the recorded tables with run metadata.
    pub fn finish(self) -> Recording {
        let complete = self.is_done();
        let metadata = vec![
            ("ballcage.scene".to_string(), self.scene_toml),
            ("ballcage.version".to_string(), crate::VERSION.to_string()),
            (
                "ballcage.integrator".to_string(),
                self.model.integrator.name().to_string(),
            ),
            ("ballcage.dt_s".to_string(), format!("{:e}", self.model.dt)),
            ("ballcage.steps".to_string(), self.step.to_string()),
            (
                "ballcage.force_evaluations".to_string(),
                self.dynamics.evaluations.to_string(),
            ),
            (
                "ballcage.wall_time_s".to_string(),
                format!("{:.6}", self.wall.as_secs_f64()),
            ),
            ("ballcage.complete".to_string(), complete.to_string()),
        ];
        Recording {
            tables: self.tables,
            body_names: self.model.bodies.iter().map(|b| b.name.clone()).collect(),
            pair_names: self.model.pairs.iter().map(|p| p.name.clone()).collect(),
            metadata,
        }
    }

    fn check_finite(&self) -> Result<(), SimulationError> {
        for &i in &self.model.integrated {
            let s = &self.state;
            let ok = s.pos[i]
                .iter()
                .chain(s.vel[i].iter())
                .chain(s.omega[i].iter())
                .all(|x| x.is_finite())
                && s.rot[i].coords.iter().all(|x| x.is_finite());
            if !ok {
                return Err(SimulationError {
                    time: self.state.t,
                    step: self.step,
                    reason: format!(
                        "the state of body `{}` is not finite",
                        self.model.bodies[i].name
                    ),
                });
            }
        }
        Ok(())
    }

    fn record_frame(&mut self) {
        let (step, t) = (Cell::U64(self.step), Cell::F64(self.state.t));
        for k in 0..self.tables.len() {
            match self.tables[k].kind {
                TableKind::Bodies => {
                    for &i in &self.model.record.bodies {
                        let s = &self.state;
                        let (p, q, v, w) = (s.pos[i], s.rot[i], s.vel[i], s.omega_world(i));
                        self.tables[k].push(&[
                            step,
                            t,
                            Cell::U32(i as u32),
                            Cell::U32(i as u32),
                            Cell::F64(p.x),
                            Cell::F64(p.y),
                            Cell::F64(p.z),
                            Cell::F64(q.w),
                            Cell::F64(q.i),
                            Cell::F64(q.j),
                            Cell::F64(q.k),
                            Cell::F64(v.x),
                            Cell::F64(v.y),
                            Cell::F64(v.z),
                            Cell::F64(w.x),
                            Cell::F64(w.y),
                            Cell::F64(w.z),
                        ]);
                    }
                }
                TableKind::Contacts => {
                    let mut evals = std::mem::take(&mut self.evals);
                    for &pk in &self.model.record.pairs {
                        evals.clear();
                        self.dynamics
                            .contact_points(&self.model, &self.state, pk, &mut evals);
                        let pair = &self.model.pairs[pk];
                        for e in &evals {
                            let (f, p, n) = (e.tangential_force, e.point.point, e.point.normal);
                            self.tables[k].push(&[
                                step,
                                t,
                                Cell::U32(pk as u32),
                                Cell::U32(pk as u32),
                                Cell::U32(pair.a as u32),
                                Cell::U32(pair.b as u32),
                                Cell::U32(e.point.slot),
                                Cell::F64(e.point.depth),
                                Cell::F64(e.depth_rate),
                                Cell::F64(e.normal_force),
                                Cell::F64(f.x),
                                Cell::F64(f.y),
                                Cell::F64(f.z),
                                Cell::F64(e.slip_speed),
                                Cell::F64(p.x),
                                Cell::F64(p.y),
                                Cell::F64(p.z),
                                Cell::F64(n.x),
                                Cell::F64(n.y),
                                Cell::F64(n.z),
                            ]);
                        }
                    }
                    self.evals = evals;
                }
                TableKind::Energy => {
                    let e = self.energy();
                    self.tables[k].push(&[
                        step,
                        t,
                        Cell::F64(e.kinetic),
                        Cell::F64(e.potential_gravity),
                        Cell::F64(e.potential_contact),
                        Cell::F64(e.total()),
                    ]);
                }
            }
        }
    }
}
