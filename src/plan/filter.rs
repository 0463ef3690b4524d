//! Which fpoints the search plans: those no probe reaches drop, and, while a face keeps
//! enough, those reached from under a twentieth of the face's median count of setups
//! (Spitz, ch. 3.6.3) — but never the end circles of a read axis ([`super::axes`]), nor
//! so many that a plane's points fall on a line. The fewest points each surface kind's
//! fit needs ([`min_points`]) is the floor everywhere in the planner.
//!
//! **Decision: filtering** (ch. 3.6.3, `filter`) drops fpoints no probe reaches, and
//! those reached from under a twentieth of the face's median setups while the face
//! keeps half its points and its minimum (3 on a plane, 5 on a cylinder, 6 on a cone, 4
//! on a sphere); a face below its minimum is `insp::plan::uninspectable_face`. The end
//! circles of a round face whose axis a tolerance or datum reads are spared
//! (`axes::end_circles`). Where points drop, or a datum is measured again on the points
//! one setup reaches (`remeasure`), a plane keeps points spread across an area
//! (`spans_area`: a second principal spread of at least 0.5 mm), never a row a plane
//! cannot be fitted to.

use super::axes;
use super::knowledge::Knowledge;
use super::machine::Machine;
use crate::geometry::{FaceId, PartGeometry, V3};
use crate::graph::MeasurementGraph;
use crate::model::SurfaceKind;
use std::collections::{BTreeMap, BTreeSet};

/// The fewest points a face of a kind needs to be fitted.
pub(crate) fn min_points(kind: SurfaceKind) -> usize {
    match kind {
        SurfaceKind::Plane => 3,
        SurfaceKind::Cylinder => 5,
        SurfaceKind::Cone => 6,
        SurfaceKind::Sphere => 4,
        SurfaceKind::Freeform => 3,
    }
}

/// Whether points spread across an area, not along a line: a plane fitted to them is
/// determined. The second principal spread must be at least [`LEAST_SPREAD`].
pub(crate) fn spans_area(points: &[&crate::geometry::P3]) -> bool {
    if points.len() < 3 {
        return false;
    }
    let n = points.len() as f64;
    let c = points.iter().fold(V3::zeros(), |s, p| s + p.coords) / n;
    let cov = points.iter().fold(nalgebra::Matrix3::zeros(), |m, p| {
        let d = p.coords - c;
        m + d * d.transpose()
    }) / n;
    let mut e: Vec<f64> = cov.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(|a, b| b.total_cmp(a));
    e[1].max(0.0).sqrt() >= LEAST_SPREAD
}

/// The least spread (mm, standard deviation across the points' main direction) a
/// plane's points keep when points drop out.
const LEAST_SPREAD: f64 = 0.5;

/// Drops fpoints no probe reaches and, while a face keeps enough, those reached from
/// under a twentieth of the face's median count of setups (ch. 3.6.3) — but not the end
/// circles of a face in `read_axes` ([`axes::end_circles`]). Returns the dropped fpoints
/// and the faces left with too few. The `skipped` faces (left out under
/// `allow_unmeasured`) drop all their points.
pub(super) fn filter(
    g: &MeasurementGraph,
    geo: &PartGeometry,
    k: &Knowledge,
    m: &Machine,
    skipped: &BTreeSet<FaceId>,
    read_axes: &BTreeSet<FaceId>,
) -> (BTreeSet<usize>, Vec<FaceId>) {
    let mut by_face: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for (i, f) in g.fpoints.iter().enumerate() {
        by_face.entry(f.face.0).or_default().push(i);
    }
    let mut dropped = BTreeSet::new();
    let mut bad = Vec::new();
    for (face, pts) in by_face {
        if skipped.contains(&FaceId(face)) {
            dropped.extend(pts);
            continue;
        }
        let on_table = k.tables.iter().any(|t| t.face.0 == face && t.alive);
        if on_table {
            // The table can stand in for the whole face where it is a datum; elsewhere
            // the unreachable points drop out when the graph is unfolded.
            continue;
        }
        let need = min_points(geo.faces[face].surface.kind()).min(pts.len());
        let sizes: Vec<usize> = pts.iter().map(|&p| k.setups(p, m).count()).collect();
        let mut keep: Vec<(usize, usize)> = pts
            .iter()
            .zip(&sizes)
            .filter(|(_, &s)| s > 0)
            .map(|(&p, &s)| (p, s))
            .collect();
        for (&p, &s) in pts.iter().zip(&sizes) {
            if s == 0 {
                dropped.insert(p);
            }
        }
        if keep.len() < need {
            bad.push(FaceId(face));
            continue;
        }
        let floor = need.max(pts.len().div_ceil(2));
        // Those left must still fix the face's surface (never a plane on a line).
        let plane = matches!(
            geo.faces[face].surface,
            crate::geometry::Surface::Plane { .. }
        );
        let mut sorted: Vec<usize> = keep.iter().map(|x| x.1).collect();
        sorted.sort_unstable();
        let median = sorted[sorted.len() / 2];
        let ends = if read_axes.contains(&FaceId(face)) {
            axes::end_circles(g, &geo.faces[face].surface, &keep)
        } else {
            BTreeSet::new()
        };
        keep.sort_by_key(|&(p, s)| (s, p));
        let mut kept: Vec<usize> = keep.iter().map(|&(p, _)| p).collect();
        for &(p, s) in &keep {
            if kept.len() <= floor || s * 20 >= median {
                break;
            }
            if ends.contains(&p) {
                continue;
            }
            if plane {
                let rest: Vec<&crate::geometry::P3> = kept
                    .iter()
                    .filter(|&&q| q != p)
                    .map(|&q| &g.fpoints[q].position)
                    .collect();
                if !spans_area(&rest) {
                    continue;
                }
            }
            kept.retain(|&q| q != p);
            dropped.insert(p);
        }
    }
    (dropped, bad)
}
