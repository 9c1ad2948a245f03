//! The per-contact data of every pair in flat arrays (issue 28): one
//! allocation per kind of datum for the whole model, each pair owning a
//! fixed range of slots, instead of two vectors per pair.

use super::{CouplingJacobian, PointDerivatives, PointLaw};
use crate::geometry::{ContactPoint, SlotSink};
use crate::model::Model;

/// The laws of a slot not in use.
const UNUSED_LAW: (PointLaw, PointDerivatives) = (
    PointLaw {
        depth_rate: 0.0,
        normal_force: 0.0,
        tangential_force: crate::math::Vec3::new(0.0, 0.0, 0.0),
        slip_speed: 0.0,
    },
    PointDerivatives {
        d_depth: 0.0,
        d_rate: 0.0,
        friction: crate::math::Mat3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    },
);

/// Pair k owns slots `start[k]..start[k + 1]` of `points` and `laws` (as
/// many as [`crate::geometry::PairGeometry::slots`] says it can report), of
/// which its last evaluation filled the first `used[k]`; and, for a law that
/// latches an approach speed at onset, slots `memory[k]..memory[k + 1]` of
/// `latched` (none otherwise), indexed by the points' `slot`.
#[derive(Debug, Clone)]
pub(super) struct ContactTable {
    start: Vec<usize>,
    used: Vec<usize>,
    points: Vec<ContactPoint>,
    laws: Vec<(PointLaw, PointDerivatives)>,
    memory: Vec<usize>,
    latched: Vec<Option<f64>>,
}

/// One pair's slots, as an evaluation fills them.
pub(super) struct PairSlots<'a> {
    /// Where its contact query puts its points.
    pub points: SlotSink<'a>,
    /// The laws at each point, in the same order.
    pub laws: &'a mut [(PointLaw, PointDerivatives)],
    /// Its latched approach speeds [m/s] (empty for laws that do not latch).
    pub latched: &'a mut [Option<f64>],
    /// Its Jacobian blocks, when the evaluation fills them.
    pub coupling: Option<&'a mut CouplingJacobian>,
}

impl ContactTable {
    /// Slots for every pair of `model`.
    pub fn new(model: &Model) -> Self {
        Self::sized(model.pairs.iter().map(|p| {
            let slots = p.geometry.slots();
            (slots, p.normal.latches_approach_speed())
        }))
    }

    /// Slots for pairs of the given sizes: (points a pair can report,
    /// whether its law latches an approach speed).
    fn sized(pairs: impl Iterator<Item = (usize, bool)>) -> Self {
        let (mut start, mut memory) = (vec![0], vec![0]);
        for (slots, latches) in pairs {
            start.push(start[start.len() - 1] + slots);
            memory.push(memory[memory.len() - 1] + if latches { slots } else { 0 });
        }
        let n = start.len() - 1;
        Self {
            used: vec![0; n],
            points: vec![ContactPoint::UNUSED; start[n]],
            laws: vec![UNUSED_LAW; start[n]],
            latched: vec![None; memory[n]],
            start,
            memory,
        }
    }

    /// Whether some pair latches approach speeds.
    pub fn has_memory(&self) -> bool {
        !self.latched.is_empty()
    }

    /// Pair `k`'s points of the last evaluation, with their laws.
    #[inline]
    pub fn pair(&self, k: usize) -> (&[ContactPoint], &[(PointLaw, PointDerivatives)]) {
        let (s, n) = (self.start[k], self.used[k]);
        (&self.points[s..s + n], &self.laws[s..s + n])
    }

    /// Pair `k`'s latched approach speeds (empty for laws that do not latch).
    #[inline]
    pub fn latched(&self, k: usize) -> &[Option<f64>] {
        &self.latched[self.memory[k]..self.memory[k + 1]]
    }

    /// Calls `one(k, slots)` for every pair k, with the pair's slots and,
    /// with `couplings` (one per pair, then the joints'), its Jacobian
    /// blocks; sets each pair's count of points to what its sink holds
    /// after. With a `pool`, ranges of about `chunk` pairs go to its
    /// threads; each pair writes only its own slots, so the result does not
    /// depend on the threads.
    pub fn for_each_pair<F>(
        &mut self,
        couplings: Option<&mut [CouplingJacobian]>,
        pool: Option<&rayon::ThreadPool>,
        chunk: usize,
        one: F,
    ) where
        F: Fn(usize, &mut PairSlots) + Sync,
    {
        let n = self.used.len();
        let range = Range {
            first: 0,
            start: &self.start,
            memory: &self.memory,
            used: &mut self.used,
            points: &mut self.points,
            laws: &mut self.laws,
            latched: &mut self.latched,
            couplings: couplings.map(|c| &mut c[..n]),
        };
        match pool {
            None => range.each(&one),
            Some(pool) => pool.install(|| range.split(chunk.max(1), &one)),
        }
    }
}

impl ContactTable {
    /// Calls `one(k, slots)` for each pair k of `pairs` in turn, on this
    /// thread, with `couplings[i]` for `pairs[i]` when given (a
    /// quasi-static group's own blocks); sets each pair's count of points.
    pub fn each_listed<F>(
        &mut self,
        pairs: &[usize],
        mut couplings: Option<&mut [CouplingJacobian]>,
        one: F,
    ) where
        F: Fn(usize, &mut PairSlots),
    {
        for (i, &k) in pairs.iter().enumerate() {
            let mut slots = pair_slots(
                (
                    &mut self.points[..],
                    &mut self.laws[..],
                    &mut self.latched[..],
                ),
                (self.start[k], self.start[k + 1]),
                (self.memory[k], self.memory[k + 1]),
                couplings.as_deref_mut().map(|c| &mut c[i]),
            );
            one(k, &mut slots);
            self.used[k] = slots.points.len;
        }
    }
}

/// The points, laws and latched speeds of a run of slots.
type SlotArrays<'a> = (
    &'a mut [ContactPoint],
    &'a mut [(PointLaw, PointDerivatives)],
    &'a mut [Option<f64>],
);

/// One pair's slots: `points[s..e]`, `laws[s..e]` and `latched[ms..me]`,
/// with its Jacobian blocks when the evaluation fills them.
fn pair_slots<'a>(
    (points, laws, latched): SlotArrays<'a>,
    (s, e): (usize, usize),
    (ms, me): (usize, usize),
    coupling: Option<&'a mut CouplingJacobian>,
) -> PairSlots<'a> {
    PairSlots {
        points: SlotSink {
            slots: &mut points[s..e],
            len: 0,
            turning: coupling.is_some(),
        },
        laws: &mut laws[s..e],
        latched: &mut latched[ms..me],
        coupling,
    }
}

/// The slots of the pairs `first..first + used.len()`: the offset tables
/// are absolute, the slices start at the range's first pair.
struct Range<'a> {
    first: usize,
    start: &'a [usize],
    memory: &'a [usize],
    used: &'a mut [usize],
    points: &'a mut [ContactPoint],
    laws: &'a mut [(PointLaw, PointDerivatives)],
    latched: &'a mut [Option<f64>],
    couplings: Option<&'a mut [CouplingJacobian]>,
}

impl Range<'_> {
    /// Each pair of the range in turn, on this thread.
    fn each(self, one: &(impl Fn(usize, &mut PairSlots) + Sync)) {
        let (s0, m0) = (self.start[self.first], self.memory[self.first]);
        let mut couplings = self.couplings;
        for (i, used) in self.used.iter_mut().enumerate() {
            let k = self.first + i;
            let mut slots = pair_slots(
                (
                    &mut self.points[..],
                    &mut self.laws[..],
                    &mut self.latched[..],
                ),
                (self.start[k] - s0, self.start[k + 1] - s0),
                (self.memory[k] - m0, self.memory[k + 1] - m0),
                couplings.as_deref_mut().map(|c| &mut c[i]),
            );
            one(k, &mut slots);
            *used = slots.points.len;
        }
    }

    /// The range in halves on the pool's threads, down to about `chunk` pairs.
    fn split(self, chunk: usize, one: &(impl Fn(usize, &mut PairSlots) + Sync)) {
        let n = self.used.len();
        if n <= chunk {
            return self.each(one);
        }
        let mid = self.first + n / 2;
        let (s0, m0) = (self.start[self.first], self.memory[self.first]);
        let (used_l, used_r) = self.used.split_at_mut(n / 2);
        let (points_l, points_r) = self.points.split_at_mut(self.start[mid] - s0);
        let (laws_l, laws_r) = self.laws.split_at_mut(self.start[mid] - s0);
        let (latched_l, latched_r) = self.latched.split_at_mut(self.memory[mid] - m0);
        let (couplings_l, couplings_r) = match self.couplings {
            Some(c) => {
                let (l, r) = c.split_at_mut(n / 2);
                (Some(l), Some(r))
            }
            None => (None, None),
        };
        let left = Range {
            first: self.first,
            start: self.start,
            memory: self.memory,
            used: used_l,
            points: points_l,
            laws: laws_l,
            latched: latched_l,
            couplings: couplings_l,
        };
        let right = Range {
            first: mid,
            start: self.start,
            memory: self.memory,
            used: used_r,
            points: points_r,
            laws: laws_r,
            latched: latched_r,
            couplings: couplings_r,
        };
        rayon::join(|| left.split(chunk, one), || right.split(chunk, one));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::PointSink;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Pair sizes as in the paper's scene: link–tube pairs of 20 slots
    /// (level sets of 9 samples and the tube's two open ends), and
    /// single-point pairs of which some latch (Hunt–Crossley) and some do
    /// not (IMPACT).
    const PAIRS: [(usize, bool); 9] = [
        (20, false),
        (20, false),
        (1, true),
        (1, false),
        (1, true),
        (1, true),
        (20, false),
        (1, false),
        (1, true),
    ];

    #[test]
    fn each_pair_owns_its_slots_and_memory_only_where_its_law_latches() {
        let table = ContactTable::sized(PAIRS.into_iter());
        let (mut slots, mut remembered) = (0, 0);
        for (k, &(n, latches)) in PAIRS.iter().enumerate() {
            assert_eq!(
                table.start[k], slots,
                "pair {k} starts where the one before ends"
            );
            slots += n;
            let memory = table.latched(k).len();
            assert_eq!(memory, if latches { n } else { 0 }, "pair {k}");
            remembered += memory;
        }
        assert_eq!((table.points.len(), table.laws.len()), (slots, slots));
        assert_eq!((table.latched.len(), remembered), (4, 4));
        assert!(table.has_memory());
        assert!(!ContactTable::sized([(20, false), (1, false)].into_iter()).has_memory());
    }

    #[test]
    fn threads_visit_every_pair_once_with_its_own_slots() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool");
        for (pool, chunk) in [(None, 1), (Some(&pool), 1), (Some(&pool), 3)] {
            let mut table = ContactTable::sized(PAIRS.into_iter());
            let visits: Vec<_> = PAIRS.iter().map(|_| AtomicUsize::new(0)).collect();
            // Pair k fills k mod 3 + 1 of its slots (at most all), each
            // marked with k, to check below that no pair wrote another's.
            let fills = |k: usize| (k % 3 + 1).min(PAIRS[k].0);
            table.for_each_pair(None, pool, chunk, |k, s| {
                visits[k].fetch_add(1, Ordering::Relaxed);
                let (n, latches) = PAIRS[k];
                assert_eq!(s.points.slots.len(), n, "pair {k}");
                assert_eq!(s.laws.len(), n, "pair {k}");
                assert_eq!(s.latched.len(), if latches { n } else { 0 }, "pair {k}");
                for _ in 0..fills(k) {
                    let mut point = ContactPoint::UNUSED;
                    point.depth = k as f64;
                    s.points.push(point);
                }
            });
            for (k, v) in visits.iter().enumerate() {
                assert_eq!(v.load(Ordering::Relaxed), 1, "pair {k}");
                let (points, laws) = table.pair(k);
                assert_eq!((points.len(), laws.len()), (fills(k), fills(k)), "pair {k}");
                assert!(points.iter().all(|p| p.depth == k as f64), "pair {k}");
            }
        }
    }
}
