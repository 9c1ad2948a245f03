//! Block elimination along the bodies' coupling graph: the default linear
//! solver of the implicit steps.
//!
//! The Newton matrix has one dense block per integrated body (6 × 6, or
//! 1 × 1 for a `spin` body) on its diagonal and one pair of off-diagonal
//! blocks per declared contact pair or joint between two integrated bodies.
//! Its graph is the scene's graph of bodies and pairs. [`BlockLu::new`]
//! orders the bodies by minimum degree on that graph (a greedy
//! elimination, ties broken by index, so the order is deterministic) and
//! records once where the elimination fills in. In a chain of links joined
//! by hinges made of a cage and balls, the balls go first (each touches the
//! two links and the cage), then the cages: each hinge is condensed onto
//! its two links by a Schur complement, and the links that remain form a
//! block-tridiagonal system eliminated without fill. Nothing in it knows
//! about drill pipes: any chain-like or tree-like scene gets the same.
//!
//! The numeric factorization is block LDU without pivoting between blocks:
//! U_kj = D_k⁻¹·A_kj, A_ij −= A_ik·U_kj for the later neighbours i, j of
//! each eliminated body k, the pivot block D_k inverted by LU with partial
//! pivoting. Every block is stored as a 6 × 6 matrix (a 1 × 1 block padded
//! with the identity on the diagonal and zeros elsewhere), so that every
//! operation is a fixed-size 6 × 6 product. Pivoting only within blocks is
//! safe for the implicit steps' matrices M − γh·(D + γh·K): the mass is
//! positive definite and the damping, friction and stiffness of dissipative
//! contacts only add to the symmetric part. A pivot block that cannot be
//! inverted makes [`BlockLu::factor`] return false, as the sparse LU does.
//!
//! Everything is allocated in [`BlockLu::new`]; factoring and solving
//! allocate nothing.

use std::collections::{BTreeMap, BTreeSet};

use crate::dynamics::Mat6;

/// A 6-vector.
type Vec6 = nalgebra::Vector6<f64>;

/// One block update of the factorization: blocks[dst] −= blocks[lower]·blocks[upper].
#[derive(Debug, Clone, Copy)]
struct Update {
    dst: usize,
    lower: usize,
    upper: usize,
}

/// A later neighbour j of an eliminated body k: its index, the block A_jk
/// (then L_jk·D_k) and the block A_kj (then U_kj).
#[derive(Debug, Clone, Copy)]
struct Later {
    node: usize,
    lower: usize,
    upper: usize,
}

/// Block LDU factorization of a block-sparse matrix with a fixed pattern.
#[derive(Debug, Clone)]
pub(crate) struct BlockLu {
    /// Per node: its first unknown and its dimension (1..=6).
    offsets: Vec<(usize, usize)>,
    /// Nodes in elimination order.
    order: Vec<usize>,
    /// Block values; index of each (row node, column node) in `index`.
    blocks: Vec<Mat6>,
    index: BTreeMap<(usize, usize), usize>,
    /// Per node: its diagonal block, then the inverse of its pivot.
    diag: Vec<usize>,
    pivots: Vec<Mat6>,
    /// Per position in `order`: its later neighbours `later[later_start[p]..later_start[p + 1]]`
    /// and its updates likewise.
    later_start: Vec<usize>,
    later: Vec<Later>,
    update_start: Vec<usize>,
    updates: Vec<Update>,
    /// Per node: the right-hand side, then the solution.
    work: Vec<Vec6>,
}

impl BlockLu {
    /// The pattern of `offsets.len()` nodes (first unknown and dimension
    /// ≤ 6 of each) coupled by `edges` (pairs of distinct nodes, in any
    /// order, repeats allowed), with its elimination order and fill.
    pub(crate) fn new(offsets: Vec<(usize, usize)>, edges: &[(usize, usize)]) -> Self {
        assert!(offsets.iter().all(|&(_, d)| (1..=6).contains(&d)));
        let n = offsets.len();
        let mut graph: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
        for &(a, b) in edges {
            if a != b {
                graph[a].insert(b);
                graph[b].insert(a);
            }
        }
        let (order, filled) = minimum_degree(graph);
        let mut position = vec![0; n];
        for (p, &k) in order.iter().enumerate() {
            position[k] = p;
        }
        let mut index = BTreeMap::new();
        for (i, neighbours) in filled.iter().enumerate() {
            index.insert((i, i), 0);
            for &j in neighbours {
                index.insert((i, j), 0);
            }
        }
        for (k, slot) in index.values_mut().enumerate() {
            *slot = k;
        }
        let diag = (0..n).map(|i| index[&(i, i)]).collect();
        let (mut later_start, mut later) = (vec![0], vec![]);
        let (mut update_start, mut updates) = (vec![0], vec![]);
        for &k in &order {
            let next: Vec<usize> = filled[k]
                .iter()
                .copied()
                .filter(|&j| position[j] > position[k])
                .collect();
            for &j in &next {
                later.push(Later {
                    node: j,
                    lower: index[&(j, k)],
                    upper: index[&(k, j)],
                });
                for &i in &next {
                    updates.push(Update {
                        dst: index[&(i, j)],
                        lower: index[&(i, k)],
                        upper: index[&(k, j)],
                    });
                }
            }
            later_start.push(later.len());
            update_start.push(updates.len());
        }
        Self {
            offsets,
            order,
            blocks: vec![Mat6::zeros(); index.len()],
            index,
            diag,
            pivots: vec![Mat6::zeros(); n],
            later_start,
            later,
            update_start,
            updates,
            work: vec![Vec6::zeros(); n],
        }
    }

    /// The block of (row node `i`, column node `j`), if in the pattern.
    pub(crate) fn block(&self, i: usize, j: usize) -> Option<usize> {
        self.index.get(&(i, j)).copied()
    }

    /// Zeroes every block.
    pub(crate) fn clear(&mut self) {
        self.blocks.fill(Mat6::zeros());
    }

    /// blocks[b] += scale·m, m in the leading dim_i × dim_j corner (the rest zero).
    pub(crate) fn add(&mut self, b: usize, m: &Mat6, scale: f64) {
        self.blocks[b] += scale * m;
    }

    /// Factors the assembled matrix in place; false if a pivot block is
    /// singular or not finite.
    pub(crate) fn factor(&mut self) -> bool {
        for (p, &k) in self.order.iter().enumerate() {
            let mut pivot = self.blocks[self.diag[k]];
            let dim = self.offsets[k].1;
            for r in dim..6 {
                pivot[(r, r)] = 1.0;
            }
            let Some(inverse) = pivot
                .try_inverse()
                .filter(|m| m.iter().all(|x| x.is_finite()))
            else {
                return false;
            };
            self.pivots[k] = inverse;
            for l in &self.later[self.later_start[p]..self.later_start[p + 1]] {
                self.blocks[l.upper] = inverse * self.blocks[l.upper];
            }
            for u in &self.updates[self.update_start[p]..self.update_start[p + 1]] {
                let product = self.blocks[u.lower] * self.blocks[u.upper];
                self.blocks[u.dst] -= product;
            }
        }
        true
    }

    /// Overwrites `rhs` (all unknowns) with the solution of the factored
    /// system.
    pub(crate) fn solve(&mut self, rhs: &mut [f64]) {
        for (w, &(off, dim)) in self.work.iter_mut().zip(&self.offsets) {
            w.fill(0.0);
            for r in 0..dim {
                w[r] = rhs[off + r];
            }
        }
        // Forward: y_k = D_k⁻¹·b_k, then b_j −= A_jk·y_k.
        for (p, &k) in self.order.iter().enumerate() {
            let y = self.pivots[k] * self.work[k];
            self.work[k] = y;
            for l in &self.later[self.later_start[p]..self.later_start[p + 1]] {
                self.work[l.node] -= self.blocks[l.lower] * y;
            }
        }
        // Backward: x_k = y_k − Σ_j U_kj·x_j.
        for (p, &k) in self.order.iter().enumerate().rev() {
            let mut x = self.work[k];
            for l in &self.later[self.later_start[p]..self.later_start[p + 1]] {
                x -= self.blocks[l.upper] * self.work[l.node];
            }
            self.work[k] = x;
        }
        for (w, &(off, dim)) in self.work.iter().zip(&self.offsets) {
            rhs[off..off + dim].copy_from_slice(&w.as_slice()[..dim]);
        }
    }

    /// Blocks stored after fill, and block updates per factorization.
    #[cfg(test)]
    fn size(&self) -> (usize, usize) {
        (self.blocks.len(), self.updates.len())
    }
}

/// Greedy minimum-degree elimination of `graph`: the order, and the graph
/// with the fill of that elimination (every edge it creates).
fn minimum_degree(graph: Vec<BTreeSet<usize>>) -> (Vec<usize>, Vec<BTreeSet<usize>>) {
    let n = graph.len();
    let mut filled = graph.clone();
    let mut live = graph;
    let mut done = vec![false; n];
    let mut order = Vec::with_capacity(n);
    for _ in 0..n {
        let k = (0..n)
            .filter(|&i| !done[i])
            .min_by_key(|&i| (live[i].len(), i))
            .expect("a node left");
        done[k] = true;
        order.push(k);
        let neighbours: Vec<usize> = live[k].iter().copied().collect();
        for &i in &neighbours {
            live[i].remove(&k);
            for &j in &neighbours {
                if i != j {
                    live[i].insert(j);
                    filled[i].insert(j);
                }
            }
        }
        live[k].clear();
    }
    (order, filled)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A deterministic pseudo-random number in [−1, 1).
    fn lcg(x: &mut u64) -> f64 {
        *x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        2.0 * ((*x >> 11) as f64 / (1u64 << 53) as f64) - 1.0
    }

    /// A chain of `links` 6-dof bodies, a 1-dof body at its head, and a
    /// "hinge" of a cage and three balls between each pair of links.
    /// (first unknown, dimension) of each node, and the edges.
    type Graph = (Vec<(usize, usize)>, Vec<(usize, usize)>);

    fn chain(links: usize) -> Graph {
        let mut dims = vec![1];
        dims.extend(std::iter::repeat_n(6, links));
        let mut edges = vec![(0, 1)];
        for l in 1..links {
            let cage = dims.len();
            dims.extend([6, 6, 6, 6]);
            edges.extend([(l, l + 1), (cage, l), (cage, l + 1)]);
            for b in 1..4 {
                edges.extend([(cage + b, l), (cage + b, l + 1), (cage + b, cage)]);
            }
        }
        let mut off = 0;
        let offsets = dims
            .iter()
            .map(|&d| {
                off += d;
                (off - d, d)
            })
            .collect();
        (offsets, edges)
    }

    /// Fills a non-symmetric matrix with a dominant positive diagonal on the
    /// pattern, in both `lu` and a dense copy.
    fn fill(lu: &mut BlockLu, edges: &[(usize, usize)], seed: u64) -> DMatrix<f64> {
        let n: usize = lu.offsets.iter().map(|o| o.1).sum();
        let mut dense = DMatrix::zeros(n, n);
        let mut x = seed;
        lu.clear();
        let mut put = |lu: &mut BlockLu, i: usize, j: usize, diag: f64| {
            let (oi, di) = lu.offsets[i];
            let (oj, dj) = lu.offsets[j];
            let mut m = Mat6::zeros();
            for r in 0..di {
                for c in 0..dj {
                    m[(r, c)] = lcg(&mut x) + if r == c { diag } else { 0.0 };
                    dense[(oi + r, oj + c)] += m[(r, c)];
                }
            }
            let b = lu.block(i, j).expect("in the pattern");
            lu.add(b, &m, 1.0);
        };
        for i in 0..lu.offsets.len() {
            put(lu, i, i, 20.0);
        }
        for &(a, b) in edges {
            put(lu, a, b, 0.0);
            put(lu, b, a, 0.0);
        }
        dense
    }

    #[test]
    fn solves_a_hinged_chain_as_the_dense_lu_does() {
        let (offsets, edges) = chain(5);
        let mut lu = BlockLu::new(offsets, &edges);
        let dense = fill(&mut lu, &edges, 7);
        let n = dense.nrows();
        let mut x = 3;
        let b: Vec<f64> = (0..n).map(|_| lcg(&mut x)).collect();
        assert!(lu.factor());
        let mut sol = b.clone();
        lu.solve(&mut sol);
        let expected = dense
            .clone()
            .lu()
            .solve(&nalgebra::DVector::from(b))
            .unwrap();
        for (s, e) in sol.iter().zip(expected.iter()) {
            assert!((s - e).abs() < 1e-12 * (1.0 + e.abs()), "{s} vs {e}");
        }
    }

    #[test]
    fn a_hinged_chain_is_eliminated_without_fill() {
        let (offsets, edges) = chain(4);
        let lu = BlockLu::new(offsets, &edges);
        // Minimum degree finds an order that creates no fill: each hinge
        // condensed onto its links (in whichever order ties fall), and the
        // links eliminated along the chain.
        // No fill: every block is on the diagonal or an edge of the graph.
        let edge_blocks = 2 * edges.len();
        assert_eq!(lu.size().0, lu.offsets.len() + edge_blocks);
    }

    #[test]
    fn a_singular_pivot_is_reported() {
        let (offsets, edges) = chain(2);
        let mut lu = BlockLu::new(offsets, &edges);
        lu.clear();
        assert!(!lu.factor());
    }
}
