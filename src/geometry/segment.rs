//! Faces of mesh parts: OBJ groups as given, or segmentation of an unlabelled mesh into
//! planar, cylindrical, conical, spherical and free-form patches.
//!
//! Segmentation: triangles whose normals agree within [`FLAT_DEG`] and that touch form
//! flat patches. A flat patch bordered mostly by gentle creases (under [`SMOOTH_DEG`])
//! is a facet of a curved face; neighbouring facets join into curved regions. Every
//! region is fitted ([`super::fit::best`]: the simplest surface that fits with agreeing
//! normals); a curved region no surface fits is split by growing sub-regions, facet by
//! facet, while one surface still fits them.

use super::fit::{self, Patch};
use super::{PartGeometry, RawMesh, Surface, P3, V3};

/// Normals within this angle are one flat patch (degrees).
pub(crate) const FLAT_DEG: f64 = 0.5;
/// Creases gentler than this join facets of one curved face (degrees).
pub(crate) const SMOOTH_DEG: f64 = 30.0;

fn tri_normal(m: &RawMesh, t: usize) -> (V3, f64, P3) {
    let [a, b, c] = m.triangles[t].map(|i| m.vertices[i as usize]);
    let cr = (b - a).cross(&(c - a));
    let area = cr.norm() / 2.0;
    (
        cr.try_normalize(0.0).unwrap_or_else(V3::zeros),
        area,
        P3::from((a.coords + b.coords + c.coords) / 3.0),
    )
}

/// Fits one face's surface from its triangles.
fn fit_face(m: &RawMesh, tris: &[u32], normals: &[(V3, f64, P3)], tol: f64) -> fit::Fit {
    let mut seen = vec![false; m.vertices.len()];
    let mut points = Vec::new();
    for &t in tris {
        for &i in &m.triangles[t as usize] {
            if !std::mem::replace(&mut seen[i as usize], true) {
                points.push(m.vertices[i as usize]);
            }
        }
    }
    let ns: Vec<(V3, f64, P3)> = tris.iter().map(|&t| normals[t as usize]).collect();
    fit::best(
        &Patch {
            points: &points,
            normals: &ns,
        },
        tol,
    )
}

fn fit_tolerance(m: &RawMesh) -> f64 {
    let (mut lo, mut hi) = (m.vertices[0], m.vertices[0]);
    for v in &m.vertices {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    0.01 + 1e-4 * (hi - lo).norm()
}

fn assemble(
    m: &RawMesh,
    regions: Vec<Vec<u32>>,
    names: Vec<String>,
    normals: &[(V3, f64, P3)],
) -> PartGeometry {
    let tol = fit_tolerance(m);
    let mut tri_face = vec![0u32; m.triangles.len()];
    let mut specs = Vec::new();
    let mut rms = Vec::new();
    for (k, tris) in regions.iter().enumerate() {
        for &t in tris {
            tri_face[t as usize] = k as u32;
        }
        // A STEP face's surface is the file's; a mesh face's is fitted.
        let f = match m.exact.get(k) {
            Some(surface) => fit::Fit {
                surface: surface.clone(),
                rms: 0.0,
            },
            None => fit_face(m, tris, normals, tol),
        };
        rms.push(f.rms);
        specs.push((names[k].clone(), f.surface));
    }
    let mut g = PartGeometry::new(m.vertices.clone(), m.triangles.clone(), tri_face, specs);
    for (face, r) in g.faces.iter_mut().zip(rms) {
        face.fit_rms = r;
    }
    g
}

/// Faces from the mesh's groups, in the file's order.
pub fn from_groups(m: &RawMesh) -> PartGeometry {
    let normals: Vec<_> = (0..m.triangles.len()).map(|t| tri_normal(m, t)).collect();
    let mut regions = vec![Vec::new(); m.groups.len().max(1)];
    for (t, &g) in m.tri_group.iter().enumerate() {
        regions[g as usize].push(t as u32);
    }
    let names = if m.groups.is_empty() {
        vec!["mesh".to_string()]
    } else {
        m.groups.clone()
    };
    let mut g = assemble(m, regions, names, &normals);
    g.cad = m.cad.clone();
    g
}

/// Faces found by segmentation, named `segment_1`, `segment_2`, … in the order of their
/// first triangle.
pub fn segment(m: &RawMesh) -> PartGeometry {
    let nt = m.triangles.len();
    let normals: Vec<_> = (0..nt).map(|t| tri_normal(m, t)).collect();
    let adj = Adjacency {
        normals: &normals,
        nbrs: neighbours(m),
    };
    // 1. Flat patches.
    let patches = flat_patches(&adj);
    // 2. Facets: patches bordered mostly by gentle creases.
    let facet = facets(&adj, &patches);
    // 3. Curved regions: facets joined across gentle creases.
    let regions = curved_regions(&adj, &patches, &facet);
    // 4. Fit.
    let mut faces = fitted_faces(m, &adj, &patches, regions);
    faces.sort_by_key(|f| f[0]);
    let names = (1..=faces.len()).map(|k| format!("segment_{k}")).collect();
    assemble(m, faces, names, &normals)
}

/// The triangles of a mesh as segmentation walks them: their normals (with area and
/// centroid) and, per triangle, its neighbours across manifold edges with the edge's
/// length.
struct Adjacency<'a> {
    normals: &'a [(V3, f64, P3)],
    nbrs: Vec<Vec<(u32, f64)>>,
}

impl Adjacency<'_> {
    /// The angle between two triangles' normals (degrees).
    fn angle(&self, a: u32, b: u32) -> f64 {
        self.normals[a as usize]
            .0
            .dot(&self.normals[b as usize].0)
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    }
}

/// Per triangle, its neighbours across manifold edges, with the edge length, in the
/// order of the edges' vertex pairs.
fn neighbours(m: &RawMesh) -> Vec<Vec<(u32, f64)>> {
    // Edge → triangles.
    let edge_tris = super::query::edge_triangles(&m.triangles);
    let mut nbrs: Vec<Vec<(u32, f64)>> = vec![Vec::new(); m.triangles.len()];
    let mut keys: Vec<&(u32, u32)> = edge_tris.keys().collect();
    keys.sort_unstable();
    for key in keys {
        let ts = &edge_tris[key];
        if ts.len() == 2 {
            let len = (m.vertices[key.0 as usize] - m.vertices[key.1 as usize]).norm();
            nbrs[ts[0] as usize].push((ts[1], len));
            nbrs[ts[1] as usize].push((ts[0], len));
        }
    }
    nbrs
}

/// The flat patches of a mesh: per triangle its patch, and per patch its triangles
/// (sorted), numbered in the order of their first triangle.
struct Patches {
    flat: Vec<u32>,
    patches: Vec<Vec<u32>>,
}

/// Grows flat patches from each triangle not yet in one: neighbours whose normals
/// agree with the seed's within [`FLAT_DEG`] join it.
fn flat_patches(adj: &Adjacency) -> Patches {
    let nt = adj.nbrs.len();
    let mut flat = vec![u32::MAX; nt];
    let mut patches: Vec<Vec<u32>> = Vec::new();
    for seed in 0..nt as u32 {
        if flat[seed as usize] != u32::MAX {
            continue;
        }
        let id = patches.len() as u32;
        let mut stack = vec![seed];
        flat[seed as usize] = id;
        let mut members = Vec::new();
        while let Some(t) = stack.pop() {
            members.push(t);
            for &(n, _) in &adj.nbrs[t as usize] {
                if flat[n as usize] == u32::MAX && adj.angle(seed, n) < FLAT_DEG {
                    flat[n as usize] = id;
                    stack.push(n);
                }
            }
        }
        members.sort_unstable();
        patches.push(members);
    }
    Patches { flat, patches }
}

/// Per patch, whether it is a facet of a curved face: more than half its border runs
/// along creases gentler than [`SMOOTH_DEG`].
fn facets(adj: &Adjacency, p: &Patches) -> Vec<bool> {
    let np = p.patches.len();
    let mut gentle = vec![0.0; np];
    let mut border = vec![0.0; np];
    for (t, ns) in adj.nbrs.iter().enumerate() {
        for &(n, len) in ns {
            let (pa, pb) = (p.flat[t], p.flat[n as usize]);
            if pa != pb {
                border[pa as usize] += len;
                if adj.angle(t as u32, n) < SMOOTH_DEG {
                    gentle[pa as usize] += len;
                }
            }
        }
    }
    (0..np)
        .map(|q| border[q] > 0.0 && gentle[q] > 0.5 * border[q])
        .collect()
}

/// Regions of patches: a facet with the facets it reaches across gentle creases, any
/// other patch alone.
struct Regions {
    /// Per patch, its region.
    region: Vec<u32>,
    /// Per region, its triangles.
    tris: Vec<Vec<u32>>,
    /// The patches in the order of their first triangle.
    order: Vec<usize>,
}

/// Joins facets across gentle creases into curved regions, in the order of their
/// patches' first triangles.
fn curved_regions(adj: &Adjacency, p: &Patches, facet: &[bool]) -> Regions {
    let (flat, patches) = (&p.flat, &p.patches);
    let np = patches.len();
    let mut region = vec![u32::MAX; np];
    let mut regions: Vec<Vec<u32>> = Vec::new();
    let mut order: Vec<usize> = (0..np).collect();
    order.sort_by_key(|&q| patches[q][0]);
    for &q0 in &order {
        if region[q0] != u32::MAX {
            continue;
        }
        let id = regions.len() as u32;
        region[q0] = id;
        let mut group = vec![q0];
        if facet[q0] {
            let mut stack = vec![q0];
            while let Some(q) = stack.pop() {
                for &t in &patches[q] {
                    for &(n, _) in &adj.nbrs[t as usize] {
                        let r = flat[n as usize] as usize;
                        if region[r] == u32::MAX && facet[r] && adj.angle(t, n) < SMOOTH_DEG {
                            region[r] = id;
                            group.push(r);
                            stack.push(r);
                        }
                    }
                }
            }
        }
        regions.push(
            group
                .iter()
                .flat_map(|&q| patches[q].iter().copied())
                .collect(),
        );
    }
    Regions {
        region,
        tris: regions,
        order,
    }
}

/// The faces of the regions, each fitted: a curved region no single surface fits (two
/// tangent fillets, say) is split by growing sub-regions facet by facet while one
/// surface still fits them ([`grow_by_fit`]).
fn fitted_faces(m: &RawMesh, adj: &Adjacency, p: &Patches, regions: Regions) -> Vec<Vec<u32>> {
    let tol = fit_tolerance(m);
    let mut members_of: Vec<Vec<usize>> = vec![Vec::new(); regions.tris.len()];
    for &q in &regions.order {
        members_of[regions.region[q] as usize].push(q);
    }
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for (id, tris) in regions.tris.into_iter().enumerate() {
        let members = &members_of[id];
        if members.len() > 1
            && matches!(
                fit_face(m, &tris, adj.normals, tol).surface,
                Surface::Freeform
            )
        {
            faces.extend(grow_by_fit(
                m,
                members,
                &p.patches,
                &p.flat,
                &adj.nbrs,
                adj.normals,
                tol,
            ));
        } else {
            let mut t = tris;
            t.sort_unstable();
            faces.push(t);
        }
    }
    faces
}

/// Splits a region into sub-regions that each fit one analytic surface: from the first
/// unused patch, neighbouring patches join while the fit holds.
fn grow_by_fit(
    m: &RawMesh,
    members: &[usize],
    patches: &[Vec<u32>],
    flat: &[u32],
    nbrs: &[Vec<(u32, f64)>],
    normals: &[(V3, f64, P3)],
    tol: f64,
) -> Vec<Vec<u32>> {
    let mut left: std::collections::BTreeSet<usize> = members.iter().copied().collect();
    let mut out = Vec::new();
    while let Some(&seed) = left.iter().next() {
        left.remove(&seed);
        let mut tris: Vec<u32> = patches[seed].clone();
        let mut rejected: std::collections::BTreeSet<usize> = std::collections::BTreeSet::new();
        loop {
            let candidate = tris
                .iter()
                .flat_map(|&t| {
                    nbrs[t as usize]
                        .iter()
                        .map(|&(n, _)| flat[n as usize] as usize)
                })
                .filter(|p| left.contains(p) && !rejected.contains(p))
                .min();
            let Some(p) = candidate else { break };
            let mut trial = tris.clone();
            trial.extend(&patches[p]);
            if matches!(fit_face(m, &trial, normals, tol).surface, Surface::Freeform) {
                rejected.insert(p);
            } else {
                tris = trial;
                left.remove(&p);
            }
        }
        tris.sort_unstable();
        out.push(tris);
    }
    out
}
