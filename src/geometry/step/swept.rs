//! Surfaces made from curves: a curve swept along a vector
//! (`SURFACE_OF_LINEAR_EXTRUSION`), a curve revolved about an axis
//! (`SURFACE_OF_REVOLUTION`), a surface ruled between two curves (QIF's `Ruled23`, whose
//! inverse is `geom.rs`'s search over its parameter square); and, in `geom.rs` beside the surfaces it grows, a surface
//! grown along its normal (`OFFSET_SURFACE`).
//!
//! The parametrisations are ISO 10303-42's (§ 4.4.x `surface_of_linear_extrusion`,
//! `surface_of_revolution`, `offset_surface`), so that `S_u × S_v` points along the
//! standard's natural normal:
//! - extrusion: `S(u, v) = C(u) + v·V`, u the curve's parameter, v millimetres along
//!   the unit vector V;
//! - revolution: `S(u, v)` = `C(v)` turned by the angle u about the axis (right-handed);
//! - offset: `S(u, v) = B(u, v) + d·N_B(u, v)`, the basis's parameters and normal.
//!
//! Most of them are analytic surfaces in disguise (a line swept or revolved is a plane,
//! cylinder or cone; a circle revolved is a sphere or torus; an offset plane is a plane)
//! and are read as such (`canon.rs`); what is left is evaluated here, and its inverse
//! found by projecting along the sweep (extrusion), turning back into the profile's
//! half-plane (revolution), or taking the basis's (offset: a point's foot on the offset
//! surface and on its basis share their parameters).

use super::curve::{nearest_param, Curve, Frame};
use crate::geometry::{P3, V3};
use std::f64::consts::TAU;

/// A curve swept along a direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Extrusion {
    /// The swept curve.
    pub(crate) curve: Curve,
    /// The unit sweep direction.
    pub(crate) dir: V3,
}

/// A curve revolved about an axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Revolution {
    /// The swept curve.
    pub(crate) curve: Curve,
    /// The axis: origin and z; x points from the axis toward the curve, so that the
    /// curve lies at u = 0.
    pub(crate) axis: Frame,
}

/// A surface ruled between two curves: `S(u, v) = (1 − v)·A(a(u)) + v·B(b(u))` for u and
/// v from 0 to 1, each curve's parameter running linearly over its span as u does (the
/// straight segments join corresponding points; QIF 3 Geometry.xsd `Ruled23CoreType`).
#[derive(Debug, Clone, PartialEq)]
pub struct Ruled {
    /// The first curve and the parameters it runs from and to.
    pub(crate) a: (Curve, f64, f64),
    /// The second curve likewise.
    pub(crate) b: (Curve, f64, f64),
    /// Whether both curves close, so that u runs on round them.
    pub(crate) closed: bool,
}

impl Ruled {
    pub(crate) fn eval(&self, u: f64, v: f64) -> P3 {
        let u = if self.closed { u.rem_euclid(1.0) } else { u };
        let at = |(c, t0, t1): &(Curve, f64, f64)| c.eval(t0 + (t1 - t0) * u);
        P3::from(at(&self.a).coords * (1.0 - v) + at(&self.b).coords * v)
    }
}

impl Extrusion {
    pub(crate) fn eval(&self, u: f64, v: f64) -> P3 {
        self.curve.eval(u) + self.dir * v
    }

    /// The curve's parameter whose sweep line passes nearest `p`, and how far along it.
    pub(crate) fn param(&self, p: &P3, hint: Option<f64>) -> (f64, f64) {
        let d = self.dir;
        let u = match self.curve.plane() {
            // A planar curve swept square to its plane: p dropped into the plane is
            // its foot's sweep line, inverted in closed form.
            Some(f) if d.cross(&f.z).norm() < 1e-9 => {
                let q = p - d * ((p - f.o).dot(&f.z) / d.dot(&f.z));
                curve_param(&self.curve, &q, hint, |t| self.curve.eval(t))
            }
            _ => {
                // Seen along the sweep, the nearest point of the curve (the foot of a
                // point on the surface or off it: the normal is square to the sweep).
                let flat = |q: P3| q - d * q.coords.dot(&d);
                let target = flat(*p);
                curve_param(&self.curve, &target, hint, |t| flat(self.curve.eval(t)))
            }
        };
        (u, (p - self.curve.eval(u)).dot(&d))
    }
}

impl Revolution {
    pub(crate) fn eval(&self, u: f64, v: f64) -> P3 {
        let a = &self.axis;
        let l = a.local(&self.curve.eval(v));
        let (s, c) = u.sin_cos();
        a.at(l.x * c - l.y * s, l.x * s + l.y * c, l.z)
    }

    /// The profile parameter whose circle about the axis passes nearest `p` (the
    /// profile and `p` both turned into the half-plane at angle 0, so that a profile
    /// outside the axis's planes is inverted too), and the angle that turns that
    /// profile point onto `p`.
    pub(crate) fn param(&self, p: &P3, hint: Option<f64>) -> (f64, f64) {
        let a = &self.axis;
        let flat = |q: &P3| {
            let l = a.local(q);
            a.at(l.x.hypot(l.y), 0.0, l.z)
        };
        let v = curve_param(&self.curve, &flat(p), hint, |t| flat(&self.curve.eval(t)));
        let (lp, lc) = (a.local(p), a.local(&self.curve.eval(v)));
        let u = lp.y.atan2(lp.x) - lc.y.atan2(lc.x);
        (u, v)
    }

    /// The profile's parameters where it meets the axis: the surface's poles.
    pub(crate) fn poles(&self) -> Vec<f64> {
        let ends = match &self.curve {
            Curve::BSpline(c) => {
                let (a, b) = c.knots.range();
                vec![a, b]
            }
            Curve::Circle(..) | Curve::Ellipse(..) => {
                (0..4).map(|k| k as f64 * TAU / 4.0 - TAU / 2.0).collect()
            }
            _ => vec![],
        };
        ends.into_iter()
            .filter(|&t| self.radius(&self.curve.eval(t)) < 1e-7)
            .collect()
    }

    /// The distance of `p` from the axis.
    pub(crate) fn radius(&self, p: &P3) -> f64 {
        let l = self.axis.local(p);
        l.x.hypot(l.y)
    }
}

/// The parameter of `curve` whose point `at(t)` lies nearest `target`: Newton's steps
/// from `hint` when given and they settle, else a scan of the curve's range.
fn curve_param(curve: &Curve, target: &P3, hint: Option<f64>, at: impl Fn(f64) -> P3) -> f64 {
    let range = curve.range();
    if let Some(t0) = hint {
        if let Some(t) = newton(&at, target, t0, range, curve.period().is_some()) {
            return t;
        }
    }
    match curve {
        // The analytic curves invert in closed form (their points are `at`'s when the
        // sweep is not needed).
        Curve::Circle(..)
        | Curve::Ellipse(..)
        | Curve::Parabola(..)
        | Curve::Hyperbola(..)
        | Curve::Line(..)
            if (at(0.0) - curve.eval(0.0)).norm() < 1e-12 =>
        {
            // Exact for a point on the curve; a point off it (on an offset of the
            // sweep) is then taken to its true foot.
            let t = curve.param(target);
            newton(&at, target, t, range, curve.period().is_some()).unwrap_or(t)
        }
        _ => nearest_param(&at, range, target),
    }
}

/// Newton's method on the squared distance from `at(t)` to `target`, inside `range`
/// (wrapping round it on a closed curve); `None` when it does not settle in a few steps.
fn newton(
    at: &impl Fn(f64) -> P3,
    target: &P3,
    t0: f64,
    (a, b): (f64, f64),
    closed: bool,
) -> Option<f64> {
    let h = 1e-6 * (1.0 + (b - a).abs().min(1e6));
    let mut t = t0;
    for _ in 0..8 {
        let p = at(t);
        let d1 = (at(t + h) - at(t - h)) / (2.0 * h);
        let d2 = ((at(t + h) - p) + (at(t - h) - p)) / (h * h);
        let r = p - target;
        let g = r.dot(&d1);
        let hess = d1.dot(&d1) + r.dot(&d2);
        if hess <= 0.0 {
            return None;
        }
        let step = g / hess;
        t = if closed {
            a + (t - step - a).rem_euclid(b - a)
        } else {
            (t - step).clamp(a, b)
        };
        if step.abs() < 1e-12 * (1.0 + t.abs()) {
            return Some(t);
        }
    }
    None
}
