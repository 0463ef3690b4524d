//! The exact surfaces of a STEP B-rep (its curves are `curve.rs`'s): evaluation, and the
//! inverse map from a point to its parameters, which tessellation triangulates in.
//!
//! Every surface is parametrised so that `S_u × S_v` points along STEP's natural normal
//! (away from a cylinder's, cone's, sphere's or torus's axis or centre); angles are
//! radians, lengths millimetres.

use super::curve::{Frame, Knots};
use super::swept::{Extrusion, Revolution, Ruled};
use crate::geometry::{P3, V3};
use std::f64::consts::{FRAC_PI_2, TAU};
use std::sync::Arc;

/// A B-spline surface.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BSplineSurface {
    /// Knots along u (the first index of `points`).
    pub u: Knots,
    /// Knots along v.
    pub v: Knots,
    /// Control points, `points[i][j]` for u index i, v index j.
    pub points: Vec<Vec<P3>>,
    /// Weights, shaped as `points`.
    pub weights: Vec<Vec<f64>>,
    /// Whether the surface closes on itself along u and along v (a revolved profile).
    pub closed: [bool; 2],
}

impl BSplineSurface {
    /// The ends of v where the surface closes to a point (a revolved profile that
    /// reaches its axis, a sphere made a B-spline): u is undefined there.
    pub(crate) fn poles(&self) -> Vec<f64> {
        let (u0, u1) = self.u.range();
        let (v0, v1) = self.v.range();
        [v0, v1]
            .into_iter()
            .filter(|&v| {
                let first = self.eval(u0, v);
                (1..8).all(|k| {
                    let u = u0 + (u1 - u0) * k as f64 / 8.0;
                    (self.eval(u, v) - first).norm() < 1e-7
                })
            })
            .collect()
    }

    /// The point at `(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> P3 {
        let wrap = |t: f64, k: &Knots, closed: bool| {
            let (a, b) = k.range();
            if closed {
                a + (t - a).rem_euclid(b - a)
            } else {
                t
            }
        };
        let (fu, nu) = self.u.basis(wrap(u, &self.u, self.closed[0]));
        let (fv, nv) = self.v.basis(wrap(v, &self.v, self.closed[1]));
        let mut sum = V3::zeros();
        let mut w = 0.0;
        for (a, bu) in nu[..=self.u.degree].iter().enumerate() {
            for (b, bv) in nv[..=self.v.degree].iter().enumerate() {
                let (i, j) = (fu + a, fv + b);
                let k = bu * bv * self.weights[i][j];
                sum += self.points[i][j].coords * k;
                w += k;
            }
        }
        P3::from(sum / w)
    }
}

/// A face's surface.
#[derive(Debug, Clone, PartialEq)]
pub enum Surf {
    /// A plane through the frame's origin with normal z.
    Plane(Frame),
    /// A cylinder of this radius about the frame's z axis.
    Cylinder(Frame, f64),
    /// A cone: radius at the origin, semi-angle (radians), opening along z.
    Cone(Frame, f64, f64),
    /// A sphere about the origin.
    Sphere(Frame, f64),
    /// A torus about z: major and minor radius.
    Torus(Frame, f64, f64),
    /// A B-spline surface (shared: every face on it holds the one read).
    BSpline(Arc<BSplineSurface>),
    /// A curve swept along a vector (one not read as a plane or cylinder).
    Extrusion(Arc<Extrusion>),
    /// A curve revolved about an axis (one not read as an analytic surface).
    Revolution(Arc<Revolution>),
    /// A surface grown along its normal (one not read as an analytic surface).
    Offset(Arc<Offset>),
    /// A surface ruled between two curves (QIF's `Ruled23`).
    Ruled(Arc<Ruled>),
}

impl Surf {
    /// The point at `(u, v)`.
    pub fn eval(&self, u: f64, v: f64) -> P3 {
        match self {
            Surf::Plane(f) => f.at(u, v, 0.0),
            Surf::Cylinder(f, r) => f.at(r * u.cos(), r * u.sin(), v),
            Surf::Cone(f, r, a) => {
                let rr = r + v * a.tan();
                f.at(rr * u.cos(), rr * u.sin(), v)
            }
            Surf::Sphere(f, r) => f.at(r * v.cos() * u.cos(), r * v.cos() * u.sin(), r * v.sin()),
            Surf::Torus(f, big, small) => {
                let rr = big + small * v.cos();
                f.at(rr * u.cos(), rr * u.sin(), small * v.sin())
            }
            Surf::BSpline(s) => s.eval(u, v),
            Surf::Extrusion(e) => e.eval(u, v),
            Surf::Revolution(r) => r.eval(u, v),
            Surf::Offset(o) => o.eval(u, v),
            Surf::Ruled(r) => r.eval(u, v),
        }
    }

    /// Whether the surface's inverse is a search that a nearby parameter pair speeds up
    /// (tessellation passes each bound point's as the next one's hint).
    pub(crate) fn takes_hint(&self) -> bool {
        match self {
            Surf::BSpline(_) | Surf::Extrusion(_) | Surf::Revolution(_) | Surf::Ruled(_) => true,
            Surf::Offset(o) => o.base.takes_hint(),
            _ => false,
        }
    }

    /// The parameters of `p` (on or near the surface); angles in (-π, π]. For a
    /// B-spline, `hint` (a nearby parameter pair) starts the search when given.
    pub fn param(&self, p: &P3, hint: Option<(f64, f64)>) -> (f64, f64) {
        match self {
            Surf::Plane(f) => {
                let l = f.local(p);
                (l.x, l.y)
            }
            Surf::Cylinder(f, _) | Surf::Cone(f, _, _) => {
                let l = f.local(p);
                (l.y.atan2(l.x), l.z)
            }
            Surf::Sphere(f, _) => {
                let l = f.local(p);
                let rho = (l.x * l.x + l.y * l.y).sqrt();
                (l.y.atan2(l.x), l.z.atan2(rho))
            }
            Surf::Torus(f, big, _) => {
                let l = f.local(p);
                let rho = (l.x * l.x + l.y * l.y).sqrt();
                (l.y.atan2(l.x), l.z.atan2(rho - big))
            }
            Surf::BSpline(s) => bspline_param(s, p, hint),
            Surf::Extrusion(e) => e.param(p, hint.map(|h| h.0)),
            Surf::Revolution(r) => r.param(p, hint.map(|h| h.1)),
            Surf::Offset(o) => o.base.param(p, hint),
            Surf::Ruled(r) => {
                let patch = Patch {
                    eval: &|u, v| r.eval(u, v),
                    u: (0.0, 1.0),
                    v: (0.0, 1.0),
                    closed: [r.closed, false],
                };
                patch_param(&patch, p, hint)
            }
        }
    }

    /// The distance from `p` to the surface; `hint` (parameters near the foot) starts a
    /// B-spline's search.
    pub fn distance(&self, p: &P3, hint: (f64, f64)) -> f64 {
        let local = |f: &Frame| f.local(p);
        match self {
            Surf::Plane(f) => local(f).z.abs(),
            Surf::Cylinder(f, r) => {
                let l = local(f);
                ((l.x * l.x + l.y * l.y).sqrt() - r).abs()
            }
            Surf::Cone(f, r, a) => {
                let l = local(f);
                let rho = (l.x * l.x + l.y * l.y).sqrt();
                ((rho - r - l.z * a.tan()) * a.cos()).abs()
            }
            Surf::Sphere(f, r) => (local(f).norm() - r).abs(),
            Surf::Torus(f, big, small) => {
                let l = local(f);
                let rho = (l.x * l.x + l.y * l.y).sqrt();
                ((rho - big).hypot(l.z) - small).abs()
            }
            Surf::BSpline(_)
            | Surf::Extrusion(_)
            | Surf::Revolution(_)
            | Surf::Offset(_)
            | Surf::Ruled(_) => {
                let (u, v) = self.param(p, Some(hint));
                (self.eval(u, v) - p).norm()
            }
        }
    }

    /// The period of u (an angle), if it has one.
    pub(crate) fn u_period(&self) -> Option<f64> {
        match self {
            Surf::Plane(_) => None,
            Surf::BSpline(s) => s.closed[0].then(|| s.u.range().1 - s.u.range().0),
            Surf::Extrusion(e) => e.curve.period(),
            Surf::Offset(o) => o.base.u_period(),
            Surf::Ruled(r) => r.closed.then_some(1.0),
            _ => Some(TAU),
        }
    }

    /// The period of v: a torus's tube angle.
    pub(crate) fn v_period(&self) -> Option<f64> {
        match self {
            Surf::Torus(..) => Some(TAU),
            Surf::BSpline(s) => s.closed[1].then(|| s.v.range().1 - s.v.range().0),
            Surf::Revolution(r) => r.curve.period(),
            Surf::Offset(o) => o.base.v_period(),
            _ => None,
        }
    }

    /// The values of v where u is undefined: a sphere's poles, a cone's apex.
    pub(crate) fn poles(&self) -> Vec<f64> {
        match self {
            Surf::Sphere(..) => vec![-FRAC_PI_2, FRAC_PI_2],
            Surf::Cone(_, r, a) => vec![-r / a.tan()],
            Surf::BSpline(s) => s.poles(),
            Surf::Revolution(r) => r.poles(),
            Surf::Offset(o) => o.base.poles(),
            _ => vec![],
        }
    }

    /// Whether `v` is at a pole (where u is undefined).
    pub(crate) fn at_pole(&self, p: &P3, v: f64) -> bool {
        match self {
            Surf::Sphere(_, r) => (FRAC_PI_2 - v.abs()) * r < 1e-7,
            Surf::Cone(f, ..) => {
                let l = f.local(p);
                (l.x * l.x + l.y * l.y).sqrt() < 1e-7
            }
            Surf::Revolution(r) => r.radius(p) < 1e-7,
            Surf::BSpline(s) => s.poles().iter().any(|&pv| {
                (v - pv).abs() < 1e-9 * (1.0 + pv.abs())
                    || (s.eval(s.u.range().0, pv) - p).norm() < 1e-7
            }),
            Surf::Offset(o) => o
                .base
                .poles()
                .iter()
                .any(|&pv| (v - pv).abs() < 1e-9 * (1.0 + pv.abs())),
            _ => false,
        }
    }

    /// Millimetres per unit of u and v about `(u, v)`, so that triangulating in scaled
    /// parameters gives well-shaped triangles.
    pub fn scale(&self, u: f64, v: f64) -> (f64, f64) {
        match self {
            Surf::Plane(_) => (1.0, 1.0),
            Surf::Cylinder(_, r) => (*r, 1.0),
            Surf::Cone(_, r, a) => ((r + v * a.tan()).abs().max(1e-3), 1.0 / a.cos()),
            Surf::Sphere(_, r) => ((r * v.cos()).abs().max(1e-3), *r),
            Surf::Torus(_, big, small) => ((big + small * v.cos()).abs().max(1e-3), *small),
            Surf::BSpline(_)
            | Surf::Extrusion(_)
            | Surf::Revolution(_)
            | Surf::Offset(_)
            | Surf::Ruled(_) => {
                let h = 1e-4;
                let du = (self.eval(u + h, v) - self.eval(u - h, v)).norm() / (2.0 * h);
                let dv = (self.eval(u, v + h) - self.eval(u, v - h)).norm() / (2.0 * h);
                (du.max(1e-3), dv.max(1e-3))
            }
        }
    }

    /// The unit natural normal at the surface point `p` (parameters `(u, v)`):
    /// exact for the analytic surfaces, by finite differences for B-splines; `None`
    /// where it is undefined (on an axis, at an apex, where a B-spline degenerates).
    pub fn normal(&self, p: &P3, u: f64, v: f64) -> Option<V3> {
        let radial = |f: &Frame| {
            let l = f.local(p);
            (f.x * l.x + f.y * l.y).try_normalize(1e-9)
        };
        match self {
            Surf::Plane(f) => Some(f.z),
            Surf::Cylinder(f, _) => radial(f),
            Surf::Cone(f, _, a) => radial(f).map(|r| r * a.cos() - f.z * a.sin()),
            Surf::Sphere(f, _) => (p - f.o).try_normalize(1e-9),
            Surf::Torus(f, big, _) => {
                let r = radial(f)?;
                (p - (f.o + r * *big)).try_normalize(1e-9)
            }
            Surf::BSpline(_)
            | Surf::Extrusion(_)
            | Surf::Revolution(_)
            | Surf::Offset(_)
            | Surf::Ruled(_) => {
                let h = 1e-6;
                let su = self.eval(u + h, v) - self.eval(u - h, v);
                let sv = self.eval(u, v + h) - self.eval(u, v - h);
                su.cross(&sv).try_normalize(1e-14)
            }
        }
    }
}

/// A surface grown along its natural normal.
#[derive(Debug, Clone, PartialEq)]
pub struct Offset {
    /// The basis surface.
    pub(crate) base: Surf,
    /// The distance along the basis's natural normal (mm, may be negative).
    pub(crate) distance: f64,
}

impl Offset {
    pub(crate) fn eval(&self, u: f64, v: f64) -> P3 {
        let p = self.base.eval(u, v);
        match self.base.normal(&p, u, v) {
            Some(n) => p + n * self.distance,
            None => p,
        }
    }
}

/// A surface known by evaluation over a parameter box, closed or not along each
/// direction: what [`patch_param`] projects onto.
pub(crate) struct Patch<'a> {
    /// The point at `(u, v)`.
    pub eval: &'a dyn Fn(f64, f64) -> P3,
    /// The range of u.
    pub u: (f64, f64),
    /// The range of v.
    pub v: (f64, f64),
    /// Whether it closes on itself along u and along v.
    pub closed: [bool; 2],
}

/// Projects `p` onto a B-spline surface ([`patch_param`]).
fn bspline_param(s: &BSplineSurface, p: &P3, hint: Option<(f64, f64)>) -> (f64, f64) {
    let patch = Patch {
        eval: &|u, v| s.eval(u, v),
        u: s.u.range(),
        v: s.v.range(),
        closed: s.closed,
    };
    patch_param(&patch, p, hint)
}

/// Projects `p` onto a patch: Gauss-Newton steps from the hint when given; where they
/// do not settle (a hint from another bound, far across the face), from the best point
/// of a grid.
pub(crate) fn patch_param(s: &Patch, p: &P3, hint: Option<(f64, f64)>) -> (f64, f64) {
    if let Some(h) = hint {
        let (uv, settled) = gauss_newton(s, p, h, 6);
        if settled {
            return uv;
        }
    }
    let (u0, u1) = s.u;
    let (v0, v1) = s.v;
    let d = |u: f64, v: f64| ((s.eval)(u, v) - p).norm_squared();
    const N: usize = 24;
    let mut best = (u0, v0, f64::INFINITY);
    for i in 0..=N {
        for j in 0..=N {
            let uu = u0 + (u1 - u0) * i as f64 / N as f64;
            let vv = v0 + (v1 - v0) * j as f64 / N as f64;
            let dd = d(uu, vv);
            if dd < best.2 {
                best = (uu, vv, dd);
            }
        }
    }
    gauss_newton(s, p, (best.0, best.1), 30).0
}

/// Up to `steps` Gauss-Newton steps toward the foot of `p` from `start`, inside the
/// parameter box (wrapping along a closed direction); whether the last step moved the
/// point by less than 10⁻⁷ mm.
fn gauss_newton(s: &Patch, p: &P3, start: (f64, f64), steps: usize) -> ((f64, f64), bool) {
    let (u0, u1) = s.u;
    let (v0, v1) = s.v;
    let (mut u, mut v) = start;
    let h = 1e-7 * (1.0 + (u1 - u0).abs().max((v1 - v0).abs()));
    // Central differences whose ends stay in the box (at an open end a step outside
    // would read the clamped end and halve the derivative).
    let diff = |lo: f64, hi: f64, at: &dyn Fn(f64) -> P3, t: f64, closed: bool| {
        let (a, b) = if closed {
            (t - h, t + h)
        } else {
            ((t - h).max(lo), (t + h).min(hi))
        };
        (at(b) - at(a)) / (b - a)
    };
    for _ in 0..steps {
        let q = (s.eval)(u, v);
        let su = diff(u0, u1, &|t| (s.eval)(t, v), u, s.closed[0]);
        let sv = diff(v0, v1, &|t| (s.eval)(u, t), v, s.closed[1]);
        let r = p - q;
        let (a, b, c) = (su.dot(&su), su.dot(&sv), sv.dot(&sv));
        let (e, f) = (su.dot(&r), sv.dot(&r));
        let det = a * c - b * b;
        if det.abs() < 1e-30 {
            return ((u, v), false);
        }
        let du = (c * e - b * f) / det;
        let dv = (a * f - b * e) / det;
        // Along a closed direction the parameter wraps; along an open one it stays in range.
        let keep = |x: f64, a: f64, b: f64, closed: bool| {
            if closed {
                a + (x - a).rem_euclid(b - a)
            } else {
                x.clamp(a, b)
            }
        };
        let nu = keep(u + du, u0, u1, s.closed[0]);
        let nv = keep(v + dv, v0, v1, s.closed[1]);
        let moved = ((nu - u) * a.sqrt()).abs() + ((nv - v) * c.sqrt()).abs();
        let wrapped = (nu - (u + du)).abs() > 1e-12 && s.closed[0]
            || (nv - (v + dv)).abs() > 1e-12 && s.closed[1];
        u = nu;
        v = nv;
        if moved < 1e-7 && !wrapped {
            return ((u, v), true);
        }
    }
    ((u, v), false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn surfaces_invert_their_own_points() {
        let f = Frame::new(P3::new(1.0, 2.0, 3.0), Some(V3::new(0.0, 1.0, 1.0)), None).unwrap();
        for s in [
            Surf::Plane(f),
            Surf::Cylinder(f, 4.0),
            Surf::Cone(f, 4.0, 0.3),
            Surf::Sphere(f, 4.0),
            Surf::Torus(f, 10.0, 2.0),
        ] {
            for (u, v) in [(0.3, 0.2), (-2.0, 1.0), (3.0, -0.5)] {
                let p = s.eval(u, v);
                let (a, b) = s.param(&p, None);
                let q = s.eval(a, b);
                assert!((p - q).norm() < 1e-9, "{s:?} at {u},{v}");
                // The natural normal points away from the axis or centre.
                // The normal is the parametrisation's: along S_u × S_v.
                let h = 1e-6;
                let su = s.eval(u + h, v) - s.eval(u - h, v);
                let sv = s.eval(u, v + h) - s.eval(u, v - h);
                let n = s.normal(&p, u, v).unwrap();
                assert!(
                    su.cross(&sv).normalize().dot(&n) > 0.999,
                    "{s:?} at {u},{v}"
                );
            }
        }
    }
}
