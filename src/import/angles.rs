//! An angularity's basic angle from the model. STEP and QIF carry an angularity's
//! basic angle as a separate (often missing) dimension; the model itself fixes it: it
//! is the angle between the toleranced feature and its primary datum feature as
//! modelled (ASME Y14.5-2018 ch. 9, angularity: the zone is at the basic angle to the datum).
//!
//! A feature's direction is its planes' common normal or its cylinders' and cones'
//! common axis; the angle between a plane and a plane, or an axis and an axis, is that
//! between their normals or axes, between a plane and an axis its complement, and it
//! is written acute (0°–90°): the zone's orientation is the same either side.

use crate::geometry::step::pmi::{GeoTolerance, Pmi};
use crate::geometry::{Surface, V3};

/// A feature's direction: a plane's normal or an axis.
#[derive(Debug, Clone, Copy)]
enum Direction {
    Normal(V3),
    Axis(V3),
}

/// The basic angle (degrees) the model gives angularity `t`, or why it gives none.
pub(super) fn basic_angle(t: &GeoTolerance, p: &Pmi, exact: &[Surface]) -> Result<f64, String> {
    let primary = t
        .datums
        .first()
        .and_then(|d| d.letters.first())
        .ok_or("it has no datum to take its basic angle from")?;
    let datum_faces = p
        .datums
        .iter()
        .find(|d| &d.letter == primary)
        .map(|d| d.faces.as_slice())
        .filter(|f| !f.is_empty())
        .ok_or_else(|| format!("datum {primary} has no faces to take its basic angle from"))?;
    let f = direction(&t.faces, exact)
        .ok_or("its faces share no plane normal or axis to take its basic angle from")?;
    let d = direction(datum_faces, exact).ok_or_else(|| {
        format!(
            "datum {primary}'s faces share no plane normal or axis to take its basic angle from"
        )
    })?;
    let between = |a: V3, b: V3| a.dot(&b).abs().clamp(0.0, 1.0).acos().to_degrees();
    let angle =
        match (f, d) {
            (Direction::Normal(a), Direction::Normal(b))
            | (Direction::Axis(a), Direction::Axis(b)) => between(a, b),
            (Direction::Normal(a), Direction::Axis(b))
            | (Direction::Axis(a), Direction::Normal(b)) => 90.0 - between(a, b),
        };
    // To a thousandth of a degree, as drawings give basic angles.
    Ok((angle * 1000.0).round() / 1000.0)
}

/// The direction the faces share: every face a plane with one normal (up to sign), or
/// every face a cylinder or cone on one axis.
fn direction(faces: &[usize], exact: &[Surface]) -> Option<Direction> {
    let mut dirs = faces.iter().map(|&i| match exact.get(i)? {
        Surface::Plane { normal, .. } => Some(Direction::Normal(*normal)),
        Surface::Cylinder { axis, .. } | Surface::Cone { axis, .. } => Some(Direction::Axis(*axis)),
        _ => None,
    });
    let first = dirs.next()??;
    let same = |a: &V3, b: &V3| a.cross(b).norm() < 1e-6;
    for d in dirs {
        match (first, d?) {
            (Direction::Normal(a), Direction::Normal(b))
            | (Direction::Axis(a), Direction::Axis(b))
                if same(&a, &b) => {}
            _ => return None,
        }
    }
    Some(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::step::pmi::DatumRef;
    use crate::geometry::P3;

    fn plane(normal: V3) -> Surface {
        Surface::Plane {
            origin: P3::origin(),
            normal: normal.normalize(),
        }
    }

    fn axis(a: V3) -> Surface {
        Surface::Cylinder {
            origin: P3::origin(),
            axis: a.normalize(),
            radius: 5.0,
            convex: false,
        }
    }

    /// Angularity of face 1 to datum A on face 0.
    fn angle(exact: &[Surface]) -> Result<f64, String> {
        let pmi = Pmi {
            datums: vec![crate::geometry::step::pmi::Datum {
                id: 1,
                letter: "A".into(),
                faces: vec![0],
                targets: vec![],
                located: false,
            }],
            ..Pmi::default()
        };
        let t = GeoTolerance {
            id: 2,
            name: "angularity".into(),
            kind: Some(crate::model::TolKind::Angularity),
            value_mm: 0.1,
            diameter: false,
            spherical: false,
            material: None,
            other: vec![],
            datums: vec![DatumRef {
                letters: vec!["A".into()],
                material: None,
                other: vec![],
            }],
            faces: vec![1],
            composite_of: None,
            unequal_mm: None,
            per_unit: None,
        };
        basic_angle(&t, &pmi, exact)
    }

    #[test]
    fn the_model_gives_the_basic_angle() {
        let z = V3::z();
        let tilted = |deg: f64| V3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
        // A plane 30° from datum plane A, seen from either side.
        assert_eq!(angle(&[plane(z), plane(tilted(30.0))]), Ok(30.0));
        assert_eq!(angle(&[plane(z), plane(-tilted(150.0))]), Ok(30.0));
        // A bore whose axis leans 60° from the datum plane's normal: 30° to the plane.
        assert_eq!(angle(&[plane(z), axis(tilted(60.0))]), Ok(30.0));
        // Two axes 45° apart.
        assert_eq!(angle(&[axis(z), axis(tilted(45.0))]), Ok(45.0));
        // A sphere has no direction.
        let sphere = Surface::Sphere {
            center: P3::origin(),
            radius: 3.0,
            convex: true,
        };
        assert!(angle(&[plane(z), sphere]).is_err());
    }
}
