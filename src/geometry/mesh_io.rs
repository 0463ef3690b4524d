//! Reading STL (binary and ASCII) and OBJ meshes (and STEP and QIF parts, through `step` and `qif`), welding coincident vertices and
//! checking that the result is a (nearly) closed solid.
//!
//! **Decision: imperfect meshes are read.** Real exports are nearly closed (NIST CTC
//! 01's mesh has 4 non-manifold edges, FTC 08's 24 open and 20 non-manifold); up to a
//! tenth of the edges defective is a warning (`insp::geometry::mesh_defects`), more is
//! an error.

use super::errors::MeshError;
use super::P3;
use crate::source::{FileKind, World};
use std::collections::HashMap;
use std::path::Path;

/// The most triangles a mesh may have.
pub const MAX_TRIANGLES: usize = 2_000_000;

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

/// Reads a mesh file through the world, scaling by `unit_mm`; a STEP or QIF part is
/// meshed at the default resolution.
pub fn read_mesh(world: &dyn World, path: &Path, unit_mm: f64) -> Result<RawMesh, MeshError> {
    read_mesh_at(world, path, unit_mm, super::step::RESOLUTION)
}

/// [`read_mesh`], meshing a STEP or QIF part at `res`.
pub fn read_mesh_at(
    world: &dyn World,
    path: &Path,
    unit_mm: f64,
    res: super::step::Resolution,
) -> Result<RawMesh, MeshError> {
    let bytes = world
        .read(path, FileKind::Mesh)
        .map_err(|e| MeshError::Unreadable(e.0))?;
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    if ext == "stp" || ext == "step" {
        return super::step::read(&bytes, res).map(|p| p.mesh);
    }
    if ext == "qif" {
        return super::qif::read(&bytes, res).map(|p| p.mesh);
    }
    let (positions, faces, tri_group, groups) = if ext == "obj" {
        parse_obj(&bytes)?
    } else {
        parse_stl(&bytes)?
    };
    if faces.is_empty() {
        return Err(MeshError::Corrupt("it has no triangles".into()));
    }
    if faces.len() > MAX_TRIANGLES {
        return Err(MeshError::TooLarge(format!("{} triangles", faces.len())));
    }
    weld(positions, faces, tri_group, groups, unit_mm)
}

type Parsed = (Vec<[f64; 3]>, Vec<[usize; 3]>, Vec<u32>, Vec<String>);

fn parse_stl(bytes: &[u8]) -> Result<Parsed, MeshError> {
    if bytes.len() >= 84 && !bytes.starts_with(b"solid") {
        let declared = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if declared > MAX_TRIANGLES {
            return Err(MeshError::TooLarge(format!(
                "the header declares {declared} triangles"
            )));
        }
        if bytes.len() < 84 + declared * 50 {
            return Err(MeshError::Corrupt(format!(
                "the file is truncated: {declared} triangles declared, room for {}",
                (bytes.len() - 84) / 50
            )));
        }
    }
    // stl_io reads both forms; a binary file's header may start with "solid" too.
    let mut cursor = std::io::Cursor::new(bytes);
    let mesh = stl_io::read_stl(&mut cursor)
        .map_err(|e| MeshError::Corrupt(format!("not a valid STL file ({e})")))?;
    let positions = mesh
        .vertices
        .iter()
        .map(|v| [v[0] as f64, v[1] as f64, v[2] as f64])
        .collect();
    let faces: Vec<[usize; 3]> = mesh.faces.iter().map(|f| f.vertices).collect();
    let n = faces.len();
    Ok((positions, faces, vec![0; n], vec![]))
}

fn parse_obj(bytes: &[u8]) -> Result<Parsed, MeshError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        MeshError::Corrupt(format!(
            "not text: invalid UTF-8 at byte {}",
            e.valid_up_to()
        ))
    })?;
    let mut positions: Vec<[f64; 3]> = Vec::new();
    let mut faces = Vec::new();
    let mut tri_group = Vec::new();
    let mut groups: Vec<String> = Vec::new();
    let mut current: Option<u32> = None;
    for (ln, line) in text.lines().enumerate() {
        let ln = ln + 1;
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let mut c = [0.0; 3];
                for slot in &mut c {
                    let tok = it.next().ok_or_else(|| {
                        MeshError::Corrupt(format!("line {ln}: a vertex needs three coordinates"))
                    })?;
                    *slot = tok
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            MeshError::Corrupt(format!("line {ln}: `{tok}` is not a finite number"))
                        })?;
                }
                positions.push(c);
            }
            Some("g") | Some("o") => {
                let name = it.collect::<Vec<_>>().join(" ");
                let name = if name.is_empty() {
                    "default".to_string()
                } else {
                    name
                };
                current = Some(match groups.iter().position(|g| *g == name) {
                    Some(i) => i as u32,
                    None => {
                        groups.push(name);
                        groups.len() as u32 - 1
                    }
                });
            }
            Some("f") => {
                let mut idx = Vec::new();
                for tok in it {
                    let first = tok.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| {
                        MeshError::Corrupt(format!("line {ln}: `{tok}` is not a vertex index"))
                    })?;
                    let resolved = if i > 0 {
                        i - 1
                    } else {
                        positions.len() as i64 + i
                    };
                    if resolved < 0 || resolved >= positions.len() as i64 {
                        return Err(MeshError::Corrupt(format!(
                            "line {ln}: vertex index {i} is out of range (1 to {})",
                            positions.len()
                        )));
                    }
                    idx.push(resolved as usize);
                }
                if idx.len() < 3 {
                    return Err(MeshError::Corrupt(format!(
                        "line {ln}: a face needs at least three vertices"
                    )));
                }
                let g = *current.get_or_insert_with(|| {
                    groups.push("default".into());
                    groups.len() as u32 - 1
                });
                for k in 1..idx.len() - 1 {
                    faces.push([idx[0], idx[k], idx[k + 1]]);
                    tri_group.push(g);
                }
                if faces.len() > MAX_TRIANGLES {
                    return Err(MeshError::TooLarge(format!(
                        "more than {MAX_TRIANGLES} triangles"
                    )));
                }
            }
            _ => {}
        }
    }
    Ok((positions, faces, tri_group, groups))
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
