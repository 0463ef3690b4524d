//! Risers: the part stands in one of its stable poses on three pads a riser's height
//! above the table — a three-point support, the 3-2-1 locating principle's primary
//! plane (a plane rests determinately on three points; ASME Y14.5-2018 §7 builds a
//! primary datum from three datum target points the same way) — so the faces and holes
//! at its bottom are free of the table.
//!
//! **Decision: the table first.** A stable pose stands on the plan's risers only where
//! the table hides a face: one that does not lie on the table, does not face down and
//! lies wholly within [`LIFT_MM`] of it (a bottom chamfer, a datum hole 2 mm deep
//! opening into the base, a shallow step). Where nothing needs the lift the part stands
//! on the table, as an operator fetches risers only for a reason.
//!
//! **Decision: where the pads go.** Under the faces the part rests on, as far apart as
//! they allow: of pad centres on a grid over the contact next to its outline (each pad
//! wholly on the faces where they are wide enough), the triangle the part tips furthest
//! from, whose tipping angle about the centre of mass must reach
//! [`super::poses::MIN_TIP_DEG`] like any stable pose.
//! A pose whose pads cannot hold the part so stands on the table.

use crate::access::pose::Solid;
use crate::geometry::{FaceId, PartGeometry, Surface, P3, V3};
use crate::sample::{convex_hull, perpendicular_basis};

/// Three corners in the resting plane's coordinates.
type Triangle = [(f64, f64); 3];

/// How high above the table a face lies wholly, at most, for the table to hide it
/// (mm): a Ø4 mm tip's centre 2 mm up plus a motion margin leaves a face lower than
/// this no room to be touched.
pub(crate) const LIFT_MM: f64 = 5.0;

/// The most spots the pads' triangle is searched over.
const MAX_CORNERS: usize = 100;

/// Whether the table hides a face of the part resting on `resting` with `up` pointing
/// up, its lowest point at `low` along `up`.
pub(crate) fn needs_lift(g: &PartGeometry, up: &V3, low: f64, resting: &[FaceId]) -> bool {
    let mut top = vec![f64::NEG_INFINITY; g.faces.len()];
    for (t, tri) in g.triangles.iter().enumerate() {
        let f = g.tri_face[t] as usize;
        for &v in tri {
            top[f] = top[f].max(g.vertices[v as usize].coords.dot(up));
        }
    }
    g.faces.iter().enumerate().any(|(k, face)| {
        let faces_down = match face.surface {
            Surface::Plane { normal, .. } => normal.dot(up) < -0.5,
            _ => false,
        };
        face.area > 0.0
            && !faces_down
            && !resting.contains(&FaceId(k))
            && top[k] > f64::NEG_INFINITY
            && top[k] - low < LIFT_MM
    })
}

/// The three pad centres (on the resting plane, part frame) under the faces `resting`
/// of a part with centre of mass `com` resting with `up` pointing up at `low`, for pads
/// of diameter `pad`; `None` where three pads cannot hold it.
pub(crate) fn pads(
    g: &PartGeometry,
    up: &V3,
    low: f64,
    resting: &[FaceId],
    com: &P3,
    pad: f64,
    min_tip_deg: f64,
) -> Option<[P3; 3]> {
    let (e1, e2) = perpendicular_basis(up);
    let flat = |x: &V3| (x.dot(&e1), x.dot(&e2));
    let tris: Vec<Triangle> = g
        .triangles
        .iter()
        .enumerate()
        .filter(|(t, _)| resting.contains(&FaceId(g.tri_face[*t] as usize)))
        .map(|(_, tri)| tri.map(|v| flat(&g.vertices[v as usize].coords)))
        .collect();
    let edges = boundary(g, resting, &flat);
    // Pads wholly on the material where they fit, else as far in as they go.
    let mut spots = Vec::new();
    for clearance in [pad / 2.0, 0.0] {
        spots = on_material(&tris, &edges, clearance);
        if spots.len() >= 3 {
            break;
        }
    }
    let height = com.coords.dot(up) - low;
    let tri = steadiest_triangle(&outermost(&spots), flat(&com.coords), height)?;
    if super::support::tip(&tri, flat(&com.coords), height) < min_tip_deg {
        return None;
    }
    Some(tri.map(|(x, y)| P3::from(e1 * x + e2 * y + up * low)))
}

/// Grid points over the triangles `tris` that lie on one of them and at least
/// `clearance` from every edge of `edges` (the contact's outline).
fn on_material(tris: &[Triangle], edges: &[[(f64, f64); 2]], clearance: f64) -> Vec<(f64, f64)> {
    let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
    for p in tris.iter().flatten() {
        lo = (lo.0.min(p.0), lo.1.min(p.1));
        hi = (hi.0.max(p.0), hi.1.max(p.1));
    }
    let mut out = Vec::new();
    for i in 0..=GRID {
        for j in 0..=GRID {
            let (s, t) = (i as f64 / GRID as f64, j as f64 / GRID as f64);
            let q = (lo.0 + s * (hi.0 - lo.0), lo.1 + t * (hi.1 - lo.1));
            let inside = tris.iter().any(|t| in_triangle(t, q));
            if inside && edges.iter().all(|e| segment_distance(e, q) >= clearance) {
                out.push(q);
            }
        }
    }
    out
}

/// Grid lines across the contact's bounds the pads are placed on.
const GRID: usize = 24;

/// The mesh edges of the faces `resting` that bound them (one triangle of theirs on
/// either side), flattened by `flat`.
fn boundary(
    g: &PartGeometry,
    resting: &[FaceId],
    flat: &dyn Fn(&V3) -> (f64, f64),
) -> Vec<[(f64, f64); 2]> {
    let mut count: std::collections::BTreeMap<(u32, u32), usize> = Default::default();
    for (t, tri) in g.triangles.iter().enumerate() {
        if resting.contains(&FaceId(g.tri_face[t] as usize)) {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
    }
    count
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .map(|((a, b), _)| [a, b].map(|v| flat(&g.vertices[v as usize].coords)))
        .collect()
}

fn in_triangle(t: &Triangle, q: (f64, f64)) -> bool {
    let side = |a: (f64, f64), b: (f64, f64)| (b.0 - a.0) * (q.1 - a.1) - (b.1 - a.1) * (q.0 - a.0);
    let s = [side(t[0], t[1]), side(t[1], t[2]), side(t[2], t[0])];
    s.iter().all(|&x| x >= -1e-9) || s.iter().all(|&x| x <= 1e-9)
}

fn segment_distance(e: &[(f64, f64); 2], q: (f64, f64)) -> f64 {
    let (a, b) = (e[0], e[1]);
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len2 = dx * dx + dy * dy;
    let t = if len2 > 0.0 {
        (((q.0 - a.0) * dx + (q.1 - a.1) * dy) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (px, py) = (a.0 + t * dx - q.0, a.1 + t * dy - q.1);
    (px * px + py * py).sqrt()
}

/// The spots of `spots` (grid points) next to their convex hull's outline — where an
/// operator puts a riser: at a corner or along a side, never out over a gap the hull
/// spans — at most [`MAX_CORNERS`] of them, evenly in their order round the outline.
fn outermost(spots: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let hull = convex_hull(spots.to_vec());
    if hull.len() < 3 {
        return hull;
    }
    // One grid step: the spacing of the spots along either axis.
    let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
    for p in &hull {
        lo = (lo.0.min(p.0), lo.1.min(p.1));
        hi = (hi.0.max(p.0), hi.1.max(p.1));
    }
    let step = (hi.0 - lo.0).max(hi.1 - lo.1) / GRID as f64;
    let outline: Vec<[(f64, f64); 2]> = (0..hull.len())
        .map(|k| [hull[k], hull[(k + 1) % hull.len()]])
        .collect();
    let mid = hull.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let mid = (mid.0 / hull.len() as f64, mid.1 / hull.len() as f64);
    let mut rim: Vec<(f64, (f64, f64))> = spots
        .iter()
        .filter(|&&q| {
            outline
                .iter()
                .any(|e| segment_distance(e, q) <= 1.01 * step)
        })
        .map(|&q| ((q.1 - mid.1).atan2(q.0 - mid.0), q))
        .collect();
    rim.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1 .0.total_cmp(&b.1 .0)));
    let every = rim.len().div_ceil(MAX_CORNERS).max(1);
    rim.into_iter().step_by(every).map(|(_, q)| q).collect()
}

/// The triangle with corners among `pts` that the centre of mass over `c` at height `h`
/// tips furthest from (ties: the larger), counter-clockwise.
fn steadiest_triangle(pts: &[(f64, f64)], c: (f64, f64), h: f64) -> Option<Triangle> {
    let area = |a: (f64, f64), b: (f64, f64), c: (f64, f64)| {
        ((b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)) / 2.0
    };
    // (tipping angle, area, corners)
    let mut best: Option<(f64, f64, Triangle)> = None;
    let n = pts.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let mut tri = [pts[i], pts[j], pts[k]];
                let a = area(tri[0], tri[1], tri[2]);
                if a.abs() <= 1e-9 {
                    continue;
                }
                if a < 0.0 {
                    tri.swap(1, 2);
                }
                let tip = super::support::tip(&tri, c, h);
                let better = best.is_none_or(|(t, b, _)| {
                    tip > t + 1e-9 || (tip > t - 1e-9 && a.abs() > b + 1e-9)
                });
                if better {
                    best = Some((tip, a.abs(), tri));
                }
            }
        }
    }
    best.map(|(_, _, tri)| tri)
}

/// The pads as solids: cylinders of diameter `pad` from the table, `height` under the
/// part, up to just under it.
pub(crate) fn solids(centres: &[P3; 3], up: &V3, height: f64, pad: f64) -> Vec<Solid> {
    centres
        .iter()
        .map(|c| Solid::cylinder(c - up * height, *up, height - 1e-3, pad / 2.0))
        .collect()
}

/// Where the pads go, for the operator, measured from the corner of the part's
/// bounding box at its least x, y and z (`corner`), to the nearest millimetre: `pads at
/// x 28 y 10, x 68 y 30 and x 28 y 50 mm from the corner of the part at its least x, y and
/// z, along the axes of the part drawing`. The axes are said: a part turned over stands
/// with its y against the machine's, and pads read in machine axes land elsewhere (an
/// independent review of NIST FTC 08's program put one 9.8 mm from a touch on datum D).
/// The coordinate along `up` is left out where `up` is a part axis (it is the base's).
/// No apostrophe: a DMIS text cannot hold one.
pub(crate) fn words(pads: &[P3; 3], corner: &P3, up: &V3) -> String {
    let axes: Vec<(usize, &str)> = [(0, "x"), (1, "y"), (2, "z")]
        .into_iter()
        .filter(|&(k, _)| up[k].abs() < 1.0 - 1e-9)
        .collect();
    let at = |p: &P3| {
        axes.iter()
            .map(|&(k, name)| {
                let d = (p[k] - corner[k]).round() + 0.0;
                format!("{name} {}", crate::model::fmt_num(d))
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    format!(
        "pads at {}, {} and {} mm from the corner of the part at its least x, y and z, \
         along the axes of the part drawing",
        at(&pads[0]),
        at(&pads[1]),
        at(&pads[2])
    )
}
