//! Swept and offset surfaces read as the analytic surfaces they are.
//!
//! Exporters write the same cylinder as a `CYLINDRICAL_SURFACE` (most), a circle swept
//! along its normal (CATIA V5's `SURFACE_OF_LINEAR_EXTRUSION`) or a line revolved about
//! a parallel axis; a part's features (a bore's diameter, a datum plane) must not
//! depend on which. OpenCASCADE recognises the same cases when it reads such a surface
//! (`GeomAdaptor_Surface` reports the basis's kind; `ShapeCustom`/`GeomConvert` turn
//! them analytic); the rules here are the geometry of ISO 10303-42's definitions:
//! - a line swept along any other direction is a plane; a circle swept along its own
//!   normal is a cylinder;
//! - a line revolved is a cylinder (parallel to the axis and in a plane with it), a
//!   plane (square to the axis) or a cone (crossing or meeting the axis in a plane with
//!   it); a circle in a plane through the axis revolved is a sphere (centred on the
//!   axis) or a torus;
//! - an offset plane, cylinder, cone, sphere or torus is one of the same kind;
//! - a B-spline surface whose control points lie on one plane is that plane: a point of
//!   a (rational, positive-weight) B-spline is a convex combination of its control
//!   points (ISO 10303-42 `b_spline_surface`), so it never leaves their plane. This is
//!   the test OpenCASCADE's `GeomLib_IsPlanarSurface` makes on the poles; files whose
//!   every surface is a B-spline (a part put through a NURBS conversion, some
//!   exporters' "NURBS only" option) keep their planes, and the datums and defaults that
//!   need them.
//!
//! The analytic surface's natural normal may point the other way from the swept one's
//! (a circle swept along −z gives the inward normal; a revolved half-circle's depends
//! on its side of the axis), so the face's sense is compared at its own points and
//! flipped where they disagree.

use super::curve::{Curve, Frame};
use super::geom::{BSplineSurface, Offset, Surf};
use super::swept::{Extrusion, Revolution};
use crate::geometry::{P3, V3};

/// How far from parallel, square or coplanar a direction may be and still count
/// (radians, or millimetres per millimetre).
const ANGLE_EPS: f64 = 1e-7;
/// How far from the axis a point may be and still be on it (mm).
const ON_AXIS_MM: f64 = 1e-7;

/// The analytic surface `s` is, if it is one, and whether a face on it must flip its
/// sense to keep its outward normal (judged at `points`, points of the face).
pub(crate) fn canonical(s: &Surf, points: &[P3]) -> (Surf, bool) {
    let analytic = match s {
        Surf::Extrusion(e) => extrusion(e),
        Surf::Revolution(r) => revolution(r, points),
        Surf::Offset(o) => offset(o),
        Surf::BSpline(b) => planar(b),
        _ => None,
    };
    let Some(a) = analytic else {
        return (s.clone(), false);
    };
    (a.clone(), flipped(s, &a, points))
}

/// Whether the natural normals of `swept` and `analytic` are opposite at the first of
/// `points` where both are defined.
fn flipped(swept: &Surf, analytic: &Surf, points: &[P3]) -> bool {
    for p in points {
        let (u, v) = swept.param(p, None);
        let (a, b) = analytic.param(p, None);
        if let (Some(n), Some(m)) = (
            swept.normal(&swept.eval(u, v), u, v),
            analytic.normal(p, a, b),
        ) {
            return n.dot(&m) < 0.0;
        }
    }
    false
}

fn extrusion(e: &Extrusion) -> Option<Surf> {
    let d = e.dir;
    match &e.curve {
        Curve::Line(o, t) => {
            let n = t.cross(&d).try_normalize(ANGLE_EPS)?;
            Some(Surf::Plane(Frame::new(*o, Some(n), Some(*t))?))
        }
        Curve::Circle(f, r) if f.z.cross(&d).norm() < ANGLE_EPS => Some(Surf::Cylinder(*f, *r)),
        _ => None,
    }
}

fn revolution(r: &Revolution, points: &[P3]) -> Option<Surf> {
    let axis = &r.axis;
    let foot = |p: &P3| axis.o + axis.z * (p - axis.o).dot(&axis.z);
    match &r.curve {
        Curve::Line(o, t) => {
            let e = t.try_normalize(1e-300)?;
            let q = foot(o);
            let w = o - q;
            // The line must lie in a plane with the axis (else a hyperboloid).
            if w.norm() > ON_AXIS_MM && e.dot(&axis.z.cross(&w.normalize())).abs() > ANGLE_EPS {
                return None;
            }
            let along = e.dot(&axis.z);
            let radial = (e - axis.z * along).try_normalize(ANGLE_EPS);
            match radial {
                None => {
                    let x = w.try_normalize(ON_AXIS_MM)?;
                    Some(Surf::Cylinder(
                        Frame::new(q, Some(axis.z), Some(x))?,
                        w.norm(),
                    ))
                }
                Some(x) if along.abs() < ANGLE_EPS => {
                    Some(Surf::Plane(Frame::new(q, Some(axis.z), Some(x))?))
                }
                Some(x) => {
                    // A line crossing the axis sweeps two nappes about its apex; the
                    // face lies on one, told by its own points (ISO 10303-42 lets the
                    // line's point lie anywhere on it, either side of the apex).
                    let apex = o + e * (-w.dot(&x) / e.dot(&x));
                    let side = points
                        .iter()
                        .chain([o, &(o + e)])
                        .map(|p| (p - apex).dot(&axis.z))
                        .find(|h| h.abs() > ON_AXIS_MM)?;
                    let z = axis.z * side.signum();
                    let semi = (e.dot(&x).abs() / along.abs()).atan();
                    Some(Surf::Cone(Frame::new(apex, Some(z), Some(x))?, 0.0, semi))
                }
            }
        }
        Curve::Circle(f, radius) => {
            // The circle's plane must hold the axis.
            if f.z.dot(&axis.z).abs() > ANGLE_EPS || (f.o - axis.o).dot(&f.z).abs() > ON_AXIS_MM {
                return None;
            }
            let q = foot(&f.o);
            let w = f.o - q;
            if w.norm() < ON_AXIS_MM {
                Some(Surf::Sphere(
                    Frame::new(q, Some(axis.z), Some(axis.x))?,
                    *radius,
                ))
            } else {
                let x = w.normalize();
                Some(Surf::Torus(
                    Frame::new(q, Some(axis.z), Some(x))?,
                    w.norm(),
                    *radius,
                ))
            }
        }
        _ => None,
    }
}

fn offset(o: &Offset) -> Option<Surf> {
    let d = o.distance;
    let grown = |r: f64| (r + d > 0.0).then_some(r + d);
    match &o.base {
        Surf::Plane(f) => Some(Surf::Plane(Frame {
            o: f.o + f.z * d,
            ..*f
        })),
        Surf::Cylinder(f, r) => Some(Surf::Cylinder(*f, grown(*r)?)),
        // The normal leans back by the semi-angle: the radius at the origin grows by
        // d / cos(semi-angle).
        Surf::Cone(f, r, a) => {
            // The radius at the frame's origin may come out negative: move the origin
            // along the axis to the apex's side where it is 0 or more.
            let r2 = r + d / a.cos();
            if r2 >= 0.0 {
                Some(Surf::Cone(*f, r2, *a))
            } else {
                let shift = -r2 / a.tan();
                Some(Surf::Cone(
                    Frame {
                        o: f.o + f.z * shift,
                        ..*f
                    },
                    0.0,
                    *a,
                ))
            }
        }
        Surf::Sphere(f, r) => Some(Surf::Sphere(*f, grown(*r)?)),
        Surf::Torus(f, big, small) => Some(Surf::Torus(*f, *big, grown(*small)?)),
        _ => None,
    }
}

/// How far a B-spline's control point may lie off the plane of the others (mm) and the
/// surface still be that plane: far below any tolerance a part is drawn to, above the
/// rounding of 15-digit coordinates on a part a few metres across.
const ON_PLANE_MM: f64 = 1e-6;

/// The plane a B-spline surface is, if its control points lie on one, its normal the
/// surface's own (∂S/∂u × ∂S/∂v where that is defined), so no face on it flips.
fn planar(b: &BSplineSurface) -> Option<Surf> {
    let s = Surf::BSpline(std::sync::Arc::new(b.clone()));
    let (u0, u1) = b.u.range();
    let (v0, v1) = b.v.range();
    // The natural normal at the first of a few parameters where it is defined (a
    // degenerate edge has none).
    let normal = [
        (0.5, 0.5),
        (0.25, 0.25),
        (0.75, 0.75),
        (0.25, 0.75),
        (0.75, 0.25),
    ]
    .iter()
    .find_map(|(a, c)| {
        let (u, v) = (u0 + a * (u1 - u0), v0 + c * (v1 - v0));
        s.normal(&s.eval(u, v), u, v)
    })?;
    let poles: Vec<&P3> = b.points.iter().flatten().collect();
    let n = poles.len() as f64;
    let centre = P3::from(poles.iter().fold(V3::zeros(), |a, p| a + p.coords) / n);
    if poles
        .iter()
        .any(|p| (*p - centre).dot(&normal).abs() > ON_PLANE_MM)
    {
        return None;
    }
    Frame::new(centre, Some(normal), None).map(Surf::Plane)
}

/// The frame of a revolution's axis with x pointing at the profile, so that the
/// profile lies at angle 0.
pub(crate) fn revolution_axis(origin: P3, axis: V3, curve: &Curve) -> Option<Frame> {
    let (a, b) = curve.range();
    let mid = 0.5 * (a.max(-1e3) + b.min(1e3));
    let samples = [mid, a.max(-1e3), b.min(1e3), 0.0];
    let z = axis.try_normalize(ANGLE_EPS)?;
    let x = samples.iter().find_map(|&t| {
        let d = curve.eval(t) - origin;
        (d - z * d.dot(&z)).try_normalize(ON_AXIS_MM)
    });
    Frame::new(origin, Some(z), x)
}
