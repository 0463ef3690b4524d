//! A "size" between planes that all face one way: a step, not a feature of size.
//!
//! A feature of size has opposed elements (ASME Y14.5-2018 § 3.35; ISO 14405-1's linear
//! size is between opposite points): a slot's walls face each other, a tab's face apart.
//! AP242 files also tag as a size a height from one level of a part to another, all its
//! faces facing the same way: NIST CTC 03's 20.828 mm runs from the top (80,943 mm², +z)
//! down to four 17 mm² pads (+z). No two points of those faces oppose each other, so a
//! width read there measures nothing; the dimension locates one level from the other,
//! which the language says as a `distance` between the two sets of faces.

use crate::geometry::{Surface, P3, V3};

/// How far apart (mm) two planes' offsets along their normal may be and still be one
/// level.
const SAME_LEVEL: f64 = 1e-3;

/// The faces of a size at its upper and its lower level, when every one is a plane
/// facing the same way and they lie at exactly two levels along that normal; None for
/// anything else (a slot or tab, whose walls oppose, or a mix of surfaces).
pub(super) fn step_levels(exact: &[Surface], faces: &[usize]) -> Option<(Vec<usize>, Vec<usize>)> {
    let planes: Vec<(usize, P3, V3)> = faces
        .iter()
        .map(|&f| match exact.get(f)? {
            Surface::Plane { origin, normal } => Some((f, *origin, *normal)),
            _ => None,
        })
        .collect::<Option<_>>()?;
    let n = planes.first()?.2;
    if planes.iter().any(|p| p.2.dot(&n) < 1.0 - 1e-6) {
        return None;
    }
    let level = |o: &P3| o.coords.dot(&n);
    let top = planes
        .iter()
        .map(|p| level(&p.1))
        .fold(f64::NEG_INFINITY, f64::max);
    type Face = (usize, P3, V3);
    let (upper, lower): (Vec<&Face>, Vec<&Face>) =
        planes.iter().partition(|p| top - level(&p.1) < SAME_LEVEL);
    let low = lower
        .iter()
        .map(|p| level(&p.1))
        .fold(f64::INFINITY, f64::min);
    if lower.is_empty() || lower.iter().any(|p| level(&p.1) - low >= SAME_LEVEL) {
        return None;
    }
    let ids = |v: Vec<&Face>| v.into_iter().map(|p| p.0).collect();
    Some((ids(upper), ids(lower)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(z: f64, nz: f64) -> Surface {
        Surface::Plane {
            origin: P3::new(1.0, 2.0, z),
            normal: V3::new(0.0, 0.0, nz),
        }
    }

    #[test]
    fn a_top_and_pads_below_it_facing_up_are_two_levels() {
        let exact = [plane(78.108, 1.0), plane(57.28, 1.0), plane(57.28, 1.0)];
        assert_eq!(step_levels(&exact, &[0, 1, 2]), Some((vec![0], vec![1, 2])));
    }

    #[test]
    fn opposed_walls_a_single_level_or_three_levels_are_not_a_step() {
        let slot = [plane(10.0, 1.0), plane(0.0, -1.0)];
        assert_eq!(step_levels(&slot, &[0, 1]), None);
        let one = [plane(5.0, 1.0), plane(5.0, 1.0)];
        assert_eq!(step_levels(&one, &[0, 1]), None);
        let three = [plane(9.0, 1.0), plane(5.0, 1.0), plane(1.0, 1.0)];
        assert_eq!(step_levels(&three, &[0, 1, 2]), None);
        let bore = [Surface::Sphere {
            center: P3::origin(),
            radius: 1.0,
            convex: false,
        }];
        assert_eq!(step_levels(&bore, &[0]), None);
    }
}
