//! A window slot: the gap between two parallel planes (a cage window seen by
//! the ball it holds).

use parry3d_f64::math::Vector;

use crate::contact::{LocalContact, Rod, unit};
use crate::line::Ends;

/// The gap of width 2·`half_width` about the mid-plane through `centre` with
/// unit normal `normal`, in its frame: the solid is the two half-spaces
/// beyond the faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowSlot {
    /// A point of the mid-plane [m].
    pub centre: Vector,
    /// Unit normal of the planes.
    pub normal: Vector,
    /// Half the gap [m].
    pub half_width: f64,
}

impl WindowSlot {
    /// The slot about `centre` with `normal` (normalized here) and
    /// `half_width` [m].
    pub fn new(centre: Vector, normal: Vector, half_width: f64) -> Self {
        Self {
            centre,
            normal: unit(normal),
            half_width,
        }
    }

    /// Signed height of `p` above the mid-plane [m].
    #[inline]
    pub fn height(&self, p: Vector) -> f64 {
        (p - self.centre).dot(self.normal)
    }

    /// A ball of `ball_radius` [m] centred at `p` against the face on its
    /// side of the mid-plane (height u): δ = r + |u| − w, pushed back along
    /// ∓normal.
    pub fn ball_contact(&self, p: Vector, ball_radius: f64) -> LocalContact {
        let u = self.height(p);
        let depth = ball_radius + u.abs() - self.half_width;
        let side = if u >= 0.0 { 1.0 } else { -1.0 };
        LocalContact {
            point: p + side * (ball_radius - 0.5 * depth) * self.normal,
            normal: -side * self.normal,
            depth,
            feature: 0,
        }
    }

    /// A rod against both faces: for each face (σ = ±1) and each end of the
    /// axis (s = ∓L/2), the end's surface point farthest toward that face —
    /// for a cylinder the rim point along the part of σ·normal across the
    /// axis (the end's centre when the axis is along the normal, the flat
    /// end then lying on the face), for a capsule the end sphere's point
    /// σ·r·normal — with δ = σ·height − w. Reports those deeper than
    /// `threshold` [m]; `feature` = 2·face + end.
    pub fn rod_contacts(
        &self,
        rod: &Rod,
        ends: Ends,
        threshold: f64,
        emit: &mut impl FnMut(LocalContact),
    ) {
        for (face, sigma) in [(0u32, 1.0), (1, -1.0)] {
            let n = sigma * self.normal;
            let across = n - n.dot(rod.axis) * rod.axis;
            let len = across.length();
            for (end, s) in [(0u32, -rod.half_length), (1, rod.half_length)] {
                let e = rod.at(s);
                let w = match ends {
                    Ends::Round => e + rod.radius * n,
                    Ends::Flat if len > 1e-12 => e + rod.radius * across / len,
                    Ends::Flat => e,
                };
                let depth = sigma * self.height(w) - self.half_width;
                if depth > threshold {
                    emit(LocalContact {
                        point: w - 0.5 * depth * n,
                        normal: -n,
                        depth,
                        feature: 2 * face + end,
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ball_is_pushed_back_from_the_face_it_crosses() {
        let s = WindowSlot::new(Vector::ZERO, Vector::Y, 0.008);
        // 0.7 mm below the mid-plane, radius 7.5 mm: 0.2 mm into the lower face.
        let c = s.ball_contact(Vector::new(0.3, -0.0007, 0.1), 0.0075);
        assert!((c.depth - 2e-4).abs() < 1e-15);
        assert_eq!(c.normal, Vector::Y);
    }

    /// A cylinder tilted by θ about z, its centre on the mid-plane: each end
    /// reaches (L/2)·sin θ + r·cos θ toward the face it leans to, so
    /// δ = that − w there, on both faces by symmetry.
    #[test]
    fn a_tilted_cylinder_touches_each_face_with_one_rim() {
        let (th, h, r, w) = (0.3_f64, 0.01, 0.004, 0.006);
        let slot = WindowSlot::new(Vector::ZERO, Vector::Y, w);
        let rod = Rod {
            centre: Vector::ZERO,
            axis: Vector::new(th.cos(), th.sin(), 0.0),
            half_length: h,
            radius: r,
        };
        let mut out = vec![];
        slot.rod_contacts(&rod, Ends::Flat, 0.0, &mut |c| out.push(c));
        let expect = h * th.sin() + r * th.cos() - w;
        assert!(expect > 0.0);
        assert_eq!(out.len(), 2);
        for c in &out {
            assert!((c.depth - expect).abs() < 1e-15);
        }
        // The upper face (σ = +1) meets the end at s = +h, pushed down.
        assert_eq!((out[0].feature, out[0].normal), (1, -Vector::Y));
        assert_eq!((out[1].feature, out[1].normal), (2, Vector::Y));
    }
}
