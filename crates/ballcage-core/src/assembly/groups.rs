//! Quasi-static bodies → the groups solved together for equilibrium.

use crate::error::SceneError;
use crate::math::{Quat, Vec3};
use crate::model::{Body, ContactPair, Motion, State, StaticGroup};

/// The quasi-static bodies of `bodies`, grouped by the contact pairs that
/// join them, each group with the bodies outside it that its pairs touch
/// (held), those pairs, and where each held body carries each free one
/// from `state` (the initial state). A group that touches no other body is
/// refused (a joint on a quasi-static body is refused by the scene's
/// validation).
pub(super) fn static_groups(
    bodies: &[Body],
    pairs: &[ContactPair],
    state: &State,
) -> Result<Vec<StaticGroup>, SceneError> {
    let dofs = |i: usize| match bodies[i].motion {
        Motion::QuasiStatic(d) => Some(d),
        _ => None,
    };
    let mut root = roots_of(bodies.len(), pairs, |i| dofs(i).is_some());
    // Each quasi-static body's group, numbered in order of their first bodies.
    let mut group_of = vec![None; bodies.len()];
    let mut groups: Vec<StaticGroup> = Vec::new();
    let mut roots: Vec<usize> = Vec::new();
    for i in (0..bodies.len()).filter(|&i| dofs(i).is_some()) {
        let r = find(&mut root, i);
        let g = roots.iter().position(|&x| x == r).unwrap_or_else(|| {
            roots.push(r);
            groups.push(StaticGroup {
                free: vec![],
                held: vec![],
                pairs: vec![],
                carried: vec![],
            });
            groups.len() - 1
        });
        group_of[i] = Some(g);
        groups[g].free.push((i, dofs(i).expect("quasi-static")));
    }
    for (k, p) in pairs.iter().enumerate() {
        for g in [group_of[p.a], group_of[p.b]].into_iter().flatten() {
            let group = &mut groups[g];
            if group.pairs.last() != Some(&k) {
                group.pairs.push(k);
            }
            for i in [p.a, p.b] {
                if group_of[i].is_none() && !group.held.contains(&i) {
                    group.held.push(i);
                }
            }
        }
    }
    for g in &mut groups {
        g.held.sort_unstable();
        if g.held.is_empty() {
            let first = g.free[0].0;
            return Err(SceneError::new(
                format!("bodies[{first}].motion"),
                bodies[first].name.clone(),
                "is quasi-static, but no contact pair joins it or its group to a body that is not: \
                 nothing holds it",
            ));
        }
    }
    for g in &mut groups {
        g.carried = carried(g, state);
    }
    Ok(groups)
}

/// Union–find over the pairs between two bodies that are `in_group`: each
/// body's link toward its component's root ([`find`]).
fn roots_of(n: usize, pairs: &[ContactPair], in_group: impl Fn(usize) -> bool) -> Vec<usize> {
    let mut root: Vec<usize> = (0..n).collect();
    for p in pairs {
        if in_group(p.a) && in_group(p.b) {
            let (ra, rb) = (find(&mut root, p.a), find(&mut root, p.b));
            root[ra.max(rb)] = ra.min(rb);
        }
    }
    root
}

/// The root of body `i`'s component, compressing the path on the way.
fn find(root: &mut [usize], mut i: usize) -> usize {
    while root[i] != i {
        root[i] = root[root[i]];
        i = root[i];
    }
    i
}

/// Per free body of `g`, per held body: the free body's pose in the held
/// body's frame at `state`.
fn carried(g: &StaticGroup, state: &State) -> Vec<Vec<(Vec3, Quat)>> {
    g.free
        .iter()
        .map(|&(f, _)| {
            g.held
                .iter()
                .map(|&h| {
                    let inv = state.rot[h].inverse();
                    (inv * (state.pos[f] - state.pos[h]), inv * state.rot[f])
                })
                .collect()
        })
        .collect()
}
