//! QIF 3's surfaces beyond the analytic ones (Geometry.xsd): `Nurbs23` (orders, knot
//! vectors, control points and weights), `Spline23` (polynomial patches, `splines.rs`),
//! `Extrude23` (a profile curve swept to a termination point), `Revolution23` (a
//! generatrix turned about an axis), `Ruled23` (straight segments joining corresponding
//! points of two curves) and `Offset23` (a surface moved along its normal), read into
//! the STEP reader's surfaces
//! so that one tessellator meshes both; a sweep or offset that is an analytic surface
//! is read as that surface (`step/canon.rs`).
//!
//! **Decision: the control points' order from the file's own vertices.** The schema
//! sizes `CPs` as (u-knots − u-order) × (v-knots − v-order) points but does not say
//! which index runs fastest. The surface is read with u fastest and, if the face's
//! vertices do not lie on it, with v fastest; a surface neither order puts its own
//! vertices on is malformed, not guessed.

use super::curves::curve_core;
use super::doc::{core, domain, frame, malformed, num, positive, vec3, Doc};
use super::xml::Node;
use super::QifError;
use crate::geometry::step::canon::{canonical, revolution_axis};
use crate::geometry::step::curve::{Curve, Knots, MAX_DEGREE};
use crate::geometry::step::geom::{BSplineSurface, Offset, Surf};
use crate::geometry::step::swept::{Extrusion, Revolution, Ruled};
use crate::geometry::{P3, V3};
use std::sync::Arc;

/// How far a face's vertex may lie from the surface read for it (mm).
const ON_SURFACE_MM: f64 = 1e-3;

/// The surface of a `Nurbs23`, `Extrude23`, `Revolution23` or `Offset23` element whose
/// faces have these vertices.
pub(super) fn read(d: &Doc, n: &Node, vertices: &[P3]) -> Result<Surf, QifError> {
    let s = from_core(d, core(n)?, vertices)?;
    Ok(canonical(&s, &[]).0)
}

fn from_core(d: &Doc, c: &Node, vertices: &[P3]) -> Result<Surf, QifError> {
    match c.name.as_str() {
        "Nurbs23Core" => nurbs(d, c, vertices),
        "Spline23Core" => super::splines::spline23(d, c, vertices, ON_SURFACE_MM),
        "Ruled23Core" => ruled(d, c),
        "Extrude23Core" => extrude(d, c),
        "Revolution23Core" => revolution(d, c),
        "Offset23Core" => {
            let base_core = c
                .child("Surface")
                .and_then(|s| s.children.iter().find(|k| k.name.ends_with("Core")))
                .ok_or_else(|| malformed(c, "it has no <Surface> core"))?;
            // The basis passes a distance away from the face's vertices, which cannot
            // tell a NURBS basis's order: it is read u-fastest.
            let base = from_core(d, base_core, &[])?;
            let distance = num(c, "Distance")? * d.unit;
            if !distance.is_finite() {
                return Err(malformed(c, "its <Distance> is not a number"));
            }
            Ok(Surf::Offset(Arc::new(Offset { base, distance })))
        }
        _ => analytic_surface(d, c),
    }
}

/// The one curve core inside `parent` (`<Curve>`, `<Generatrix>`).
fn inner_curve(d: &Doc, c: &Node, parent: &str) -> Result<(Curve, P3), QifError> {
    let inner = c
        .child(parent)
        .and_then(|k| k.children.iter().find(|k| k.name.ends_with("Core")))
        .ok_or_else(|| malformed(c, &format!("it has no curve in <{parent}>")))?;
    let (curve, start) = curve_core(d, inner, c)?;
    if matches!(curve, Curve::Polyline(_)) {
        return Err(QifError::Unsupported {
            id: c.id(),
            line: c.line,
            what: "surface swept from a polyline".into(),
        });
    }
    let start = start.unwrap_or_else(|| curve.eval(curve.range().0));
    Ok((curve, start))
}

fn extrude(d: &Doc, c: &Node) -> Result<Surf, QifError> {
    let (curve, start) = inner_curve(d, c, "Curve")?;
    let end = d.point(c, "TerminationPoint")?;
    let dir = (end - start)
        .try_normalize(1e-12)
        .ok_or_else(|| malformed(c, "its termination point is its start"))?;
    Ok(Surf::Extrusion(Arc::new(Extrusion { curve, dir })))
}

/// A `Ruled23Core`: its two `<Curve>`s, each run over its own parameters (a segment's
/// from start to end, a polyline's from its first point to its last, an arc's or a NURBS curve's over its domain, a NURBS curve's
/// knots when it states none) as u runs from 0 to 1; the second backwards when
/// `turnedSecondCurve` is set (Geometry.xsd `Ruled23CoreType`).
fn ruled(d: &Doc, c: &Node) -> Result<Surf, QifError> {
    let mut curves = Vec::new();
    for holder in c.all("Curve") {
        let inner = holder
            .children
            .iter()
            .find(|k| k.name.ends_with("Core"))
            .ok_or_else(|| malformed(holder, "it has no curve"))?;
        let (curve, _) = curve_core(d, inner, c)?;
        let span = match &curve {
            // A segment and a polyline run over parameters of their own.
            Curve::Line(..) => (0.0, 1.0),
            Curve::Polyline(_) => curve.range(),
            Curve::BSpline(_) => domain(inner).unwrap_or(curve.range()),
            _ => domain(inner).ok_or_else(|| malformed(inner, "it has no domain"))?,
        };
        curves.push((curve, span.0, span.1));
    }
    let [a, mut b]: [(Curve, f64, f64); 2] = curves
        .try_into()
        .map_err(|_| malformed(c, "it does not have two <Curve>s"))?;
    if matches!(c.attr("turnedSecondCurve"), Some("true" | "1")) {
        b = (b.0, b.2, b.1);
    }
    let closes = |(k, t0, t1): &(Curve, f64, f64)| (k.eval(*t0) - k.eval(*t1)).norm() < 1e-9;
    let closed = closes(&a) && closes(&b);
    Ok(Surf::Ruled(Arc::new(Ruled { a, b, closed })))
}

fn revolution(d: &Doc, c: &Node) -> Result<Surf, QifError> {
    let (curve, _) = inner_curve(d, c, "Generatrix")?;
    let axis = c
        .child("Axis")
        .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
    let o = d.point(axis, "AxisPoint")?;
    let z = vec3(axis, "Direction")?;
    let axis = revolution_axis(o, z, &curve)
        .ok_or_else(|| malformed(c, "its generatrix lies on its axis, or the axis is zero"))?;
    Ok(Surf::Revolution(Arc::new(Revolution { curve, axis })))
}

fn nurbs(d: &Doc, c: &Node, vertices: &[P3]) -> Result<Surf, QifError> {
    if c.child("CPsBinary").is_some() {
        return Err(QifError::Unsupported {
            id: c.id(),
            line: c.line,
            what: "NURBS surface with binary control points (CPsBinary)".into(),
        });
    }
    let order = |name: &str| -> Result<usize, QifError> {
        let o = num(c, name)?;
        if o.fract() != 0.0 || !(2.0..=(MAX_DEGREE + 1) as f64).contains(&o) {
            return Err(malformed(
                c,
                &format!("its <{name}> is not an order inspc reads"),
            ));
        }
        Ok(o as usize)
    };
    let (ou, ov) = (order("OrderU")?, order("OrderV")?);
    let numbers = |name: &str| {
        c.child(name)
            .and_then(|k| k.numbers())
            .ok_or_else(|| malformed(c, &format!("its <{name}> are not numbers")))
    };
    let (ku, kv) = (numbers("KnotsU")?, numbers("KnotsV")?);
    let (nu, nv) = (
        ku.len().checked_sub(ou).filter(|n| *n >= ou),
        kv.len().checked_sub(ov).filter(|n| *n >= ov),
    );
    let (Some(nu), Some(nv)) = (nu, nv) else {
        return Err(malformed(c, "its knots are too few for its orders"));
    };
    let cps = numbers("CPs")?;
    if cps.len() != 3 * nu * nv {
        return Err(malformed(
            c,
            &format!("its <CPs> are not {nu} × {nv} x y z triples"),
        ));
    }
    let weights = match c.child("Weights") {
        Some(_) => numbers("Weights")?,
        None => vec![1.0; nu * nv],
    };
    if weights.len() != nu * nv || weights.iter().any(|w| !(*w > 0.0 && w.is_finite())) {
        return Err(malformed(
            c,
            "its <Weights> are not one positive number per point",
        ));
    }
    let (Some(u), Some(v)) = (Knots::checked(ou - 1, ku), Knots::checked(ov - 1, kv)) else {
        return Err(malformed(c, "its knots are not ascending"));
    };
    let grid = |u_fastest: bool| {
        let at = |i: usize, j: usize| if u_fastest { j * nu + i } else { i * nv + j };
        let points: Vec<Vec<P3>> = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let k = 3 * at(i, j);
                        P3::new(cps[k], cps[k + 1], cps[k + 2]) * d.unit
                    })
                    .collect()
            })
            .collect();
        let w: Vec<Vec<f64>> = (0..nu)
            .map(|i| (0..nv).map(|j| weights[at(i, j)]).collect())
            .collect();
        let same = |a: &P3, b: &P3| (a - b).norm() < 1e-9 * (1.0 + a.coords.norm());
        let closed = [
            (0..nv).all(|j| same(&points[0][j], &points[nu - 1][j])),
            (0..nu).all(|i| same(&points[i][0], &points[i][nv - 1])),
        ];
        Surf::BSpline(Arc::new(BSplineSurface {
            u: u.clone(),
            v: v.clone(),
            points,
            weights: w,
            closed,
        }))
    };
    let fits = |s: &Surf| {
        vertices.iter().all(|p| {
            let (a, b) = s.param(p, None);
            (s.eval(a, b) - p).norm() <= ON_SURFACE_MM
        })
    };
    let first = grid(true);
    if fits(&first) {
        return Ok(first);
    }
    let second = grid(false);
    if fits(&second) {
        return Ok(second);
    }
    Err(malformed(
        c,
        "its face's vertices lie off it with the control points taken u-fastest or v-fastest",
    ))
}

/// An analytic surface from its core element (`Plane23Core`, …).
pub(super) fn analytic_surface(d: &Doc, c: &Node) -> Result<Surf, QifError> {
    match c.name.as_str() {
        "Plane23Core" => {
            let o = d.point(c, "Origin")?;
            let u = c.child("DirU").map(|_| vec3(c, "DirU")).transpose()?;
            let z = match (c.child("Normal"), u, c.child("DirV")) {
                (Some(_), _, _) => vec3(c, "Normal")?,
                (None, Some(u), Some(_)) => u.cross(&vec3(c, "DirV")?),
                _ => {
                    return Err(malformed(
                        c,
                        "it has neither <Normal> nor <DirU> and <DirV>",
                    ))
                }
            };
            Ok(Surf::Plane(frame(c, o, z, u)?))
        }
        "Cylinder23Core" => {
            let r = d.length(c, "Diameter")? / 2.0;
            let axis = c
                .child("Axis")
                .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
            let beg = sweep_start(c)?;
            let f = frame(
                c,
                d.point(axis, "AxisPoint")?,
                vec3(axis, "Direction")?,
                beg,
            )?;
            positive(c, r, "its diameter")?;
            Ok(Surf::Cylinder(f, r))
        }
        "Cone23Core" => {
            let bottom = d.length(c, "DiameterBottom")? / 2.0;
            let top = d.length(c, "DiameterTop")? / 2.0;
            let len = d.length(c, "Length")?;
            positive(c, len, "its length")?;
            let axis = c
                .child("Axis")
                .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
            let p = d.point(axis, "AxisPoint")?;
            let dir = vec3(axis, "Direction")?
                .try_normalize(1e-12)
                .ok_or_else(|| malformed(axis, "its direction is zero"))?;
            let beg = sweep_start(c)?;
            if (top - bottom).abs() < 1e-12 {
                return Ok(Surf::Cylinder(frame(c, p, dir, beg)?, top));
            }
            // inspc's cone opens along its axis: start at the narrow end.
            let (o, z, r) = if top > bottom {
                (p, dir, bottom)
            } else {
                (p + dir * len, -dir, top)
            };
            let a = ((top - bottom).abs() / len).atan();
            Ok(Surf::Cone(frame(c, o, z, beg)?, r, a))
        }
        "Sphere23Core" => {
            let r = d.length(c, "Diameter")? / 2.0;
            positive(c, r, "its diameter")?;
            let o = d.point(c, "Location")?;
            let (x, z) = match c.child("LatitudeLongitudeSweep") {
                Some(s) => (
                    s.child("DirMeridianPrime")
                        .map(|_| vec3(s, "DirMeridianPrime"))
                        .transpose()?,
                    s.child("DirNorthPole")
                        .map(|_| vec3(s, "DirNorthPole"))
                        .transpose()?,
                ),
                None => (None, None),
            };
            Ok(Surf::Sphere(frame(c, o, z.unwrap_or(V3::z()), x)?, r))
        }
        "Torus23Core" => {
            let big = d.length(c, "DiameterMajor")? / 2.0;
            let small = d.length(c, "DiameterMinor")? / 2.0;
            positive(c, small, "its minor diameter")?;
            let axis = c
                .child("Axis")
                .ok_or_else(|| malformed(c, "it has no <Axis>"))?;
            let x = match c.child("LatitudeLongitudeSweep") {
                Some(s) => s
                    .child("DirMeridianPrime")
                    .map(|_| vec3(s, "DirMeridianPrime"))
                    .transpose()?,
                None => None,
            };
            let f = frame(c, d.point(axis, "AxisPoint")?, vec3(axis, "Direction")?, x)?;
            Ok(Surf::Torus(f, big, small))
        }
        _ => Err(QifError::Unsupported {
            id: None,
            line: c.line,
            what: format!("surface {}", c.name.trim_end_matches("Core")),
        }),
    }
}

/// Where a surface of revolution's angle starts (`<Sweep><DirBeg>`), if it says.
fn sweep_start(c: &Node) -> Result<Option<V3>, QifError> {
    match c.child("Sweep") {
        Some(s) if s.child("DirBeg").is_some() => Ok(Some(vec3(s, "DirBeg")?)),
        _ => Ok(None),
    }
}
