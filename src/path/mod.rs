//! Stage 9, paths (seed ch. 5): HLIP → low-level inspection plan (LLIP). The HLIP tree
//! is linearised into groups — one per (setup, probe, orientation) — and each group gets
//! a collision-free tour of its points:
//!
//! - every point is touched from its *stand-off*, the tip centre `max(prehit, retract)`
//!   back from contact along the surface normal (`r + max(prehit, retract)` from the
//!   point); the planner validated that approach, so it is not checked again
//!   (ch. 5.4.1);
//! - stand-offs are joined by a roadmap ([`roadmap`]) built with the CMM local planner
//!   and enhanced until connected; every segment is checked with parry (`Pose::segment`);
//! - the visiting order is a tour over the roadmap's shortest paths ([`tour`]), one
//!   block of points per feature face (a DMIS `MEAS` block), datum features first;
//! - a group starts and ends on the clearance plane above the part, and moves between
//!   groups run along it, high enough for the head to index.
//!
//! Each setup also gets its manual 3-2-1 alignment ([`align`], ch. 5.6). The entry point
//! is [`plan`]; a move that cannot be made collision-free is `insp::path::no_path`. The
//! files: `linearise.rs` cuts the HLIP into groups and blocks, `touch_group.rs` and
//! `scan_group.rs` plan a group, `join.rs` joins the groups into the LLIP.
//!
//! **Architecture Invariant:** the result is a function of the input alone: the roadmap
//! links nodes in index order and collects parallel checks in input order, random
//! enhancement nodes come from a fixed seed, and ties go to the lower index.
//!
//! Moves are checked by `access::Pose::segment`, each component on its own (ch. 5.4.2):
//! the tip as an exact capsule, stylus and extensions as the exact union of two rounded
//! triangles, body, head and ram as the convex hull of their two end positions (a
//! support map, `access::swept`, never a built hull); the table by the components'
//! lowest points at the ends. A group of an indexed probe first keeps its moves clear
//! with the stylus also turned as far as the setup lets the part be set off square
//! (`Pose::with_turned`, as the planner validated its touches); only where that leaves
//! goals apart are its moves those clear at the nominal pose. A scanner's group
//! (`plan_scan_group`) runs its passes in order, each from its nearer end, joined
//! straight, over the passes lifted along the scanner's direction, or by the clearance
//! plane.
//!
//! **Decision: an unreachable touch is one more failed test.** A touch the roadmap
//! cannot reach is returned, not given up on: the driver bans its configuration and
//! plans again (`paths_of` in `lib.rs`).

pub mod align;
mod errors;
mod join;
mod linearise;
mod render;
mod roadmap;
mod scan_group;
mod touch_group;
pub mod tour;

pub use align::{AlignStep, Alignment, ExtraFace};
pub(crate) use errors::{NoWay, PathError};
pub use render::json;

use crate::access::pose::{Contact, Head};
use crate::access::Scene;
use crate::diag::Diagnostics;
use crate::geometry::{FaceId, P3};
use crate::model::{DatumId, FeatureId, Motion, SlotId, TolKind, ToleranceId};
use crate::plan::{Ban, Hlip, Input, Names};
use join::join;
use linearise::{linearise, GroupIn};
use rayon::prelude::*;
use scan_group::plan_scan_group;
use touch_group::{plan_group, GroupOut};

/// The low-level inspection plan: every move of the program.
#[derive(Debug, Clone, PartialEq)]
pub struct Llip {
    /// Approach, retract, search and clearance distances.
    pub motion: Motion,
    /// The setups, in HLIP order.
    pub setups: Vec<SetupPath>,
    /// Counts.
    pub summary: PathSummary,
}

/// One setup's moves.
#[derive(Debug, Clone, PartialEq)]
pub struct SetupPath {
    /// Index into [`Hlip::setups`].
    pub setup: usize,
    /// The manual alignment after the operator places the part.
    pub alignment: Alignment,
    /// The groups, datum groups first.
    pub groups: Vec<GroupPath>,
}

impl SetupPath {
    /// The features the setup's blocks measure, in block order (repeats kept).
    pub(crate) fn features(&self) -> Vec<FeatureId> {
        self.groups
            .iter()
            .flat_map(|g| g.blocks.iter().filter_map(|b| b.feature))
            .collect()
    }
}

/// One (probe, orientation) group: its entry, blocks of touches, and exit.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupPath {
    /// The probe's slot in the rack.
    pub probe: SlotId,
    /// Head angle A (degrees).
    pub a: f64,
    /// Head angle B (degrees).
    pub b: f64,
    /// The probe direction, tip to head, part frame.
    pub direction: [f64; 3],
    /// Positions from the clearance plane down to the first stand-off (tip centre).
    pub entry: Vec<[f64; 3]>,
    /// The touches, one block per feature face.
    pub blocks: Vec<BlockPath>,
    /// Positions from the last stand-off up to the clearance plane.
    pub exit: Vec<[f64; 3]>,
    /// The tolerances whose features this group completes, in HLIP order.
    pub records: Vec<ToleranceId>,
    /// Travel in this group, touches included (mm).
    pub length: f64,
}

/// The touches on one face (a DMIS `MEAS` block).
#[derive(Debug, Clone, PartialEq)]
pub struct BlockPath {
    /// The feature.
    pub feature: Option<FeatureId>,
    /// The face (or the datum face the table stands in for).
    pub face: FaceId,
    /// The face itself, or the table it rests on.
    pub contact: Contact,
    /// The datum when the feature is a datum feature.
    pub datum: Option<DatumId>,
    /// The stand-off of its touches: `max(prehit, retract)`, or less where the space in
    /// front of the face is narrower (a small bore), so that the tip waits half-way.
    pub standoff: f64,
    /// The touches in order.
    pub touches: Vec<Touch>,
    /// A scanner's passes in order (none for a touch probe).
    pub passes: Vec<PassPath>,
}

/// One pass of a laser scanner: the middle of its depth of field moves from `start` to
/// `end` in a straight line, the stripe square to the motion.
#[derive(Debug, Clone, PartialEq)]
pub struct PassPath {
    /// Positions passed on the way from where the scanner was, before `start`.
    pub via: Vec<[f64; 3]>,
    /// Where the pass starts.
    pub start: [f64; 3],
    /// Where it ends.
    pub end: [f64; 3],
}

/// One touch.
#[derive(Debug, Clone, PartialEq)]
pub struct Touch {
    /// Index into [`Hlip::points`].
    pub point: usize,
    /// Positions passed on the way from the previous stand-off, before this one.
    pub via: Vec<[f64; 3]>,
    /// The stand-off: where the touch starts and ends.
    pub standoff: [f64; 3],
    /// The margin moves to and from the stand-off keep (mm): the plan's, or less where
    /// the feature leaves less room.
    pub margin: f64,
}

/// The LLIP in numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct PathSummary {
    /// Groups.
    pub groups: usize,
    /// Touches.
    pub touches: usize,
    /// Total travel (mm): moves and touches.
    pub length: f64,
    /// Roadmap nodes the enhancement step added.
    pub added_nodes: usize,
    /// Move segments checked with parry.
    pub checks: usize,
    /// Faces whose stand-offs keep less than the plan's margin, with the least kept.
    pub tight: Vec<(crate::geometry::FaceId, f64)>,
}

/// Plans every move of `hlip` around `scene` (the part, [`Scene::of_part`]). `None`
/// after pushing diagnostics when some move cannot be made collision-free; `bans` then
/// gets the configurations of the touches no move reached, for the planner to fail in
/// validation on another try.
pub fn plan(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    progress: &(dyn Fn(usize, usize) + Sync),
    diags: &mut Diagnostics,
    bans: &mut Vec<Ban>,
) -> Option<Llip> {
    let motion = input.plan.motion;
    let probes =
        crate::access::scan::sensor_shapes(input.model, &input.model.cmms[input.plan.cmm.0]);
    let groups = linearise(input, hlip, &probes, scene);
    let standoff = motion.prehit.max(motion.retract);
    let total = groups.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Result<GroupOut, Unreached>> = groups
        .par_iter()
        .map(|g| {
            let r = if g.blocks.iter().any(|b| !b.passes.is_empty()) {
                plan_scan_group(input, scene, g)
            } else {
                plan_group(input, hlip, scene, g, standoff)
            };
            progress(
                done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
                total,
            );
            r
        })
        .collect();
    let mut outs = Vec::new();
    for r in results {
        match r {
            Ok(o) => outs.push(o),
            Err(e) => {
                diags.push(*e.error);
                bans.extend(e.bans);
            }
        }
    }
    if outs.len() < total {
        return None;
    }
    match join(input, hlip, scene, &groups, outs) {
        Ok(llip) => {
            for sp in &llip.setups {
                self_aligned(input, sp, diags);
                if !sp.alignment.missing.is_empty() {
                    diags.push(PathError::AlignmentIncomplete {
                        span: input.plan.span,
                        plan: input.plan.name.clone(),
                        setup: sp.setup + 1,
                        missing: and_list(&sp.alignment.missing),
                    });
                }
            }
            Some(llip)
        }
        Err(e) => {
            diags.push(*e.error);
            bans.extend(e.bans);
            None
        }
    }
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [a] => a.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

/// The length of a polyline.
fn polyline(pts: &[P3]) -> f64 {
    pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// A block no move reaches: the diagnostic, and the configurations of its points that
/// the planner should not offer again.
pub(crate) struct Unreached {
    error: Box<PathError>,
    bans: Vec<Ban>,
}

/// The diagnostic for a block no move reaches; `why` says which move and what hits,
/// `points` which touches of the group (indices into [`Hlip::points`]) cannot be reached.
fn no_path(input: &Input, b: &BlockPath, g: &GroupIn, why: NoWay, points: Vec<usize>) -> Unreached {
    let names = Names::new(input.model, input.geometry, input.plan_id());
    let part = names.part();
    let feature = b.feature.map(|f| &part.features[f.0]);
    let bans = points
        .into_iter()
        .map(|point| Ban {
            point,
            probe: g.slot.0,
            up: g.up,
            dir: g.dir,
            any_dir: false,
        })
        .collect();
    let error = Box::new(PathError::NoPath {
        span: feature.map_or(part.span, |f| f.span),
        face: names.face(b.face).to_string(),
        feature: names.feature(b.feature).to_string(),
        probe: names.probe(g.slot).to_string(),
        orient: match g.probe.head {
            Head::Indexable => Some((g.a, g.b)),
            Head::Fixed => None,
        },
        why,
    });
    Unreached { error, bans }
}

/// Warns of each tolerance read against a setup's frame that one of its own features
/// fixes: the feature is one the alignment stands on, and the tolerance's datums are not
/// all measured in that setup (were they, the datum reference frame would be built from
/// them and the alignment would not matter).
fn self_aligned(input: &Input, sp: &SetupPath, diags: &mut Diagnostics) {
    let part = &input.model.parts[input.plan.part.0];
    let measured = sp.features();
    let mut warned: Vec<usize> = Vec::new();
    for step in &sp.alignment.steps {
        let Some(b) = sp
            .groups
            .get(step.group)
            .and_then(|g| g.blocks.get(step.block?))
        else {
            continue;
        };
        let (Some(f), None) = (b.feature, b.datum) else {
            continue;
        };
        for (ti, t) in part.tolerances.iter().enumerate() {
            if t.datums.is_empty() || !t.targets.contains(&f) || warned.contains(&ti) {
                continue;
            }
            // An orientation reads no origin.
            let orientation = matches!(
                t.kind,
                TolKind::Perpendicularity | TolKind::Parallelism | TolKind::Angularity
            );
            if orientation && !step.keywords.iter().any(|k| k.ends_with("DIR")) {
                continue;
            }
            if t.datums
                .iter()
                .all(|d| measured.contains(&part.datums[d.datum.0].feature))
            {
                continue;
            }
            warned.push(ti);
            diags.push(PathError::SelfAligned {
                span: t.span,
                tolerance: t.name.clone(),
                feature: part.features[f.0].name.clone(),
                setup: sp.setup + 1,
                datums: match &t.datums[..] {
                    [d] => format!("datum {} is not", part.datums[d.datum.0].name),
                    ds => format!(
                        "datums {} are not all",
                        ds.iter()
                            .map(|d| part.datums[d.datum.0].name.clone())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                },
            });
        }
    }
}
