//! A mesh as read ([`RawMesh`]) and the welding every reader ends with: coincident
//! vertices merged, degenerate triangles dropped, and a mesh with more than a tenth of
//! its edges open or non-manifold refused as no solid. Below the file readers (STL, OBJ
//! in `mesh_io`, STEP and QIF in `step` and `qif`), which all call it.
//!
//! **Decision: imperfect meshes are read.** Real exports are nearly closed (NIST CTC
//! 01's mesh has 4 non-manifold edges, FTC 08's 24 open and 20 non-manifold); up to a
//! tenth of the edges defective is a warning (`insp::geometry::mesh_defects`), more is
//! an error.

use super::errors::MeshError;
use super::P3;
use std::collections::HashMap;

/// The most triangles a mesh may have, read (STL, OBJ) or made (STEP, QIF).
pub(crate) const MAX_TRIANGLES: usize = 2_000_000;

/// A mesh as read: welded vertices (mm), triangles, and each triangle's group.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    /// Vertex positions in mm.
    pub vertices: Vec<P3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Index into `groups` per triangle (all 0 for STL).
    pub tri_group: Vec<u32>,
    /// OBJ group names in order of first appearance; empty for STL.
    pub groups: Vec<String>,
    /// Edges used by one triangle only.
    pub open_edges: usize,
    /// Edges used by more than two triangles.
    pub nonmanifold_edges: usize,
    /// Per group, its exact surface when the file gives one (STEP); empty for meshes,
    /// whose surfaces are fitted.
    pub exact: Vec<super::Surface>,
    /// For a CAD file, each group's id in the file (`step_face`, `qif_face`).
    pub cad: Option<super::CadFaces>,
}

impl RawMesh {
    /// Per group with an exact surface (`exact`'s order), the indices of its triangles.
    pub fn triangles_of_groups(&self) -> Vec<Vec<u32>> {
        let mut own: Vec<Vec<u32>> = vec![Vec::new(); self.exact.len()];
        for (t, &g) in self.tri_group.iter().enumerate() {
            if let Some(list) = own.get_mut(g as usize) {
                list.push(t as u32);
            }
        }
        own
    }

    /// The mesh scaled by `s` about the origin, its exact surfaces with it.
    pub fn scale(&mut self, s: f64) {
        for v in &mut self.vertices {
            *v *= s;
        }
        for e in &mut self.exact {
            *e = e.scaled(s);
        }
    }
}

/// Merges coincident vertices (to 1e-6 mm), drops degenerate triangles and counts open
/// and non-manifold edges; a mesh with more than a tenth of its edges defective is not
/// a solid at all.
pub(super) fn weld(
    positions: Vec<[f64; 3]>,
    faces: Vec<[usize; 3]>,
    tri_group: Vec<u32>,
    groups: Vec<String>,
    unit_mm: f64,
) -> Result<RawMesh, MeshError> {
    let mut key_of: HashMap<[i64; 3], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let mut remap = Vec::with_capacity(positions.len());
    for p in &positions {
        let q = p.map(|c| c * unit_mm);
        if q.iter()
            .any(|c| !c.is_finite() || c.abs() > crate::model::MAX_LENGTH_MM)
        {
            return Err(MeshError::Corrupt(
                "a vertex lies at infinity or more than 10 m from the origin".into(),
            ));
        }
        let key = q.map(|c| (c * 1e6).round() as i64);
        let id = *key_of.entry(key).or_insert_with(|| {
            vertices.push(P3::new(q[0], q[1], q[2]));
            vertices.len() as u32 - 1
        });
        remap.push(id);
    }
    let mut triangles = Vec::new();
    let mut groups_of = Vec::new();
    for (f, g) in faces.iter().zip(tri_group) {
        let t = f.map(|i| remap[i]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        triangles.push(t);
        groups_of.push(g);
    }
    if triangles.is_empty() {
        return Err(MeshError::Corrupt("every triangle is degenerate".into()));
    }
    let mut uses: HashMap<(u32, u32), u32> = HashMap::new();
    for t in &triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let open_edges = uses.values().filter(|&&u| u == 1).count();
    let nonmanifold_edges = uses.values().filter(|&&u| u > 2).count();
    if (open_edges + nonmanifold_edges) * 10 > uses.len() {
        return Err(MeshError::NotClosed(format!(
            "{open_edges} open and {nonmanifold_edges} non-manifold edges of {}",
            uses.len()
        )));
    }
    Ok(RawMesh {
        vertices,
        triangles,
        tri_group: groups_of,
        groups,
        open_edges,
        nonmanifold_edges,
        exact: Vec::new(),
        cad: None,
    })
}
