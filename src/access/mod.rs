//! Stage 7, accessibility (seed ch. 2, paper 001): for a point near the part, the
//! directions from which a probe can reach it, as cube-map cones.
//!
//! Built so far: the cube map ([`CubeMap`]) with its set operations, growing and
//! preferred directions; the conservative CPU rasterizer for the half-line GAC
//! ([`gac_halfline`]); and the map between an indexable head's A/B grid and directions.
//! Grown half-lines, the ram, bent probes and the wgpu backend follow (issue 4).
//!
//! **Architecture Invariant:** a direction the obstacle blocks is never reported
//! accessible: the rasterizer marks every pixel a triangle's shadow touches.

mod cubemap;
mod raster;

pub use cubemap::{face_dir, face_uv, Cell, CubeMap, Pixel};
pub use raster::{blocked_halfline, shadow_triangle};

use crate::geometry::{PartGeometry, P3, V3};

/// The part's triangles as corner points.
pub fn triangles_of(g: &PartGeometry) -> Vec<[P3; 3]> {
    g.triangles
        .iter()
        .map(|t| t.map(|i| g.vertices[i as usize]))
        .collect()
}

/// The global accessibility cone of a half-line at `p`: the directions d for which the
/// ray p + t·d, t > 0, misses every triangle (seed ch. 2.3). `p` should be off the
/// surface, such as a tip centre p + r·n.
pub fn gac_halfline(p: &P3, triangles: &[[P3; 3]], n: u32, preferred: &[V3]) -> CubeMap {
    blocked_halfline(p, triangles, n, preferred).not()
}

/// The probe direction of an indexable head at angles A (tilt from vertical) and B
/// (rotation about vertical), in degrees: the unit vector from the stylus tip towards the
/// head, in the machine frame. A = 0 hangs the stylus straight down, so the probe
/// approaches from +z; A = 90°, B = 0 lays it horizontal, reaching from +x.
pub fn head_direction(a_deg: f64, b_deg: f64) -> V3 {
    let (a, b) = (a_deg.to_radians(), b_deg.to_radians());
    V3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos())
}

/// The orientations of a head's grid whose direction is in the cone, in grid order.
pub fn orientations_in(cone: &CubeMap, orientations: &[(f64, f64)]) -> Vec<(f64, f64)> {
    orientations
        .iter()
        .copied()
        .filter(|&(a, b)| cone.contains(&head_direction(a, b)))
        .collect()
}

/// The cone of a set of orientations: the cells their directions fall in.
pub fn orientation_cone(orientations: &[(f64, f64)], n: u32, preferred: &[V3]) -> CubeMap {
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

    #[test]
    fn a_single_triangle_blocks_what_is_behind_it() {
        let tri = [[
            P3::new(-1.0, -1.0, 1.0),
            P3::new(1.0, -1.0, 1.0),
            P3::new(0.0, 1.0, 1.0),
        ]];
        let gac = gac_halfline(&P3::origin(), &tri, 32, &[V3::z()]);
        assert!(!gac.contains(&V3::z()));
        assert!(!gac.contains(&V3::new(0.0, -0.9, 1.0)));
        assert!(gac.contains(&V3::new(0.0, 0.0, -1.0)));
        assert!(gac.contains(&V3::new(1.0, 1.0, 1.0)));
    }
}
