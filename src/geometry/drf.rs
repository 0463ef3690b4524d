//! The datum reference frame of measured datum features: the rotation and translation
//! that take them onto their nominals, and the degrees of freedom they leave free
//! (ASME Y14.5-2018, ch. 7: a primary plane fixes three, a secondary two, a tertiary one;
//! a pattern of holes after the primary fixes the turn by two located centres). The
//! simulator's evaluation reads tolerances in it; the path stage asks which directions a
//! tolerance's frame leaves free before aligning on its faces.

use super::cmm_fit::Shape;
use super::{P3, V3};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};

/// A datum reference frame: the motion taking measured features into the nominal's
/// frame, and what the datums leave free.
#[derive(Debug, Clone)]
pub struct Drf {
    /// Measured (program frame) → nominal.
    pub to_nominal: Isometry3<f64>,
    /// Orthonormal directions the datums do not locate.
    pub free_t: Vec<V3>,
    /// Axes the datums do not fix the rotation about.
    pub free_r: Vec<V3>,
}

/// What a datum constrains: a direction, and the directions it locates at a point.
fn constraints(s: &Shape) -> (Option<V3>, Vec<V3>, Option<P3>) {
    match s {
        Shape::Plane { p, n } | Shape::Parpln { p, n, .. } => (Some(*n), vec![*n], Some(*p)),
        Shape::Cylinder { p, a, .. } => {
            let (u, v) = super::cmm_fit::across(a);
            (Some(*a), vec![u, v], Some(*p))
        }
        Shape::Cone { apex, a, .. } => (Some(*a), vec![V3::x(), V3::y(), V3::z()], Some(*apex)),
        Shape::Sphere { c, .. } => (None, vec![V3::x(), V3::y(), V3::z()], Some(*c)),
        Shape::Point { p, .. } => (None, vec![V3::x(), V3::y(), V3::z()], Some(*p)),
        // A line on a face: its run is a direction, the face's normal a location.
        Shape::Line { p, d, n } => (Some(*d), vec![*n], Some(*p)),
        Shape::Surface => (None, vec![], None),
    }
}

/// The datum reference frame of datum features (measured, nominal), in order.
pub fn drf(datums: &[(Shape, Shape)]) -> Drf {
    // Rotation: the primary direction, then the first one across it.
    let dirs: Vec<(V3, V3)> = datums
        .iter()
        .filter_map(|(a, n)| Some((a.direction()?, n.direction()?)))
        .collect();
    let mut rot = UnitQuaternion::identity();
    let mut free_r = Vec::new();
    match dirs.first() {
        None => free_r = vec![V3::x(), V3::y(), V3::z()],
        Some((a1, n1)) => {
            rot = UnitQuaternion::rotation_between(a1, n1).unwrap_or_else(|| {
                let (u, _) = super::cmm_fit::across(n1);
                UnitQuaternion::from_axis_angle(&Unit::new_normalize(u), std::f64::consts::PI)
            });
            let proj = |v: V3| -> Option<V3> { (v - n1 * v.dot(n1)).try_normalize(1e-6) };
            let turn = |pa: V3, pn: V3| -> f64 { pa.cross(&pn).dot(n1).atan2(pa.dot(&pn)) };
            let second = dirs
                .iter()
                .skip(1)
                .find_map(|(a2, n2)| Some((proj(rot * a2)?, proj(*n2)?)));
            // Else two located datums after the primary (a pattern of holes).
            let located: Vec<(P3, P3)> = datums
                .iter()
                .skip(1)
                .filter_map(|(a, n)| Some((a.location()?, n.location()?)))
                .collect();
            let by_points = || -> Option<(V3, V3)> {
                let [(a2, n2), (a3, n3), ..] = located[..] else {
                    return None;
                };
                Some((proj(rot * (a3 - a2))?, proj(n3 - n2)?))
            };
            match second.or_else(by_points) {
                Some((pa, pn)) => {
                    let q =
                        UnitQuaternion::from_axis_angle(&Unit::new_normalize(*n1), turn(pa, pn));
                    rot = q * rot;
                }
                None => free_r.push(*n1),
            }
        }
    }
    // Translation: each datum's located directions not yet fixed.
    let mut basis: Vec<V3> = Vec::new();
    let mut coef: Vec<f64> = Vec::new();
    for (a, n) in datums {
        let (_, dirs_n, loc_n) = constraints(n);
        let (Some(xa), Some(xn)) = (a.location(), loc_n) else {
            continue;
        };
        let xa = rot * xa.coords;
        for u in dirs_n {
            let mut r = u;
            for e in &basis {
                r -= e * r.dot(e);
            }
            let Some(e) = r.try_normalize(1e-6) else {
                continue;
            };
            if basis.len() == 3 {
                break;
            }
            let known: f64 = basis.iter().zip(&coef).map(|(b, c)| c * u.dot(b)).sum();
            let c = (u.dot(&(xn.coords - xa)) - known) / u.dot(&e);
            basis.push(e);
            coef.push(c);
        }
    }
    let t: V3 = basis.iter().zip(&coef).map(|(b, c)| b * *c).sum();
    let mut free_t = Vec::new();
    for axis in [V3::x(), V3::y(), V3::z()] {
        let mut r = axis;
        for e in basis.iter().chain(free_t.iter()) {
            r -= e * r.dot(e);
        }
        if let Some(e) = r.try_normalize(1e-6) {
            free_t.push(e);
        }
    }
    Drf {
        to_nominal: Isometry3::from_parts(Translation3::from(t), rot),
        free_t,
        free_r,
    }
}
