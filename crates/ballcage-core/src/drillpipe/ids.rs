//! The columns that say which contact pair a row is and where it sits in
//! the pipe: the first six of the `pairs` and `wear` tables, defined once
//! for both.

use super::layout::{Feature, PairPart};
use crate::record::{Cell, ColumnDef, ColumnKind, Dictionary, col};

use ColumnKind::{Name, OptU32, U32};

/// The pair's index: the first of the id columns ([`pair_cells`]).
pub(super) const PAIR_ID: ColumnDef = col(
    "pair_id",
    U32,
    "",
    "contact pair index in the scene's contact list (the contacts and summary tables' pair_id)",
);
/// See [`PAIR_ID`].
pub(super) const PAIR: ColumnDef = col("pair", Name(Dictionary::Pairs), "", "contact pair name");
/// See [`PAIR_ID`].
pub(super) const FEATURE: ColumnDef = col(
    "feature",
    Name(Dictionary::Labels(Feature::LABELS)),
    "",
    "what the pair touches: tube, cage-head, cage-seat, inner-race, outer-race, window or neck-mouth",
);
/// See [`PAIR_ID`].
pub(super) const LINK: ColumnDef = col(
    "link",
    OptU32,
    "",
    "link number, 1 at the top (tube pairs; null otherwise)",
);
/// See [`PAIR_ID`].
pub(super) const HINGE: ColumnDef = col(
    "hinge",
    OptU32,
    "",
    "hinge number, 0 above link 1 (joint pairs; null otherwise)",
);
/// See [`PAIR_ID`].
pub(super) const KEY: ColumnDef = col(
    "key",
    OptU32,
    "",
    "ball key number, 0-5 (key pairs; null otherwise)",
);

/// The cells of [`PAIR_ID`] … [`KEY`] for pair `k`, `part`.
pub(super) fn pair_cells(k: usize, part: &PairPart) -> [Cell; 6] {
    [
        Cell::U32(k as u32),
        Cell::U32(k as u32),
        Cell::U32(part.feature.code()),
        Cell::OptU32(part.link),
        Cell::OptU32(part.hinge),
        Cell::OptU32(part.key),
    ]
}
