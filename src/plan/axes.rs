//! Round faces read along their axis: which faces a tolerance or datum reads that way
//! ([`axis_faces`]), the end circles the planner's rarity rule keeps on them
//! ([`end_circles`]), and the warning where the plan reaches less of the axis than
//! sampling spread ([`short_axes`]). A tilt is read over the length between a bore's
//! extreme circles: a program that drops the deepest reads a tilt at the share of the
//! length it keeps.
//!
//! **Decision:** the rarity rule spares a round face's end circles where its axis is
//! read: a blind datum bore whose deepest circle only a probe along its axis reaches
//! read a tilt of twice its zone as under half of it without them. Points no probe
//! reaches still drop (a bore 47 mm deep for a 50 mm stylus reads its tilt over half
//! its length), and `insp::plan::short_axis` says so.

use super::errors::PlanError;
use super::Input;
use crate::diag::Diagnostics;
use crate::geometry::FaceId;
use crate::graph::MeasurementGraph;
use std::collections::{BTreeMap, BTreeSet};

/// Warns of each tolerance that reads a round face's axis ([`reads_axis`]) over less of
/// its length than sampling spread points along: points deeper in a bore than any probe
/// reaches drop out silently, and the axis fitted to the rest reads a tilt at the share
/// of the length they span (CTC 02's F33, Ø40 × 49 for a 50 mm stylus: its circles at
/// 810 and 787.5 read a tilt of twice its zone as 0.93 of it).
pub(super) fn short_axes(
    input: &Input,
    touches: &BTreeMap<FaceId, BTreeSet<usize>>,
    faces_of: &BTreeMap<crate::model::FeatureId, Vec<FaceId>>,
    diags: &mut Diagnostics,
) {
    use crate::geometry::Surface;
    let part = &input.model.parts[input.plan.part.0];
    let g = input.graph;
    for t in part.tolerances.iter().filter(|t| reads_axis(t.kind)) {
        for f in &t.targets {
            for &face in faces_of.get(f).into_iter().flatten() {
                let (origin, axis) = match &input.geometry.faces[face.0].surface {
                    Surface::Cylinder { origin, axis, .. } => (origin, axis),
                    Surface::Cone { apex, axis, .. } => (apex, axis),
                    _ => continue,
                };
                let span = |pts: &mut dyn Iterator<Item = usize>| {
                    let (lo, hi) = pts
                        .map(|p| (g.fpoints[p].position - origin).dot(axis))
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
                            (lo.min(t), hi.max(t))
                        });
                    (hi - lo).max(0.0)
                };
                let Some(touched) = touches.get(&face).filter(|t| !t.is_empty()) else {
                    continue;
                };
                let sampled = span(&mut g.face_points(face).into_iter());
                let reached = span(&mut touched.iter().copied());
                if sampled < 1e-6 || reached >= SHORT_AXIS_SHARE * sampled {
                    continue;
                }
                let mm = |x: f64| crate::model::fmt_num((x * 10.0).round() / 10.0);
                diags.push(PlanError::ShortAxis {
                    span: t.span,
                    tolerance: t.name.clone(),
                    feature: part.features[f.0].name.clone(),
                    face: input.geometry.faces[face.0].name.clone(),
                    touched: mm(reached),
                    sampled: mm(sampled),
                    share: crate::model::fmt_num((100.0 * reached / sampled).round()),
                });
            }
        }
    }
}

/// The share of the sampled length below which [`short_axes`] warns.
const SHORT_AXIS_SHARE: f64 = 0.8;

/// Whether a tolerance of this kind reads its feature's axis (orientation, location,
/// runout, coaxiality, cylindricity), not only a size.
fn reads_axis(kind: crate::model::TolKind) -> bool {
    use crate::model::TolKind as K;
    matches!(
        kind,
        K::Perpendicularity
            | K::Parallelism
            | K::Angularity
            | K::Position
            | K::Concentricity
            | K::Coaxiality
            | K::CircularRunout
            | K::TotalRunout
            | K::Cylindricity
    )
}

/// The faces whose axis a tolerance reads: those of a datum feature and of a feature
/// toleranced for orientation, location, runout or cylindricity. A size alone is read
/// from any circle; these are read along the axis.
pub(super) fn axis_faces(g: &MeasurementGraph, part: &crate::model::Part) -> BTreeSet<FaceId> {
    use crate::graph::{Edge, Node};
    let mut faces = BTreeSet::new();
    for (n, node) in g.nodes() {
        let Node::Tolerance(t) = node else { continue };
        for (f, edge) in g.children(n) {
            if edge == Edge::Datum || (edge == Edge::Target && reads_axis(part.tolerances[*t].kind))
            {
                faces.extend(
                    g.children(f)
                        .into_iter()
                        .filter_map(|(c, _)| match g.graph[c] {
                            Node::Face { face, .. } => Some(face),
                            _ => None,
                        }),
                );
            }
        }
    }
    faces
}

/// The points of a cylinder or cone at either end of the axial span of `points` (within
/// [`END_CIRCLE_BAND`]): the circles that fix its axis. A tilt is read over the length
/// between them, so the planner's rarity rule (`plan::filter`) keeps them, on the faces
/// whose axis a tolerance reads ([`axis_faces`]), while any setup reaches them: a
/// Ø12 × 25 blind bore whose deepest circle only a probe along its axis reaches read its
/// perpendicularity over 40 % of its length without it (a tilt at twice the zone read
/// in). Empty for other surfaces.
pub(super) fn end_circles(
    g: &MeasurementGraph,
    surface: &crate::geometry::Surface,
    points: &[(usize, usize)],
) -> BTreeSet<usize> {
    use crate::geometry::Surface;
    let (origin, axis) = match surface {
        Surface::Cylinder { origin, axis, .. } => (origin, axis),
        Surface::Cone { apex, axis, .. } => (apex, axis),
        _ => return BTreeSet::new(),
    };
    let at = |p: usize| (g.fpoints[p].position - origin).dot(axis);
    let (lo, hi) = points
        .iter()
        .map(|&(p, _)| at(p))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), t| {
            (lo.min(t), hi.max(t))
        });
    points
        .iter()
        .map(|&(p, _)| p)
        .filter(|&p| at(p) - lo <= END_CIRCLE_BAND || hi - at(p) <= END_CIRCLE_BAND)
        .collect()
}

/// How far along the axis (mm) a round face's point may be from its span's end and
/// still belong to that end's circle.
const END_CIRCLE_BAND: f64 = 0.5;
