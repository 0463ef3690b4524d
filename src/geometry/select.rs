//! Resolving a spec's face references against a built geometry.

use super::errors::GeometryError as E;
use super::{FaceId, PartGeometry, Surface, V3};
use crate::diag::{suggest, Diagnostics};
use crate::model::{FaceRef, FaceSource, Selector};

/// Angle within which a selector's normal or axis matches (degrees).
const SELECT_DEG: f64 = 5.0;

/// The help for an id no face has: the nearest ids the file's faces do have.
fn near_ids(ids: &[u64], id: u64) -> String {
    let mut near: Vec<u64> = ids.to_vec();
    near.sort_unstable_by_key(|&k| (k.abs_diff(id), k));
    near.truncate(3);
    near.sort_unstable();
    let list: Vec<String> = near.iter().map(|k| format!("#{k}")).collect();
    format!(
        "the nearest face ids are {}; `inspc faces FILE` lists every face with its id",
        list.join(", ")
    )
}

/// The faces a reference names, in face order; reports references that name nothing.
pub fn resolve_faces(g: &PartGeometry, r: &FaceRef, diags: &mut Diagnostics) -> Vec<FaceId> {
    let alive = |k: usize| g.faces[k].area > 0.0;
    match r {
        FaceRef::Role { source, role, span } => {
            let matching: Vec<usize> = (0..g.faces.len())
                .filter(|&k| {
                    g.roles.get(k).is_some_and(|(s, roles)| {
                        let same = match (source, s) {
                            (FaceSource::Op(a, None), FaceSource::Op(b, _)) => a == b,
                            _ => source == s,
                        };
                        same && roles.contains(role)
                    })
                })
                .collect();
            let live: Vec<FaceId> = matching
                .iter()
                .copied()
                .filter(|&k| alive(k))
                .map(FaceId)
                .collect();
            // No face at all comes from an operation that missed the part, which
            // `insp::geometry::misses_part` has reported: one error, not two.
            if let (true, Some(&k)) = (live.is_empty(), matching.first()) {
                diags.push(E::FaceGone {
                    span: *span,
                    face: g.faces[k].name.clone(),
                });
            }
            live
        }
        FaceRef::Group(name, span) => {
            let found: Vec<FaceId> = (0..g.faces.len())
                .filter(|&k| g.faces[k].name == *name && alive(k))
                .map(FaceId)
                .collect();
            if found.is_empty() {
                let help = suggest::help_for_unknown(
                    "group",
                    name,
                    g.faces.iter().map(|f| f.name.as_str()),
                );
                diags.push(E::UnknownGroup {
                    span: *span,
                    group: name.clone(),
                    help,
                });
            }
            found
        }
        FaceRef::Segment(n, span) => {
            let name = format!("segment_{n}");
            let found: Vec<FaceId> = (0..g.faces.len())
                .filter(|&k| g.faces[k].name == name)
                .map(FaceId)
                .collect();
            if found.is_empty() {
                let help = format!(
                    "the mesh has {} segments, numbered from 1; `inspc faces MESH` lists them",
                    g.faces.len()
                );
                diags.push(E::UnknownSegment {
                    span: *span,
                    segment: *n,
                    help,
                });
            }
            found
        }
        FaceRef::FileFace(kind, id, span) => {
            let ids = g.cad.as_ref().filter(|c| c.kind == *kind);
            let found: Vec<FaceId> = ids
                .map(|c| {
                    (0..c.ids.len())
                        .filter(|&k| c.ids[k] == *id && alive(k))
                        .map(FaceId)
                        .collect()
                })
                .unwrap_or_default();
            if found.is_empty() {
                let (what, help) = match (ids, &g.cad) {
                    (Some(c), _) => (
                        format!("the {} file has no face #{id}", kind.file()),
                        near_ids(&c.ids, *id),
                    ),
                    (None, Some(c)) => (
                        format!(
                            "`{}` names a {} face, but the part is read from a {} file",
                            kind.keyword(),
                            kind.file(),
                            c.kind.file()
                        ),
                        format!("write `{} {id}`", c.kind.keyword()),
                    ),
                    (None, None) => (
                        format!("`{}` names a face by its {} id, but the part is not read from a {} file", kind.keyword(), kind.file(), kind.file()),
                        "name the face by `group \"…\"`, `segment N` or `select(…)`; `inspc faces MESH` lists them".into(),
                    ),
                };
                diags.push(E::UnknownFileFace {
                    span: *span,
                    what,
                    help,
                });
            }
            found
        }
        FaceRef::Select(sel, span) => {
            let found = select(g, sel);
            if found.is_empty() {
                diags.push(E::NoMatch {
                    span: *span,
                    help: "relax a criterion, or list the faces with `inspc faces MESH`".into(),
                });
            }
            found
        }
    }
}

fn v(a: &[f64; 3]) -> V3 {
    V3::new(a[0], a[1], a[2])
}

fn select(g: &PartGeometry, s: &Selector) -> Vec<FaceId> {
    let cos = SELECT_DEG.to_radians().cos();
    let mut hits: Vec<usize> = (0..g.faces.len())
        .filter(|&k| {
            let f = &g.faces[k];
            if f.area <= 0.0 || s.surface.is_some_and(|kind| kind != f.surface.kind()) {
                return false;
            }
            if let Some(n) = s.normal {
                match &f.surface {
                    Surface::Plane { normal, .. } if normal.dot(&v(&n)) >= cos => {}
                    _ => return false,
                }
            }
            if let Some(a) = s.axis {
                match &f.surface {
                    Surface::Cylinder { axis, .. } | Surface::Cone { axis, .. }
                        if axis.dot(&v(&a)).abs() >= cos => {}
                    _ => return false,
                }
            }
            if let Some(r) = s.radius {
                let fr = match &f.surface {
                    Surface::Cylinder { radius, .. } | Surface::Sphere { radius, .. } => *radius,
                    _ => return false,
                };
                if (fr - r).abs() > 0.01 + 0.01 * r {
                    return false;
                }
            }
            true
        })
        .collect();
    if let Some((axis, highest)) = s.extreme {
        let key = |k: &usize| g.faces[*k].centroid[axis as usize];
        let best = if highest {
            hits.iter()
                .copied()
                .max_by(|a, b| key(a).total_cmp(&key(b)))
        } else {
            hits.iter()
                .copied()
                .min_by(|a, b| key(a).total_cmp(&key(b)))
        };
        hits = best.into_iter().collect();
    }
    if let Some(p) = s.nearest {
        let p = super::P3::new(p[0], p[1], p[2]);
        hits = hits
            .into_iter()
            .min_by(|a, b| {
                (g.faces[*a].centroid - p)
                    .norm()
                    .total_cmp(&(g.faces[*b].centroid - p).norm())
            })
            .into_iter()
            .collect();
    }
    hits.into_iter().map(FaceId).collect()
}
