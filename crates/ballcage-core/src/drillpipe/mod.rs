//! The paper's ball-cage flexible drill pipe (Zhu et al., Machines 2023): a
//! layer above the generic engine. Nothing under the engine's modules names
//! it.
//!
//! A drill-pipe document ([`DrillPipeSpec`], engineering parameters with the
//! paper's defaults, docs/model.md §4) is validated and expanded
//! ([`DrillPipeSpec::expand`]) into a generic [`Scene`](crate::scene::Scene)
//! plus the [`Layout`] of its parts by id. Its tables (`links`, `hinges`,
//! `keys`, `drive`, `pairs`, `wear`) come from [`PipeTables`], an observer
//! registered with the simulation through [`crate::record::Observer`].
//!
//! | module | job |
//! |---|---|
//! | `spec` | the document: sections, defaults, validation |
//! | `fatigue` | the `[fatigue]` section: critical sections of a link, S–N curve |
//! | `provenance` | where each default comes from: the paper, a rule, a PROPOSAL (range and why) |
//! | `expand` | document → scene + layout, one function per part |
//! | `names` | the one place part names are formatted |
//! | `layout` | body and pair ids of the parts |
//! | `tables` | the drill pipe's output tables and their observer |
//! | `ids` | the id columns of the `pairs` and `wear` tables |
//! | `stress` | the Hertz contact model of each pair |
//! | `wear` | the `wear` table: Archard wear and peak pressure per pair |
//! | `sizing` | eq. (9) both ways and the articulation limit |
//! | `chain` | placement along the centreline, eq. (4)/(5) |
//! | `cv` | exact constant-velocity ball-cage geometry |

pub mod chain;
pub mod cv;
mod expand;
mod fatigue;
mod ids;
mod layout;
pub mod names;
mod provenance;
pub mod sizing;
mod spec;
pub mod stress;
pub mod tables;
pub mod wear;

pub use expand::Expansion;
pub use fatigue::FatigueSpec;
pub use layout::{BodyPart, Feature, HingeLayout, KeyLayout, Layout, PairPart, Part};
pub use provenance::PROVENANCE;
pub use spec::{
    BallKeySpec, BoreholeSpec, DrillPipeSpec, DriveSpec, GravitySpec, HingeModel, IdealCvSpec,
    KIND, LowerEnd, MaterialSpec, MaterialsSpec, PipeRecordSpec, PipeSpec, PipeTable,
    ResistingMomentSpec, SolidSpec, WearSpec,
};
pub use tables::PipeTables;
