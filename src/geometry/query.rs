//! Point queries on a built geometry: is a point on a face, how far from the face's
//! boundary, inside or outside the solid.

use super::{FaceId, PartGeometry, P3, V3};
use std::collections::HashMap;

/// Per face, what point queries need: its boundary edges (where it meets another face or
/// the mesh is open), and which of them are walls. Built once per geometry.
#[derive(Debug, Clone)]
pub struct FaceIndex {
    /// Per face, boundary segments as vertex index pairs, in a stable order.
    pub boundary: Vec<Vec<[u32; 2]>>,
    /// Per face, parallel to `boundary`: whether the face beyond the segment rises on
    /// the face's outward side (a concave edge: a wall, a fillet up to one), where a
    /// tip beside the edge meets material; else the edge is open (an outer edge, a
    /// hole's mouth), where material falls away.
    pub wall: Vec<Vec<bool>>,
}

impl FaceIndex {
    /// Indexes a geometry's faces.
    pub fn new(g: &PartGeometry) -> FaceIndex {
        let edges = edge_triangles(&g.triangles);
        let mut boundary = vec![Vec::new(); g.faces.len()];
        let mut wall = vec![Vec::new(); g.faces.len()];
        for (t, tri) in g.triangles.iter().enumerate() {
            let f = g.tri_face[t];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let users = &edges[&(a.min(b), a.max(b))];
                let inner = users.len() == 2 && users.iter().all(|&u| g.tri_face[u as usize] == f);
                if !inner {
                    boundary[f as usize].push([a, b]);
                    wall[f as usize].push(rises_beyond(g, t, [a, b], users));
                }
            }
        }
        FaceIndex { boundary, wall }
    }

    /// Distances from `p` to a face's open edges and to its walls (mm; infinite where
    /// it has none), as [`FaceIndex::wall`] tells them apart.
    pub fn edge_distances(&self, g: &PartGeometry, face: FaceId, p: &P3) -> (f64, f64) {
        let (mut open, mut wall) = (f64::INFINITY, f64::INFINITY);
        for (&[a, b], &is_wall) in self.boundary[face.0].iter().zip(&self.wall[face.0]) {
            let d = segment_distance(p, &g.vertices[a as usize], &g.vertices[b as usize]);
            let slot = if is_wall { &mut wall } else { &mut open };
            *slot = slot.min(d);
        }
        (open, wall)
    }

    /// Distance from `p` to the boundary of a face (mm); infinite for a closed face.
    pub fn boundary_distance(&self, g: &PartGeometry, face: FaceId, p: &P3) -> f64 {
        let (open, wall) = self.edge_distances(g, face, p);
        open.min(wall)
    }
}

/// Whether the other triangle on edge `ab` of triangle `t` rises on `t`'s outward side
/// (its far corner above `t`'s plane by more than a micrometre): the edge is concave.
/// An edge of the open mesh, or one shared by more than two triangles, is not.
fn rises_beyond(g: &PartGeometry, t: usize, [a, b]: [u32; 2], users: &[u32]) -> bool {
    let mut others = users.iter().filter(|&&u| u as usize != t);
    let (Some(&u), None) = (others.next(), others.next()) else {
        return false;
    };
    let tri = g.triangles[t].map(|i| g.vertices[i as usize]);
    let Some(n) = (tri[1] - tri[0])
        .cross(&(tri[2] - tri[0]))
        .try_normalize(0.0)
    else {
        return false;
    };
    let far = g.triangles[u as usize]
        .into_iter()
        .find(|&i| i != a && i != b)
        .map(|i| g.vertices[i as usize]);
    far.is_some_and(|w| (w - g.vertices[a as usize]).dot(&n) > 1e-3)
}

/// Each undirected edge (smaller vertex index first) → the triangles using it, in order.
pub fn edge_triangles(triangles: &[[u32; 3]]) -> HashMap<(u32, u32), Vec<u32>> {
    let mut edges: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(triangles.len() * 2);
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            edges
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(t as u32);
        }
    }
    edges
}

/// Distance from a point to a segment.
pub(crate) fn segment_distance(p: &P3, a: &P3, b: &P3) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Where the line `o + t·d` crosses triangle `abc`: `t`, or `None` when it misses.
/// Möller–Trumbore, edges inclusive.
pub fn line_triangle(o: &P3, d: &V3, a: &P3, b: &P3, c: &P3) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(&e2);
    let det = e1.dot(&h);
    if det.abs() < 1e-14 * e1.norm() * e2.norm() * d.norm() {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(&h) * inv;
    const EPS: f64 = 1e-9;
    if !(-EPS..=1.0 + EPS).contains(&u) {
        return None;
    }
    let q = s.cross(&e1);
    let v = d.dot(&q) * inv;
    if v < -EPS || u + v > 1.0 + EPS {
        return None;
    }
    Some(e2.dot(&q) * inv)
}

impl PartGeometry {
    /// Whether the line through `p` along `n` crosses one of the face's triangles within
    /// `tol` of `p`: `p` (on the face's surface) lies inside the face's boundary.
    pub fn face_covers(&self, face: FaceId, p: &P3, n: &V3, tol: f64) -> bool {
        self.faces[face.0].triangles.iter().any(|&t| {
            let [a, b, c] = self.triangles[t as usize].map(|i| self.vertices[i as usize]);
            line_triangle(p, n, &a, &b, &c).is_some_and(|s| s.abs() <= tol)
        })
    }

    /// The generalized winding number of the closed mesh around `p`: 1 inside the solid,
    /// 0 outside (Van Oosterom and Strackee's solid angle, summed over triangles).
    pub fn winding_number(&self, p: &P3) -> f64 {
        winding_number(&self.vertices, &self.triangles, p)
    }
}

/// The generalized winding number of a closed triangle mesh around `p`: 1 inside, 0
/// outside (Van Oosterom and Strackee's solid angle, summed over triangles).
pub fn winding_number(vertices: &[P3], triangles: &[[u32; 3]], p: &P3) -> f64 {
    let mut total = 0.0;
    for tri in triangles {
        let [a, b, c] = tri.map(|i| vertices[i as usize] - p);
        let (la, lb, lc) = (a.norm(), b.norm(), c.norm());
        let num = a.dot(&b.cross(&c));
        let den = la * lb * lc + a.dot(&b) * lc + b.dot(&c) * la + c.dot(&a) * lb;
        total += 2.0 * num.atan2(den);
    }
    total / (4.0 * std::f64::consts::PI)
}
