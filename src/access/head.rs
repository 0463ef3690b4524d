//! An indexable head's orientations as directions: (A, B) to the probe's direction, the
//! grid orientations a cone holds, and the cone of a set of orientations.

use super::CubeMap;
use crate::geometry::V3;

/// The probe direction of an indexable head at angles A (tilt from vertical) and B
/// (rotation about vertical), in degrees: the unit vector from the stylus tip towards the
/// head, in the machine frame. A = 0 hangs the stylus straight down, so the probe
/// approaches from +z; A = 90°, B = 0 lays it horizontal, reaching from +x.
pub fn head_direction(a_deg: f64, b_deg: f64) -> V3 {
    let (a, b) = (a_deg.to_radians(), b_deg.to_radians());
    V3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos())
}

/// The orientations of a head's grid whose direction is in the cone, in grid order.
pub(crate) fn orientations_in(cone: &CubeMap, orientations: &[(f64, f64)]) -> Vec<(f64, f64)> {
    orientations
        .iter()
        .copied()
        .filter(|&(a, b)| cone.contains(&head_direction(a, b)))
        .collect()
}

#[cfg(test)]
/// The cone of a set of orientations: the cells their directions fall in.
pub(crate) fn orientation_cone(orientations: &[(f64, f64)], n: u32, preferred: &[V3]) -> CubeMap {
    let mut c = CubeMap::empty(n, preferred);
    for &(a, b) in orientations {
        let cell = c.cell_of(&head_direction(a, b));
        c.set(cell, true);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::access::Cell;

    #[test]
    fn head_directions() {
        assert!((head_direction(0.0, 0.0) - V3::z()).norm() < 1e-12);
        assert!((head_direction(90.0, 0.0) - V3::x()).norm() < 1e-12);
        assert!((head_direction(90.0, 90.0) - V3::y()).norm() < 1e-12);
    }

    #[test]
    fn orientation_cone_round_trips() {
        let grid: Vec<(f64, f64)> = (0..=14)
            .flat_map(|a| (0..48).map(move |b| (a as f64 * 7.5, -180.0 + b as f64 * 7.5)))
            .collect();
        let c = orientation_cone(&grid, 64, &[V3::z()]);
        // Every orientation's own cell is in the cone; A = 0 is the exact +z.
        assert_eq!(orientations_in(&c, &grid).len(), grid.len());
        assert!(c.get(Cell::Preferred(0)));
    }
}
