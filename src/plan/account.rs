//! What the plan measures: per tolerance, whether every face of its features and datum
//! features is touched with the points its fit needs or scanned, and for each one that
//! is not, the diagnostic naming the first face it misses and why.
//!
//! **Decision: unmeasured tolerances are errors** (`account`). After planning, every
//! face of every feature and datum feature of each tolerance must be touched; one that
//! is not fails the build (`insp::plan::unmeasured`) unless `--allow-unmeasured`, which
//! also plans around a face no probe inspects
//! (`insp::plan::uninspectable_face`, then a warning) instead of stopping: one code per
//! problem, at the severity the flag gives it (`Diagnostics::push_at`).

use super::errors::Shortfall;
use super::filter::min_points;
use super::{axes, scan, Hlip, Input, PlanError, PlanOptions};
use crate::diag::Diagnostics;
use crate::geometry::FaceId;
use crate::graph::{MeasurementGraph, Node};
use crate::model::FeatureId;
use miette::Severity;
use std::collections::{BTreeMap, BTreeSet};

/// Counts the tolerances the plan measures — every face of their features and datum
/// features touched or scanned — and reports each one it does not (an error unless
/// `allow_unmeasured`), naming the first face it misses and why; `uncovered` are the
/// faces the plan asked the scanner for that it cannot cover enough.
pub(super) fn account(
    input: &Input,
    mut hlip: Hlip,
    opts: &PlanOptions,
    uncovered: &[scan::Uncovered],
    diags: &mut Diagnostics,
) -> Hlip {
    let part = &input.model.parts[input.plan.part.0];
    let g = input.graph;
    let touches = touches(&hlip);
    let (faces_of, sampled) = faces_of(g);
    // A face is measured with as many points as its surface's fit needs (fewer only
    // where sampling gave it fewer).
    let mut touched: BTreeSet<FaceId> = touches
        .iter()
        .filter(|(face, pts)| {
            let sampled = g.face_points(**face).len();
            let need = min_points(input.geometry.faces[face.0].surface.kind()).min(sampled.max(1));
            pts.len() >= need
        })
        .map(|(face, _)| *face)
        .collect();
    // A scanned face is measured: the scan stage placed it only where its passes reach
    // the plan's coverage.
    touched.extend(hlip.scans.iter().map(|s| s.face));
    let mut measured = 0;
    for t in &part.tolerances {
        let features = t
            .targets
            .iter()
            .copied()
            .chain(t.datums.iter().map(|d| part.datums[d.datum.0].feature));
        let missing = features.into_iter().find_map(|f| {
            faces_of
                .get(&f)
                .into_iter()
                .flatten()
                .find(|face| !touched.contains(face))
                .map(|&face| (f, face))
        });
        let Some((f, face)) = missing else {
            measured += 1;
            continue;
        };
        let why = shortfall(input, &touches, &sampled, uncovered, f, face);
        let (tolerance, feature, face) = (
            t.name.clone(),
            part.features[f.0].name.clone(),
            input.geometry.faces[face.0].name.clone(),
        );
        // One problem, one code: an error, or a warning under `--allow-unmeasured`.
        let allowed = opts.allow_unmeasured;
        let severity = if allowed {
            Severity::Warning
        } else {
            Severity::Error
        };
        diags.push_at(
            severity,
            PlanError::Unmeasured {
                span: t.span,
                tolerance,
                feature,
                face,
                why,
                allowed,
            },
        );
    }
    hlip.summary.tolerances = (measured, part.tolerances.len());
    axes::short_axes(input, &touches, &faces_of, diags);
    hlip
}

/// Per face the distinct points the plan touches on it (or on the table under it).
fn touches(hlip: &Hlip) -> BTreeMap<FaceId, BTreeSet<usize>> {
    let mut touches: BTreeMap<FaceId, BTreeSet<usize>> = BTreeMap::new();
    for s in &hlip.setups {
        for p in &s.probes {
            for o in &p.orients {
                for i in &o.inspections {
                    for f in &i.faces {
                        touches.entry(f.face).or_default().extend(&f.points);
                    }
                }
            }
        }
    }
    touches
}

/// Per feature its faces, and the faces sampling gave points.
fn faces_of(g: &MeasurementGraph) -> (BTreeMap<FeatureId, Vec<FaceId>>, BTreeSet<FaceId>) {
    let mut faces_of: BTreeMap<FeatureId, Vec<FaceId>> = BTreeMap::new();
    let mut sampled: BTreeSet<FaceId> = BTreeSet::new();
    for (n, node) in g.nodes() {
        match node {
            Node::Feature { feature, .. } => {
                for (c, _) in g.children(n) {
                    if let Node::Face { face, .. } = g.graph[c] {
                        faces_of.entry(*feature).or_default().push(face);
                    }
                }
            }
            Node::Face { face, .. } if !g.children(n).is_empty() => {
                sampled.insert(*face);
            }
            _ => {}
        }
    }
    (faces_of, sampled)
}

/// Why face `face` of feature `f` is not measured by the plan.
fn shortfall(
    input: &Input,
    touches: &BTreeMap<FaceId, BTreeSet<usize>>,
    sampled: &BTreeSet<FaceId>,
    uncovered: &[scan::Uncovered],
    f: FeatureId,
    face: FaceId,
) -> Shortfall {
    let few = touches.get(&face).map_or(0, |p| p.len());
    if let Some(u) = uncovered.iter().find(|u| u.feature == f) {
        Shortfall::Scanner {
            best: u.best,
            other_face: (u.face != face).then(|| input.geometry.faces[u.face.0].name.clone()),
            asked: input.plan.scan_coverage,
        }
    } else if few > 0 {
        Shortfall::FewTouches(few)
    } else if sampled.contains(&face) {
        Shortfall::NoTouch
    } else {
        Shortfall::NoPoint
    }
}
