//! What generate-and-test ends with when no round settles ("always an answer"): the
//! round whose plan had the fewest touches that failed validation, each of those touches
//! moved to another configuration that validates (a setup the plan already
//! has, any probe, any orientation), and the few that none takes left out with a warning
//! naming the face, the probe and what it hit. Every touch of the result validated.
//!
//! **Decision: always an answer.** `--rounds N` sets the limit (40). Each touch that
//! failed moves to the first configuration that validates in a setup the plan already
//! has (its own configurations first, then any probe and orientation); the rest are
//! left out with a warning per face (`insp::plan::points_left_out`). Only a search in
//! which no round got as far as validation ends in `insp::plan::no_convergence`.
//!
//! **Decision: a fallback is finished as a settled round is.** Its branches go back to
//! the search, which measures the datums again where they are read and asks each setup
//! as square as its touches need (`Search::finish`): a fallback plan validated at the
//! nominal pose alone once wrote no squareness in its prompts, and NIST CTC 02
//! imported stopped on a stylus collision at 2.5° in `inspc verify` with no warning.

use super::cluster::Strategy;
use super::knowledge::Knowledge;
use super::machine::Machine;
use super::solve::{self, Branch};
use super::validate::{self, Pip};
use super::{explain, Input, PlanOptions};
use crate::access::pose::Blocker;
use crate::diag::Diagnostics;
use crate::geometry::FaceId;
use std::collections::{BTreeMap, BTreeSet};

/// The most configurations tried for one left-out touch.
const TRIES_PER_POINT: usize = 240;

/// A round's plan and the touches in it that failed validation.
#[derive(Clone)]
pub(super) struct Fallback {
    /// The round's best branches.
    pub branches: Vec<Branch>,
    /// Its touches that failed validation.
    pub left: BTreeSet<Pip>,
    /// Those of them that collided only with the part turned.
    pub turned_only: BTreeSet<Pip>,
    /// Per face: touches that failed, the probe of the first and what it hit.
    pub causes: BTreeMap<FaceId, (usize, usize, Blocker)>,
    /// The clustering strategy that made the branches.
    pub strategy: Strategy,
    /// Fpoints the round's filter dropped.
    pub dropped: usize,
}

/// A fallback's branches once its failed touches moved or left out.
pub(super) struct Relocated {
    /// The branches less their failed touches, and a branch per configuration they
    /// moved to.
    pub branches: Vec<Branch>,
    /// The clustering strategy that made the branches.
    pub strategy: Strategy,
    /// Fpoints the round's filter dropped and the touches left out.
    pub dropped: usize,
    /// Touches moved, touches left out.
    pub unsettled: (usize, usize),
}

impl Fallback {
    /// The branches less their failed touches, each failed touch moved to the first
    /// configuration that validates, the rest left out and reported. `None` when
    /// nothing of the plan is left. The search makes the plan of them as of a round
    /// that settled (datums measured again, the setups' squareness). With
    /// `keep_turned_only`, a touch clear at the nominal pose that collided only with the
    /// part turned stays where it is.
    pub(crate) fn settle(
        self,
        input: &Input,
        k: &mut Knowledge,
        m: &Machine,
        (opts, rounds): (&PlanOptions, usize),
        keep_turned_only: bool,
        diags: &mut Diagnostics,
    ) -> Option<Relocated> {
        let mut branches: Vec<Branch> = Vec::new();
        // Per failed touch, its branch: the tree it came from.
        let mut origin: Vec<(Pip, usize)> = Vec::new();
        for (i, b) in self.branches.iter().enumerate() {
            let failed = |point: usize| {
                let pip = b.pip(point);
                self.left.contains(&pip) && !(keep_turned_only && self.turned_only.contains(&pip))
            };
            if let Some(tree) = solve::prune(&b.tree, &failed) {
                branches.push(Branch { tree, ..b.clone() });
            }
            let mut pts = Vec::new();
            solve::leaves(&b.tree, &mut pts);
            origin.extend(
                pts.into_iter()
                    .filter(|&p| failed(p))
                    .map(|p| (b.pip(p), i)),
            );
        }
        // The configurations the plan already uses, tried first.
        let used: BTreeSet<(usize, usize, usize)> = branches
            .iter()
            .map(|b| (b.setup, b.probe, b.orient))
            .collect();
        let setups: BTreeSet<usize> = self.branches.iter().map(|b| b.setup).collect();
        // Moved touches, grouped by the branch they came from and where they went.
        let mut moved: BTreeMap<(usize, usize, usize, usize), Vec<usize>> = BTreeMap::new();
        // Per face (and whether on the table under it): the distinct points left out,
        // and the probe and blocker to name; `left` counts the touches.
        let mut still: BTreeMap<(FaceId, bool), (BTreeSet<usize>, usize, Blocker)> =
            BTreeMap::new();
        let mut left = 0;
        let failing = origin.len();
        for (pip, from) in origin {
            match relocate(k, m, &pip, &setups, &used, &opts.bans) {
                Some((s, p, o)) => moved.entry((from, s, p, o)).or_default().push(pip.point),
                None => {
                    let face = k.points[pip.point].face;
                    let cause = self.causes.get(&face).map(|c| (c.1, c.2.clone()));
                    let (probe, blocker) = cause.unwrap_or((pip.probe, Blocker::Tip));
                    let on_table = pip.point >= k.graph_points;
                    let entry = still.entry((face, on_table));
                    entry
                        .or_insert((BTreeSet::new(), probe, blocker))
                        .0
                        .insert(pip.point);
                    left += 1;
                }
            }
        }
        for ((from, setup, probe, orient), points) in moved {
            let b = &self.branches[from];
            let others = |point: usize| !points.contains(&point);
            if let Some(tree) = solve::prune(&b.tree, &others) {
                branches.push(Branch {
                    setup,
                    up: k.setup_dir(setup),
                    probe,
                    orient,
                    tree,
                });
            }
        }
        if branches.is_empty() {
            return None;
        }
        for (&(face, on_table), (points, probe, blocker)) in &still {
            let total = if on_table {
                let alts = k.tables.iter().filter(|t| t.face == face);
                alts.map(|t| t.points.len()).sum()
            } else {
                input.graph.face_points(face).len()
            };
            explain::report_left_out(
                input,
                (face, on_table),
                (points.len(), total),
                rounds,
                (&m.probes[*probe].name, blocker),
                diags,
            );
        }
        Some(Relocated {
            branches,
            strategy: self.strategy,
            dropped: self.dropped + left,
            unsettled: (failing - left, left),
        })
    }
}

/// A configuration in one of `setups` that validates for the failed touch `pip`: the
/// plan's own configurations first, then its probes' other orientations in grid order.
fn relocate(
    k: &mut Knowledge,
    m: &Machine,
    pip: &Pip,
    setups: &BTreeSet<usize>,
    used: &BTreeSet<(usize, usize, usize)>,
    bans: &[super::Ban],
) -> Option<(usize, usize, usize)> {
    if pip.point >= k.graph_points {
        return None;
    }
    let mut candidates: Vec<(bool, usize, usize, usize)> = Vec::new();
    for &s in setups {
        let up = k.setup_dir(s);
        for p in k.probes(pip.point, s, m).ones() {
            for o in k.orientations(pip.point, p, s, &up, m).ones() {
                let same = (s, p, o) == (pip.setup, pip.probe, pip.orient);
                if !same {
                    candidates.push((!used.contains(&(s, p, o)), s, p, o));
                }
            }
        }
    }
    candidates.sort();
    let mut held_of = BTreeMap::new();
    candidates
        .into_iter()
        .take(TRIES_PER_POINT)
        .map(|(_, s, p, o)| (s, p, o))
        .find(|&(s, p, o)| {
            let up = k.setup_dir(s);
            let held = held_of.entry(s).or_insert_with(|| k.held(s).clone());
            let try_ = Pip {
                point: pip.point,
                probe: p,
                setup: s,
                orient: o,
            };
            validate::check(k, m, &try_, &up, held, bans).is_ok()
        })
}
