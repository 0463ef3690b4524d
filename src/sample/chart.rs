//! Charts: a rectangle of surface parameters (u, v) that covers a face, and the map from
//! parameters to a point on the exact surface with its outward normal.
//!
//! Planes use the face's minimum-area bounding rectangle (u along its long side);
//! cylinders and cones the angle around the axis and the height along it; spheres the
//! longitude and the polar angle from a pole through the face's centroid.

use crate::geometry::{Face, FaceId, PartGeometry, Surface, P3, V3};
use std::f64::consts::{PI, TAU};

/// A face's angular span is the full turn when no gap between its vertices' angles
/// exceeds this (radians).
const FULL_TURN_GAP: f64 = PI / 4.0;

#[derive(Debug, Clone, Copy)]
enum Shape {
    Plane {
        normal: V3,
    },
    Cylinder {
        radius: f64,
        outward: f64,
    },
    Cone {
        tan: f64,
        cos: f64,
        sin: f64,
        outward: f64,
    },
    Sphere {
        radius: f64,
        outward: f64,
    },
}

/// The parameter rectangle of one face.
#[derive(Debug, Clone)]
pub struct Chart {
    shape: Shape,
    origin: P3,
    e1: V3,
    e2: V3,
    e3: V3,
    /// Range of u.
    pub u: (f64, f64),
    /// Range of v.
    pub v: (f64, f64),
    /// u is an angle covering the full turn.
    pub periodic_u: bool,
}

impl Chart {
    /// The chart of a face with an analytic surface; `None` for free-form faces.
    pub fn of(g: &PartGeometry, id: FaceId) -> Option<Chart> {
        let face = &g.faces[id.0];
        let points = face_vertices(g, face);
        if points.is_empty() {
            return None;
        }
        Some(match face.surface {
            Surface::Plane { origin, normal } => plane_chart(origin, normal, &points),
            Surface::Cylinder {
                origin,
                axis,
                radius,
                convex,
            } => {
                let (e1, e2) = perpendicular_basis(&axis);
                let (u, periodic_u) = angle_range(&points, &origin, &e1, &e2);
                let v = range(points.iter().map(|p| (p - origin).dot(&axis)));
                let shape = Shape::Cylinder {
                    radius,
                    outward: sign(convex),
                };
                Chart {
                    shape,
                    origin,
                    e1,
                    e2,
                    e3: axis,
                    u,
                    v,
                    periodic_u,
                }
            }
            Surface::Cone {
                apex,
                axis,
                half_angle,
                convex,
            } => {
                let (e1, e2) = perpendicular_basis(&axis);
                let (u, periodic_u) = angle_range(&points, &apex, &e1, &e2);
                let v = range(points.iter().map(|p| (p - apex).dot(&axis)));
                let shape = Shape::Cone {
                    tan: half_angle.tan(),
                    cos: half_angle.cos(),
                    sin: half_angle.sin(),
                    outward: sign(convex),
                };
                Chart {
                    shape,
                    origin: apex,
                    e1,
                    e2,
                    e3: axis,
                    u,
                    v,
                    periodic_u,
                }
            }
            Surface::Sphere {
                center,
                radius,
                convex,
            } => {
                let pole = (face.centroid - center)
                    .try_normalize(1e-9 * radius.max(1.0))
                    .unwrap_or_else(V3::z);
                let (e1, e2) = perpendicular_basis(&pole);
                let shape = Shape::Sphere {
                    radius,
                    outward: sign(convex),
                };
                let polar = |p: &P3| {
                    ((p - center).normalize().dot(&pole))
                        .clamp(-1.0, 1.0)
                        .acos()
                };
                let mut v = range(points.iter().map(polar));
                let (mut u, mut periodic_u) = angle_range(&points, &center, &e1, &e2);
                if g.face_covers(id, &(center + pole * radius), &pole, radius * 0.5) {
                    // The face wraps its pole: every longitude, from the pole down.
                    v.0 = 0.0;
                    (u, periodic_u) = ((0.0, TAU), true);
                }
                Chart {
                    shape,
                    origin: center,
                    e1,
                    e2,
                    e3: pole,
                    u,
                    v,
                    periodic_u,
                }
            }
            Surface::Freeform => return None,
        })
    }

    /// The point at (u, v) on the exact surface and the outward unit normal there.
    pub fn eval(&self, u: f64, v: f64) -> (P3, V3) {
        let radial = |a: f64| self.e1 * a.cos() + self.e2 * a.sin();
        match self.shape {
            Shape::Plane { normal } => (self.origin + self.e1 * u + self.e2 * v, normal),
            Shape::Cylinder { radius, outward } => {
                let r = radial(u);
                (self.origin + self.e3 * v + r * radius, r * outward)
            }
            Shape::Cone {
                tan,
                cos,
                sin,
                outward,
            } => {
                let r = radial(u);
                (
                    self.origin + self.e3 * v + r * (v * tan),
                    (r * cos - self.e3 * sin) * outward,
                )
            }
            Shape::Sphere { radius, outward } => {
                let d = radial(u) * v.sin() + self.e3 * v.cos();
                (self.origin + d * radius, d * outward)
            }
        }
    }

    /// Millimetres per unit of u and of v, near the middle of the face.
    pub fn scale(&self) -> (f64, f64) {
        let vm = (self.v.0 + self.v.1) / 2.0;
        match self.shape {
            Shape::Plane { .. } => (1.0, 1.0),
            Shape::Cylinder { radius, .. } => (radius, 1.0),
            Shape::Cone { tan, cos, .. } => ((vm * tan).abs().max(1e-9), 1.0 / cos),
            Shape::Sphere { radius, .. } => ((radius * vm.sin()).max(1e-9 * radius), radius),
        }
    }

    /// The face's extent along u and v (mm).
    pub(crate) fn extent_mm(&self) -> (f64, f64) {
        let (su, sv) = self.scale();
        ((self.u.1 - self.u.0) * su, (self.v.1 - self.v.0) * sv)
    }

    /// Maps t ∈ [0, 1] to v so that equal steps of t cover equal areas (cones and
    /// spheres grow with v); linear otherwise.
    pub(crate) fn v_by_area(&self, t: f64) -> f64 {
        let (a, b) = self.v;
        match self.shape {
            Shape::Cone { .. } if a >= 0.0 => (a * a + t * (b * b - a * a)).sqrt(),
            Shape::Sphere { .. } => {
                let (ca, cb) = (a.cos(), b.cos());
                (ca - t * (ca - cb)).clamp(-1.0, 1.0).acos()
            }
            _ => a + t * (b - a),
        }
    }

    /// The largest distance from the surface to the face's triangles worth accepting as
    /// "on the face" (mm): generous for chordal error, below anything that could reach
    /// the other side of a curved surface.
    pub(crate) fn cover_tolerance(&self) -> f64 {
        match self.shape {
            Shape::Plane { .. } => 1.0,
            Shape::Cylinder { radius, .. } | Shape::Sphere { radius, .. } => {
                (radius * 0.25).min(1.0)
            }
            Shape::Cone { tan, .. } => {
                (self.v.0.abs().min(self.v.1.abs()) * tan.abs() * 0.25).clamp(1e-3, 1.0)
            }
        }
    }
}

fn sign(convex: bool) -> f64 {
    if convex {
        1.0
    } else {
        -1.0
    }
}

/// The distinct vertices of a face, in first-use order.
fn face_vertices(g: &PartGeometry, face: &Face) -> Vec<P3> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for &t in &face.triangles {
        for &i in &g.triangles[t as usize] {
            if seen.insert(i) {
                out.push(g.vertices[i as usize]);
            }
        }
    }
    out
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    })
}

/// Two unit vectors completing `axis` to a right-handed frame, chosen the same way for
/// the same axis: e1 is the world axis least aligned with `axis`, made perpendicular.
pub fn perpendicular_basis(axis: &V3) -> (V3, V3) {
    let a = axis.map(f64::abs);
    let w = if a.x <= a.y && a.x <= a.z {
        V3::x()
    } else if a.y <= a.z {
        V3::y()
    } else {
        V3::z()
    };
    let e1 = (w - axis * w.dot(axis)).normalize();
    (e1, axis.cross(&e1))
}

/// The angular span of points around an axis: from the end of the largest gap between
/// their angles round to its start; the full turn when no gap is large.
fn angle_range(points: &[P3], origin: &P3, e1: &V3, e2: &V3) -> ((f64, f64), bool) {
    let mut angles: Vec<f64> = points
        .iter()
        .filter_map(|p| {
            let d = p - origin;
            let (x, y) = (d.dot(e1), d.dot(e2));
            (x.hypot(y) > 1e-9).then(|| y.atan2(x))
        })
        .collect();
    if angles.len() < 2 {
        return ((0.0, TAU), true);
    }
    angles.sort_by(f64::total_cmp);
    let mut gap = (angles[0] + TAU - angles[angles.len() - 1], angles[0]);
    for w in angles.windows(2) {
        if w[1] - w[0] > gap.0 {
            gap = (w[1] - w[0], w[1]);
        }
    }
    if gap.0 < FULL_TURN_GAP {
        ((0.0, TAU), true)
    } else {
        ((gap.1, gap.1 + TAU - gap.0), false)
    }
}

/// A plane's chart: the minimum-area rectangle around the face's vertices (rotating
/// calipers over their convex hull), u along its longer side.
fn plane_chart(origin: P3, normal: V3, points: &[P3]) -> Chart {
    let (b1, b2) = perpendicular_basis(&normal);
    let flat: Vec<(f64, f64)> = points
        .iter()
        .map(|p| ((p - origin).dot(&b1), (p - origin).dot(&b2)))
        .collect();
    let hull = convex_hull(flat);
    let mut best: Option<(f64, f64, f64)> = None; // (area, cos, sin)
    for k in 0..hull.len() {
        let (a, b) = (hull[k], hull[(k + 1) % hull.len()]);
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        if len < 1e-12 {
            continue;
        }
        let (c, s) = ((b.0 - a.0) / len, (b.1 - a.1) / len);
        let us = range(hull.iter().map(|p| p.0 * c + p.1 * s));
        let vs = range(hull.iter().map(|p| -p.0 * s + p.1 * c));
        let area = (us.1 - us.0) * (vs.1 - vs.0);
        if best.is_none_or(|(a0, _, _)| area < a0 * (1.0 - 1e-9)) {
            best = Some((area, c, s));
        }
    }
    let (_, c, s) = best.unwrap_or((0.0, 1.0, 0.0));
    let (mut e1, mut e2) = (b1 * c + b2 * s, -b1 * s + b2 * c);
    let extent = |e: &V3| {
        let r = range(points.iter().map(|p| (p - origin).dot(e)));
        r.1 - r.0
    };
    if extent(&e2) > extent(&e1) * (1.0 + 1e-9) {
        std::mem::swap(&mut e1, &mut e2);
    }
    // A stable sense: the largest component of e1 positive.
    let i = e1.iamax();
    if e1[i] < 0.0 {
        e1 = -e1;
    }
    e2 = normal.cross(&e1);
    let u = range(points.iter().map(|p| (p - origin).dot(&e1)));
    let v = range(points.iter().map(|p| (p - origin).dot(&e2)));
    Chart {
        shape: Shape::Plane { normal },
        origin,
        e1,
        e2,
        e3: normal,
        u,
        v,
        periodic_u: false,
    }
}

/// Andrew's monotone chain; counter-clockwise, without collinear points.
pub(crate) fn convex_hull(mut pts: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(pts.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let h = convex_hull(vec![
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 1.0),
            (0.0, 1.0),
            (0.5, 0.5),
            (0.5, 0.0),
        ]);
        assert_eq!(h, vec![(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]);
    }

    #[test]
    fn angle_range_finds_the_gap() {
        let o = P3::origin();
        let pts: Vec<P3> = (0..=8)
            .map(|k| {
                let a = PI * k as f64 / 8.0;
                P3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let ((a, b), full) = angle_range(&pts, &o, &V3::x(), &V3::y());
        assert!(!full);
        assert!((a - 0.0).abs() < 1e-9 && (b - PI).abs() < 1e-9, "{a} {b}");
    }
}
