//! Reading STL (binary and ASCII) and OBJ meshes, and STEP and QIF parts through `step`
//! and `qif`: each file parsed and its triangles handed to [`weld`](super::weld), which
//! merges vertices and checks for a (nearly) closed solid.

use super::errors::MeshError;
use super::weld::{weld, RawMesh, MAX_TRIANGLES};
use crate::source::{FileKind, World};
use std::path::Path;

/// Reads a mesh file through the world, scaling by `unit_mm`; a STEP or QIF part is
/// meshed at the default resolution.
pub fn read_mesh(world: &dyn World, path: &Path, unit_mm: f64) -> Result<RawMesh, MeshError> {
    read_mesh_at(world, path, unit_mm, super::step::RESOLUTION)
}

/// [`read_mesh`], meshing a STEP or QIF part at `res`.
pub(crate) fn read_mesh_at(
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
