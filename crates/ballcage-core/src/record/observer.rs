//! The interface through which a layer above the engine adds output tables.
//!
//! The engine records its own tables ([`super::BODIES`], [`super::CONTACTS`],
//! [`super::ENERGY`], [`super::SUMMARY`]). A scene kind built on top of it,
//! such as the drill pipe, registers an [`Observer`] with the simulation; at
//! every recorded frame the recorder hands each observer the frame and the
//! buffers of the tables it declared. The engine never needs to know what
//! those tables mean.

use std::fmt::Debug;

use super::{TableBuffer, TableDef};
use crate::dynamics::{ContactEval, PairTotals};
use crate::math::Vec3;
use crate::model::{Model, State};

/// What an observer sees of one recorded frame.
#[derive(Debug, Clone, Copy)]
pub struct Frame<'a> {
    /// The assembled model.
    pub model: &'a Model,
    /// The state at the frame.
    pub state: &'a State,
    /// Integrator step index of the frame.
    pub step: u64,
    /// Contact points of every pair with their forces, indexed by pair id.
    /// Evaluated once per frame and shared by every table; empty lists when
    /// no table asked for contacts.
    pub contacts: &'a [Vec<ContactEval>],
    /// Each pair's impulse since t = 0 as the integrator applied it, by
    /// pair id: ∫ normal force dt and ∫ |summed friction force| dt [N·s]
    /// ([`crate::dynamics::Impulses`]); empty unless an observer asked for
    /// it ([`Observer::needs_impulses`]).
    pub impulses: &'a [PairTotals],
    /// Each pair's largest totals [N] (normal, friction magnitude) since the
    /// previous frame, by pair id: at every stage of the integrator's steps
    /// accepted since then, or the frame's own totals where none was (the
    /// first frame; a frame inside a step longer than the output interval).
    /// Empty unless [`Self::impulses`] is kept.
    pub peaks: &'a [PairTotals],
}

impl Frame<'_> {
    /// Pair `k`'s largest totals since the previous frame ([`Self::peaks`]),
    /// or at this frame when they are not kept.
    pub fn peak(&self, k: usize) -> PairTotals {
        self.peaks.get(k).copied().unwrap_or_else(|| {
            let (n, t) = contact_totals(self.contacts, &[k]);
            [n, t]
        })
    }
}

/// What an observer sees after every integrator step, when it asks for it
/// ([`Observer::needs_steps`]): integrals over the run (work, sliding
/// distance, the largest pressure) need every step, not only the frames.
#[derive(Debug, Clone, Copy)]
pub struct Step<'a> {
    /// The assembled model.
    pub model: &'a Model,
    /// The state at the end of the step.
    pub state: &'a State,
    /// The step's length [s].
    pub h: f64,
    /// Contact points of every pair with their forces at the end of the
    /// step, indexed by pair id.
    pub contacts: &'a [Vec<ContactEval>],
}

/// Where a body sits in the assembly a layer above the engine built: the
/// `bodies` table's part columns. Ids that do not apply are `None`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PartIds {
    /// What the body is: an index into [`BodyParts::labels`].
    pub part: Option<u32>,
    /// Link number in a chain.
    pub link: Option<u32>,
    /// Hinge number in a chain.
    pub hinge: Option<u32>,
    /// Ball key number within its hinge.
    pub key: Option<u32>,
}

/// The parts of the bodies a layer built, for the `bodies` table.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BodyParts {
    /// Labels of [`PartIds::part`], indexed by it.
    pub labels: &'static [&'static str],
    /// Each body's ids, indexed by body id; bodies past its end have none.
    pub ids: Vec<PartIds>,
}

impl BodyParts {
    /// The ids of body `body` (all `None` for a body the layer did not describe).
    pub fn of(&self, body: usize) -> PartIds {
        self.ids.get(body).copied().unwrap_or_default()
    }
}

/// A producer of output tables, registered with a simulation by a layer
/// above the engine.
pub trait Observer: Debug + Send + Sync {
    /// The tables it fills, in order; fixed for the observer's lifetime.
    fn tables(&self) -> Vec<&'static TableDef>;

    /// Rows each of its tables (in the order of [`Self::tables`]) holds
    /// after `frames` recorded frames, at most: the memory estimate made
    /// before a run ([`super::check_budget`]).
    fn rows(&self, frames: u64) -> Vec<u64>;

    /// Whether it reads [`Frame::contacts`].
    fn needs_contacts(&self) -> bool;

    /// Appends the rows of one frame; `out[i]` is the buffer of `tables()[i]`.
    fn record(&mut self, frame: &Frame<'_>, out: &mut [TableBuffer]);

    /// Whether it reads every step ([`Self::step`]); each step then costs
    /// one more evaluation of the contact points. Default: no.
    fn needs_steps(&self) -> bool {
        false
    }

    /// Sees the end of every integrator step (only if [`Self::needs_steps`]).
    fn step(&mut self, _step: &Step<'_>) {}

    /// Whether it reads [`Frame::impulses`]; the integrators then keep
    /// every pair's totals at every stage. Default: no.
    fn needs_impulses(&self) -> bool {
        false
    }

    /// Appends the end-of-run rows at simulated time `end_time` [s]; `out`
    /// as in [`Self::record`]. Default: none.
    fn finish(&mut self, _model: &Model, _end_time: f64, _out: &mut [TableBuffer]) {}

    /// The parts of the scene's bodies, for the `bodies` table's part
    /// columns; the first observer that has them gives them. Default: none
    /// (the columns are null).
    fn body_parts(&self) -> Option<BodyParts> {
        None
    }

    /// A boxed copy (simulations are cloneable).
    fn clone_box(&self) -> Box<dyn Observer>;
}

impl Clone for Box<dyn Observer> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// Total normal force [N] and magnitude of the summed friction force [N] of
/// every point of the pairs `pairs` (pair ids into `contacts`).
pub fn contact_totals(contacts: &[Vec<ContactEval>], pairs: &[usize]) -> (f64, f64) {
    let mut n = 0.0;
    let mut f = Vec3::zeros();
    for &k in pairs {
        for e in &contacts[k] {
            n += e.normal_force;
            f += e.tangential_force;
        }
    }
    (n, f.norm())
}
