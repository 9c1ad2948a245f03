//! parry's point projection and ray casting for the container shapes.
//!
//! The solid of each shape is what surrounds its lumen, so a point in the
//! lumen is *outside* the shape (`is_inside = false`) and projects onto the
//! wall; a point in the wall is inside. Normals of ray hits follow parry's
//! convention: the solid's outward normal (into the lumen) for a ray from
//! the lumen, its opposite for a ray that starts in the solid.
//!
//! Ray casts are closed forms for the slot (planes) and the cavity (a
//! quadratic). For the tube and the groove flank (a torus: a quartic) the ray
//! is marched by the exact distance to the wall (sphere tracing, never past
//! the wall), then bracketed and bisected to 1e-12 m + 1e-12·R: exact to
//! that tolerance, at tens of nearest-point queries for most rays.

use parry3d_f64::math::{Real, Vector};
use parry3d_f64::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d_f64::shape::FeatureId;

use crate::cavity::SphericalCavity;
use crate::centreline::Centreline;
use crate::contact::{perpendicular, unit};
use crate::groove::GrooveFlank;
use crate::slot::WindowSlot;
use crate::tube::TubeInterior;

/// Projection of `pt` onto a wall at `radius` from the centreline point `c`
/// (unit `tangent` there).
fn radial_projection(
    pt: Vector,
    c: Vector,
    tangent: Vector,
    radius: f64,
    solid: bool,
) -> PointProjection {
    let r = pt - c;
    let d = r.length();
    let dir = if d > 1e-15 {
        r / d
    } else {
        perpendicular(tangent)
    };
    let inside = d >= radius;
    if inside && solid {
        PointProjection::new(true, pt)
    } else {
        PointProjection::new(inside, c + radius * dir)
    }
}

impl TubeInterior {
    /// Projection of a point past an open end (outside the solid) onto the
    /// solid: onto the end plane, pushed out to the inner radius.
    fn project_past_end(&self, pt: Vector) -> PointProjection {
        let [a, b] = self.ends();
        let beyond = |(e, out): (Vector, Vector)| (pt - e).dot(out);
        let (e, out) = if beyond(a) >= beyond(b) { a } else { b };
        let on_plane = pt - beyond((e, out)) * out;
        let rho = on_plane - e;
        let d = rho.length();
        let point = if d >= self.inner_radius() {
            on_plane
        } else {
            let dir = if d > 1e-15 {
                rho / d
            } else {
                perpendicular(out)
            };
            e + self.inner_radius() * dir
        };
        PointProjection::new(false, point)
    }
}

impl PointQuery for TubeInterior {
    fn project_local_point(&self, pt: Vector, solid: bool) -> PointProjection {
        self.project_local_point_and_get_feature(pt)
            .0
            .solid_at(pt, solid)
    }

    fn project_local_point_and_get_feature(&self, pt: Vector) -> (PointProjection, FeatureId) {
        match self.nearest(pt) {
            Some(c) => (
                radial_projection(pt, c.point, c.tangent, self.inner_radius(), false),
                FeatureId::Face(self.nearest_segment(pt).unwrap_or(0) as u32),
            ),
            None => (self.project_past_end(pt), FeatureId::Unknown),
        }
    }
}

impl PointQuery for GrooveFlank {
    fn project_local_point(&self, pt: Vector, solid: bool) -> PointProjection {
        self.project_local_point_and_get_feature(pt)
            .0
            .solid_at(pt, solid)
    }

    fn project_local_point_and_get_feature(&self, pt: Vector) -> (PointProjection, FeatureId) {
        // On the race's axis every core point is as near: take one.
        let c = Centreline::nearest(self, pt).unwrap_or_else(|| {
            let dir = perpendicular(self.axis);
            crate::centreline::CentrelinePoint {
                point: self.centre + self.core_radius * dir,
                tangent: self.axis.cross(dir),
                curvature: -dir / self.core_radius,
            }
        });
        (
            radial_projection(pt, c.point, c.tangent, self.tube_radius, false),
            FeatureId::Face(0),
        )
    }
}

impl PointQuery for WindowSlot {
    fn project_local_point(&self, pt: Vector, solid: bool) -> PointProjection {
        self.project_local_point_and_get_feature(pt)
            .0
            .solid_at(pt, solid)
    }

    fn project_local_point_and_get_feature(&self, pt: Vector) -> (PointProjection, FeatureId) {
        let u = self.height(pt);
        let side = if u >= 0.0 { 1.0 } else { -1.0 };
        let projection = PointProjection::new(
            u.abs() >= self.half_width,
            pt + (side * self.half_width - u) * self.normal,
        );
        (projection, FeatureId::Face(if u >= 0.0 { 0 } else { 1 }))
    }
}

impl PointQuery for SphericalCavity {
    fn project_local_point(&self, pt: Vector, solid: bool) -> PointProjection {
        self.project_local_point_and_get_feature(pt)
            .0
            .solid_at(pt, solid)
    }

    fn project_local_point_and_get_feature(&self, pt: Vector) -> (PointProjection, FeatureId) {
        (
            radial_projection(pt, self.centre, Vector::Z, self.radius, false),
            FeatureId::Face(0),
        )
    }
}

/// The `solid` variant of a boundary projection: a point inside the solid
/// is its own projection.
trait SolidAt {
    fn solid_at(self, pt: Vector, solid: bool) -> PointProjection;
}

impl SolidAt for PointProjection {
    fn solid_at(self, pt: Vector, solid: bool) -> PointProjection {
        if solid && self.is_inside {
            PointProjection::new(true, pt)
        } else {
            self
        }
    }
}

/// Largest number of marching steps of a ray through a lumen.
const MAX_STEPS: usize = 10_000;

/// A ray against the wall of a lumen around a centreline: marched by the
/// distance to the wall, which never steps past it (steps of at least
/// 1e-4·R, so a grazing ray still advances; a crossing is then bracketed and
/// bisected). `None` past an open end or beyond `max_toi`.
fn march<L: Centreline>(
    lumen: &L,
    ray: &Ray,
    max_toi: Real,
    solid: bool,
) -> Option<RayIntersection> {
    let speed = ray.dir.length();
    let radius = lumen.wall_radius();
    // Signed distance to the wall at time t: positive on the ray's side.
    let wall = |t: f64| -> Option<(f64, Vector)> {
        let q = ray.origin + t * ray.dir;
        let r = q - lumen.nearest(q)?.point;
        Some((radius - r.length(), r))
    };
    let (d0, r0) = wall(0.0)?;
    let in_solid = d0 <= 0.0;
    if in_solid && solid {
        return Some(RayIntersection::new(0.0, unit(r0), FeatureId::Face(0)));
    }
    if speed == 0.0 {
        return None;
    }
    let sign = if in_solid { -1.0 } else { 1.0 };
    let tolerance = 1e-12 * (1.0 + radius);
    let hit = |t: f64, r: Vector| {
        let n = unit(r);
        Some(RayIntersection::new(
            t,
            if in_solid { n } else { -n },
            FeatureId::Face(0),
        ))
    };
    let (mut t0, mut t) = (0.0, 0.0);
    for _ in 0..MAX_STEPS {
        let (d, r) = wall(t)?;
        let d = sign * d;
        if d.abs() <= tolerance {
            return (t <= max_toi).then(|| hit(t, r)).flatten();
        }
        if d < 0.0 {
            // Crossed between t0 (on the ray's side) and t: bisect.
            let (mut lo, mut hi) = (t0, t);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                let (dm, _) = wall(mid)?;
                if sign * dm > 0.0 {
                    lo = mid
                } else {
                    hi = mid
                }
                if (hi - lo) * speed <= tolerance {
                    break;
                }
            }
            let (_, r) = wall(hi)?;
            return (hi <= max_toi).then(|| hit(hi, r)).flatten();
        }
        t0 = t;
        t += d.max(1e-4 * radius) / speed;
        if t > max_toi {
            return None;
        }
    }
    None
}

impl RayCast for TubeInterior {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_toi: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        march(self, ray, max_toi, solid)
    }
}

impl RayCast for GrooveFlank {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_toi: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        march(self, ray, max_toi, solid)
    }
}

impl RayCast for WindowSlot {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_toi: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        let (u, v) = (self.height(ray.origin), ray.dir.dot(self.normal));
        let w = self.half_width;
        let n = self.normal;
        let (t, normal, face) = if u.abs() < w {
            // From the gap to the face it moves toward.
            match v {
                v if v > 0.0 => ((w - u) / v, -n, 0),
                v if v < 0.0 => ((-w - u) / v, n, 1),
                _ => return None,
            }
        } else if solid {
            (
                0.0,
                if u >= 0.0 { n } else { -n },
                if u >= 0.0 { 0 } else { 1 },
            )
        } else if u >= w && v < 0.0 {
            ((w - u) / v, n, 0)
        } else if u <= -w && v > 0.0 {
            ((-w - u) / v, -n, 1)
        } else {
            return None;
        };
        (t <= max_toi).then(|| RayIntersection::new(t, normal, FeatureId::Face(face)))
    }
}

impl RayCast for SphericalCavity {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_toi: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        // |o + t·d − O|² = R²: a t² + 2b t + c = 0.
        let o = ray.origin - self.centre;
        let (a, b, c) = (
            ray.dir.length_squared(),
            o.dot(ray.dir),
            o.length_squared() - self.radius * self.radius,
        );
        let at = |t: f64| unit(o + t * ray.dir);
        let (t, normal) = if c < 0.0 {
            // From the lumen: the far root, where the ray leaves the ball.
            if a == 0.0 {
                return None;
            }
            let t = (-b + (b * b - a * c).sqrt()) / a;
            (t, -at(t))
        } else if solid {
            (0.0, at(0.0))
        } else {
            // From the solid: where the ray enters the ball, if ahead.
            let disc = b * b - a * c;
            if a == 0.0 || disc < 0.0 || b >= 0.0 {
                return None;
            }
            let t = (-b - disc.sqrt()) / a;
            (t, at(t))
        };
        (t <= max_toi).then(|| RayIntersection::new(t, normal, FeatureId::Face(0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tube::tests::paper_tube;

    /// A point of the lumen projects radially onto the wall; a point of
    /// the wall is inside the solid.
    #[test]
    fn lumen_points_project_radially_onto_the_wall() {
        let t = paper_tube();
        let a = 30f64.to_radians();
        let c = Vector::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
        let p = t.project_local_point(c + 0.02 * Vector::Y, true);
        assert!(!p.is_inside);
        assert!((p.point - (c + 0.058 * Vector::Y)).length() < 1e-12);
        assert!((t.distance_to_local_point(c + 0.02 * Vector::Y, true) - 0.038).abs() < 1e-12);
        let q = c + 0.06 * Vector::Y;
        assert!(t.project_local_point(q, false).is_inside);
        assert_eq!(t.project_local_point(q, true).point, q);
        // Past the start (above z = 0), the solid is the end plane's annulus.
        let p = t.project_local_point(Vector::new(0.01, 0.0, 0.1), false);
        assert!((p.point - Vector::new(0.058, 0.0, 0.0)).length() < 1e-12);
    }

    /// A ray along +y from the centreline of the paper's arc meets the wall
    /// at t = R (the wall is R from the centreline off the bend plane); a
    /// ray along the outward radial meets it at R too.
    #[test]
    fn rays_from_the_centreline_meet_the_wall_at_the_radius() {
        let t = paper_tube();
        let a = 40f64.to_radians();
        let c = Vector::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
        let outward = Vector::new(-a.cos(), 0.0, -a.sin());
        for dir in [Vector::Y, outward, unit(Vector::Y + outward)] {
            let hit = t
                .cast_local_ray_and_get_normal(&Ray::new(c, dir), 1.0, true)
                .expect("a hit");
            assert!(
                (hit.time_of_impact - 0.058).abs() < 1e-11,
                "{}",
                hit.time_of_impact
            );
            assert!((hit.normal + dir).length() < 1e-9);
        }
    }

    #[test]
    fn rays_leave_a_cavity_and_a_slot_at_their_walls() {
        let cav = SphericalCavity::new(Vector::new(0.0, 0.0, 1.0), 0.5);
        let hit = cav
            .cast_local_ray_and_get_normal(
                &Ray::new(Vector::new(0.3, 0.0, 1.0), Vector::X),
                10.0,
                true,
            )
            .expect("a hit");
        assert!((hit.time_of_impact - 0.2).abs() < 1e-15);
        assert_eq!(hit.normal, -Vector::X);
        let slot = WindowSlot::new(Vector::ZERO, Vector::Y, 0.1);
        let hit = slot
            .cast_local_ray_and_get_normal(
                &Ray::new(Vector::new(0.0, 0.05, 0.0), -2.0 * Vector::Y),
                1.0,
                true,
            )
            .expect("a hit");
        assert!((hit.time_of_impact - 0.075).abs() < 1e-15);
        assert_eq!(hit.normal, Vector::Y);
    }
}
