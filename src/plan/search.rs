//! The generate-and-test loop (Spitz, ch. 3 and 4): per round, filter the points,
//! unfold the graph, cluster it with every strategy ([`super::cluster`]), keep the best
//! plan by the hierarchy's violation counts, validate its touches with parry
//! ([`super::validate`]) — with the part turned as well as at its nominal pose — and
//! teach the knowledge base what failed, until a round validates or the fallback
//! ([`super::fallback`]) settles on the best plan found. Around it, the rounds with the
//! laser scanner: features its setups cannot cover go back to the touch probes.
//!
//! **Decision: learning.** A failed PIP first buys its point the whole probe's cones
//! (at most two points per face and probe a round: neighbours cluster together, ch.
//! 4.2); once the point has them, the failing setup is removed (its pixel and
//! neighbours for a fixed head; a 5° cap for a bent probe with no orientation left
//! there) (`learn`).
//!
//! **Decision: how plans are compared** (`score`): the hierarchy's levels first
//! (violated same-constraints, level by level), then setups, probe changes, orientation
//! changes. Preferences act inside clustering: a preferred setup is picked for a
//! cluster whenever its underlying set holds it (`solve::pick_setup`), so it is used
//! whenever a plan there costs no more than one elsewhere at every level above.
//!
//! **Decision: robust to the part set off square** (`plan_placed`). The program follows
//! the part (its alignment finds it), but an indexed probe keeps its machine direction:
//! with the part turned about the vertical the stylus stands turned in the part's
//! frame, and a stylus deep in a bore with little room beside its stem touches the
//! wall. Every touch is validated also with the part turned `validate::PLACEMENT_TURN`
//! (3°, a part set by eye) either way; a point whose configurations collide only turned
//! takes one clear at the nominal pose after `FRAGILE_AFTER` (6) tries. Where no turned
//! round settles within the rounds, the best round's touches that collided only turned
//! stay where they are (clear at the nominal pose) and the others move as the fallback
//! moves them (`finish_fallback`): on NIST CTC 02 imported the turned search was two
//! touches short at round 40 and the part was planned again from nothing at the
//! nominal pose. That holds for the first planning only: where it would leave touches
//! out, where a re-plan after the path stage's bans does not settle turned, or where
//! the path stage routes no turned plan after its re-plans (`Memo::give_up_turned`),
//! the plan is made at the nominal pose. A setup with touches clear only nearer square says by how much in its
//! prompt and warns `insp::plan::placement_sensitive` (`placement`) — whichever way
//! the plan was reached, the fallback's included (`finish`). The turned validation
//! triples the pose checks; the turned search's rounds before its first that validates
//! do not count against `--rounds`, up to as many again (`plan_touch`).

use super::account::account;
use super::cluster::{self, Strategy};
use super::errors::LastRound;
use super::explain::{face_name, report_face};
use super::fallback::Fallback;
use super::filter::filter;
use super::hlip::{assemble, Round};
use super::journal::Journal;
use super::knowledge::{self, Knowledge};
use super::machine::Machine;
use super::memo::Memo;
use super::solve::{self, Branch};
use super::validate::{self, Pip};
use super::{
    axes, dense, placement, poses, remeasure, roomy, scan, Hlip, Input, PlanError, PlanOptions,
};
use crate::diag::Diagnostics;
use crate::geometry::{FaceId, V3};
use crate::graph::Node;
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::ops::ControlFlow;

/// [`super::plan`], keeping in `memo` the cones and depth maps it computes and reusing those a
/// previous planning of the same `input` left there (the re-plans after the path stage's
/// bans). The plan is the one [`super::plan`] gives.
///
/// The features the sensor selection gave a laser scanner are left out of the touch plan
/// and scanned in its setups ([`scan`]); those the selection chose by its rule and no
/// setup lets the scanner cover go back to the touch probes, and the plan is made again
/// with them until none is sent back. A feature sent back that the scanner covers in
/// the final plan's setups is scanned after all, its touches dropped.
pub fn plan_with(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    diags: &mut Diagnostics,
) -> Option<Hlip> {
    let all = scan::lasers(input);
    let mut lasers = all.clone();
    let mut back: Vec<scan::Uncovered> = Vec::new();
    loop {
        let skip: BTreeSet<FaceId> = lasers.iter().flat_map(|l| l.faces.clone()).collect();
        let mut own = Diagnostics::new();
        let mut placed = |i: &Input, o: &PlanOptions, m: &mut Memo, d: &mut Diagnostics| {
            plan_placed(i, o, m, &skip, d)
        };
        let Some(mut hlip) = dense::plan_dense(input, opts, memo, &mut own, &mut placed) else {
            diags.extend(own);
            return None;
        };
        // The features sent back are offered to the scanner again: this plan's setups are
        // not the ones that left them short.
        let offered: Vec<scan::Laser> = all
            .iter()
            .filter(|l| {
                lasers.iter().any(|x| x.feature == l.feature)
                    || back.iter().any(|u| u.feature == l.feature)
            })
            .cloned()
            .collect();
        let uncovered = scan::plan_scans(input, &mut hlip, &offered, opts, &mut memo.scans);
        let asked = |f: crate::model::FeatureId| all.iter().any(|l| l.feature == f && l.asked);
        let to_touch: Vec<&scan::Uncovered> = uncovered
            .iter()
            .filter(|u| !asked(u.feature) && !back.iter().any(|b| b.feature == u.feature))
            .collect();
        // Until none is left: the plan made again holds other setups, where other faces
        // may fall short. Each round sends at least one feature back, so this ends.
        if !to_touch.is_empty() {
            back.extend(to_touch.into_iter().cloned());
            lasers.retain(|l| !back.iter().any(|u| u.feature == l.feature));
            continue;
        }
        // A feature sent back that the scanner covers in this plan's setups is scanned
        // there: its touches leave the plan.
        let rescanned: BTreeSet<(crate::model::FeatureId, FaceId)> = hlip
            .scans
            .iter()
            .filter(|x| back.iter().any(|u| u.feature == x.feature))
            .map(|x| (x.feature, x.face))
            .collect();
        if !rescanned.is_empty() {
            hlip.drop_touches(&rescanned);
            let head = hlip.head;
            scan::recount(&mut hlip, head);
        }
        back.retain(|u| !hlip.scans.iter().any(|x| x.feature == u.feature));
        // The best coverage any round's setups gave.
        for u in back.iter_mut() {
            if let Some(now) = uncovered.iter().find(|x| x.face == u.face) {
                u.best = u.best.max(now.best);
            }
        }
        diags.extend(own);
        hlip.to_touch = back.iter().map(|u| (u.feature, u.face, u.best)).collect();
        return Some(account(input, hlip, opts, &uncovered, diags));
    }
}

/// How many configurations of a point may collide with the part turned (and not at its
/// nominal pose) before the point takes one clear at the nominal pose alone: an
/// indexed head offers the next orientation 7.5° away, which seldom clears what the
/// first did not.
const FRAGILE_AFTER: usize = 6;

/// The touch plan of every face but `skip`, robust to the part set turned about the
/// vertical: first with every touch validated at [`validate::PLACEMENT_TURN`] either way
/// as well as at the nominal pose, but for points [`FRAGILE_AFTER`] configurations of
/// which collided only turned; where that finds no plan (the configurations it turned
/// down were a point's last), the plan validated at the nominal pose. The setups say how
/// square the operator must set the part ([`hlip::SetupNode::square_within`]) and the
/// warning `insp::plan::placement_sensitive` which touches ask it.
fn plan_placed(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    skip: &BTreeSet<FaceId>,
    diags: &mut Diagnostics,
) -> Option<Hlip> {
    if !memo.unturnable {
        let mut robust = Diagnostics::new();
        let turn = validate::PLACEMENT_TURN;
        if let Some(hlip) = plan_touch(input, opts, memo, skip, turn, &mut robust) {
            diags.extend(robust);
            return Some(hlip);
        }
        memo.unturnable = true;
    }
    plan_touch(input, opts, memo, skip, 0.0, diags)
}

/// The touch plan of every face but `skip` (those a scanner measures), each touch
/// validated with the part turned `turn` degrees either way about the vertical. With a
/// turn, a search that does not settle gives no plan (the caller plans again without).
fn plan_touch(
    input: &Input,
    opts: &PlanOptions,
    memo: &mut Memo,
    skip: &BTreeSet<FaceId>,
    turn: f64,
    diags: &mut Diagnostics,
) -> Option<Hlip> {
    let (model, plan) = (input.model, input.plan);
    let machine = Machine::new(model, plan);
    let key = (turn.to_bits(), skip.clone());
    let old: Option<SearchJournal> = memo
        .journals
        .remove(&key)
        .and_then(|j| j.downcast().ok())
        .map(|j| *j);
    let mut k = initial_knowledge(input, opts, &machine, memo);
    let mut search = Search {
        input,
        opts,
        machine: &machine,
        hierarchy: &model.hierarchies[plan.hierarchy.0],
        turn,
        validated: BTreeSet::new(),
        turned_fails: BTreeMap::new(),
        last: LastRound::NotRun,
        fallback: None,
        skipped: skip.clone(),
        read_axes: axes::axis_faces(input.graph, &model.parts[plan.part.0]),
        checked: Vec::new(),
        ran: 0,
    };
    let (mut first, mut validating) = (1, false);
    let banned =
        |(pip, up): &(Pip, V3), bans: &[super::Ban]| validate::banned(&machine, pip, up, bans);
    let mut journal = match old.and_then(|j| j.resume(&opts.bans, banned)) {
        Some((iteration, (learnt, rounds), kept)) => {
            k.resume(learnt);
            search.take_up(rounds);
            (first, validating) = (iteration, true);
            kept
        }
        None => Journal::new(&opts.bans, k.domain_bytes()),
    };
    let mut own = Diagnostics::new();
    let mut out = None;
    // In the turned search, the rounds before the first that validates (the clustering
    // still learning which orientations reach) do not count against `--rounds`, up to
    // as many again: NIST CTC 02 imported learns for 26 rounds before its first plan
    // to validate and settles, every touch clear at 3°, by round 56 — where at 40 its
    // fallback asked the operator to square the part and 8 of 20 placements crashed.
    // Not in the nominal search: there the longer run replaced a fallback that kept
    // every face measured by one that left points out (MFCAD 4-5-8-10-13-23).
    let mut last = opts.max_iterations;
    let mut iteration = first;
    let mut validated = validating;
    while iteration <= last {
        let before = validating.then(|| (k.learnt(), search.rounds()));
        let reported = !own.is_empty();
        search.ran = iteration;
        let next = search.round(&mut k, iteration, &mut own);
        let checked = std::mem::take(&mut search.checked);
        validating = !checked.is_empty();
        validated |= validating;
        if turn > 0.0 && !validated && matches!(next, ControlFlow::Continue(())) {
            last = (last + 1).min(2 * opts.max_iterations);
        }
        journal.record(iteration, before, checked, reported);
        if let ControlFlow::Break(hlip) = next {
            out = Some(hlip);
            break;
        }
        iteration += 1;
    }
    let hlip = match out {
        Some(hlip) => hlip,
        None => search.give_up(&mut k, &mut own),
    };
    k.memo().journals.insert(key, Box::new(journal));
    diags.extend(own);
    hlip
}

/// The knowledge base the search starts from: the plan's setups, the datum faces that
/// can rest on the table, and the cones' options.
fn initial_knowledge<'a>(
    input: &'a Input,
    opts: &PlanOptions,
    machine: &Machine,
    memo: &'a mut Memo,
) -> Knowledge<'a> {
    let (model, plan, g) = (input.model, input.plan, input.graph);
    let setups = poses::Setups::new(model, plan, input.geometry, input.fixtures);
    let cone_opts = crate::access::ConeOptions {
        n: opts.n,
        // The approach validated is the longer of the pre-hit and retract moves.
        retract: input.plan.motion.prehit.max(input.plan.motion.retract),
        backend: opts.backend,
        ..Default::default()
    };
    Knowledge::new(
        plan,
        machine,
        input.geometry,
        &g.fpoints,
        &datum_table_faces(g),
        setups,
        cone_opts,
        memo,
    )
}

/// The faces of datum features that can rest on the table, in graph order.
fn datum_table_faces(g: &crate::graph::MeasurementGraph) -> Vec<FaceId> {
    let mut table_faces: Vec<FaceId> = Vec::new();
    for (n, node) in g.nodes() {
        if let Node::Feature { datums, .. } = node {
            if datums.is_empty() {
                continue;
            }
            for (c, _) in g.children(n) {
                if let Node::Face {
                    face,
                    on_table: true,
                } = g.graph[c]
                {
                    if !table_faces.contains(&face) {
                        table_faces.push(face);
                    }
                }
            }
        }
    }
    table_faces
}

/// What a round of the search leads to: another round (`Continue`), or the search's
/// answer (`Break`).
type Next = ControlFlow<Option<Hlip>>;

/// The state the rounds of one search share.
struct Search<'a> {
    input: &'a Input<'a>,
    opts: &'a PlanOptions,
    machine: &'a Machine,
    hierarchy: &'a crate::model::Hierarchy,
    /// Degrees the part is turned either way when touches are validated.
    turn: f64,
    validated: BTreeSet<Pip>,
    /// Per point, the configurations that collided only with the part turned: after
    /// FRAGILE_AFTER of them the point takes one clear at the nominal pose alone.
    turned_fails: BTreeMap<usize, usize>,
    /// Why the last round failed, for the diagnostic when none settles.
    last: LastRound,
    /// The round whose plan had the fewest touches that failed validation: what the plan
    /// falls back on, less those touches, if no round settles.
    fallback: Option<Fallback>,
    /// Faces no probe inspects, left out under `allow_unmeasured`, and those a scanner
    /// measures.
    skipped: BTreeSet<FaceId>,
    /// Faces whose axis a tolerance reads ([`axes::axis_faces`]).
    read_axes: BTreeSet<FaceId>,
    /// The touches the round validated, for the journal.
    checked: Vec<(Pip, V3)>,
    /// The rounds run so far.
    ran: usize,
}

/// A search's journal: per round, what the knowledge learnt and the rounds' own state
/// at its start, and the touches (in their setups) it validated.
type SearchJournal = Journal<(knowledge::Learnt, Rounds), (Pip, V3)>;

/// What a search's rounds change of their own state: what the journal keeps beside the
/// knowledge's to resume a search from.
#[derive(Clone)]
struct Rounds {
    validated: BTreeSet<Pip>,
    turned_fails: BTreeMap<usize, usize>,
    last: LastRound,
    fallback: Option<Fallback>,
    skipped: BTreeSet<FaceId>,
}

/// The touches of a round's plan that failed validation, sorted for what follows.
struct Failures {
    /// (point, probe, setup, orientation where the head indexes), for learning.
    invalid: Vec<(usize, usize, usize, Option<usize>)>,
    /// The touches that failed.
    left: BTreeSet<Pip>,
    /// Those of them clear at the nominal pose that collided only with the part turned.
    turned_only: BTreeSet<Pip>,
    /// Per face name, the touches that failed and the first cause (probe, what it hit),
    /// for the diagnostic.
    failed: BTreeMap<String, (usize, usize, crate::access::pose::Blocker)>,
    /// Per face, the touches that failed, the probe and the first blocker.
    causes: BTreeMap<FaceId, (usize, usize, crate::access::pose::Blocker)>,
}

impl Search<'_> {
    /// The state the rounds so far left ([`Rounds`]).
    fn rounds(&self) -> Rounds {
        Rounds {
            validated: self.validated.clone(),
            turned_fails: self.turned_fails.clone(),
            last: self.last.clone(),
            fallback: self.fallback.clone(),
            skipped: self.skipped.clone(),
        }
    }

    /// Takes up the state of an earlier search's rounds.
    fn take_up(&mut self, r: Rounds) {
        self.validated = r.validated;
        self.turned_fails = r.turned_fails;
        self.last = r.last;
        self.fallback = r.fallback;
        self.skipped = r.skipped;
    }

    /// One round of generate and test.
    fn round(&mut self, k: &mut Knowledge, iteration: usize, diags: &mut Diagnostics) -> Next {
        let (input, machine) = (self.input, self.machine);
        let g = input.graph;
        let (dropped, bad) = filter(
            g,
            input.geometry,
            k,
            machine,
            &self.skipped,
            &self.read_axes,
        );
        if !bad.is_empty() {
            return self.faces_short(k, iteration, bad, diags);
        }
        let Some(root) = solve::unfold(g, k, machine, &dropped) else {
            let round = Round {
                branches: &[],
                iterations: iteration,
                dropped: dropped.len(),
                strategy: None,
                exact_budget: self.opts.exact_budget,
            };
            return ControlFlow::Break(Some(assemble(input, k, machine, &round)));
        };
        let Some(best) = self.cluster(&root, k) else {
            return ControlFlow::Continue(());
        };
        let failures = self.validate(k, &best.1);
        if failures.invalid.is_empty() {
            let hlip = self.settle(k, &root, &best, iteration, dropped.len(), diags);
            return ControlFlow::Break(Some(hlip));
        }
        if !failures.failed.is_empty() {
            self.last = LastRound::Failed(last_failures(&failures.failed, self.machine));
        }
        if self
            .fallback
            .as_ref()
            .is_none_or(|f| failures.left.len() <= f.left.len())
        {
            self.fallback = Some(Fallback {
                branches: best.1.clone(),
                left: failures.left,
                turned_only: failures.turned_only,
                causes: failures.causes,
                strategy: best.0,
                dropped: dropped.len(),
            });
        }
        learn(k, machine, failures.invalid);
        ControlFlow::Continue(())
    }

    /// Faces left with too few points: the whole probe's cones are acquired for their
    /// points before a face is blamed; those still short are reported, and without
    /// `allow_unmeasured` the search ends.
    fn faces_short(
        &mut self,
        k: &mut Knowledge,
        iteration: usize,
        bad: Vec<FaceId>,
        diags: &mut Diagnostics,
    ) -> Next {
        let (input, machine, opts) = (self.input, self.machine, self.opts);
        let g = input.graph;
        // Know the whole probe before blaming a face.
        let pairs: Vec<(usize, usize)> = bad
            .iter()
            .flat_map(|f| g.face_points(*f))
            .flat_map(|f| (0..machine.probes.len()).map(move |p| (f, p)))
            .collect();
        let before = k.acquired;
        k.acquire_many(&pairs, machine);
        if k.acquired > before && iteration < opts.max_iterations {
            let (_, bad2) = filter(
                g,
                input.geometry,
                k,
                machine,
                &self.skipped,
                &self.read_axes,
            );
            if bad2.is_empty() {
                return ControlFlow::Continue(());
            }
        }
        let (_, bad) = filter(
            g,
            input.geometry,
            k,
            machine,
            &self.skipped,
            &self.read_axes,
        );
        for &face in &bad {
            report_face(input, k, machine, face, opts.allow_unmeasured, diags);
        }
        if !opts.allow_unmeasured {
            return ControlFlow::Break(None);
        }
        // Plan the rest; the tolerances on these faces are reported unmeasured.
        self.skipped.extend(bad);
        ControlFlow::Continue(())
    }

    /// The best clustering of `root` over every strategy; when none gives a plan, what
    /// failed is learnt and the round ends.
    fn cluster(
        &mut self,
        root: &solve::Inst,
        k: &mut Knowledge,
    ) -> Option<(Strategy, Vec<Branch>)> {
        let (machine, hierarchy) = (self.machine, self.hierarchy);
        let mut results: Vec<(Strategy, Vec<Branch>)> = Vec::new();
        let mut failures = Vec::new();
        let sets = solve::setup_sets(root, k, machine);
        let trees = solve::setup_trees(root, k, hierarchy, &sets);
        for (strategy, tree) in Strategy::ALL.into_iter().zip(trees) {
            match solve::solve(root, k, machine, hierarchy, strategy, tree) {
                Ok(b) => results.push((strategy, b)),
                Err(f) => failures.extend(f),
            }
        }
        if results.is_empty() {
            self.last = LastRound::NoOrientation(failures.len());
            learn(
                k,
                machine,
                failures
                    .iter()
                    .map(|f| (f.point, f.probe, f.setup, f.orient))
                    .collect(),
            );
            return None;
        }
        let best = results
            .iter()
            .min_by_key(|(_, b)| score(b, machine, hierarchy))
            .map(|(s, b)| (*s, b.clone()))
            .expect("at least one result");
        Some(best)
    }

    /// Validates the touches of `branches` not validated before, in parallel, each at
    /// the nominal pose and (but for fragile points) with the part turned.
    fn validate(&mut self, k: &mut Knowledge, branches: &[Branch]) -> Failures {
        let (input, machine, opts) = (self.input, self.machine, self.opts);
        let mut pips: Vec<(Pip, V3)> = Vec::new();
        for b in branches {
            let mut pts = Vec::new();
            solve::leaves(&b.tree, &mut pts);
            for p in pts {
                pips.push((
                    Pip {
                        point: p,
                        probe: b.probe,
                        setup: b.setup,
                        orient: b.orient,
                    },
                    b.up,
                ));
            }
        }
        pips.sort_by_key(|(p, _)| *p);
        pips.dedup_by_key(|(p, _)| *p);
        pips.retain(|(p, _)| !self.validated.contains(p));
        self.checked.clone_from(&pips);
        let held: BTreeMap<usize, knowledge::Held> = pips
            .iter()
            .map(|(p, _)| (p.setup, k.held(p.setup).clone()))
            .collect();
        let (turn, turned_fails) = (self.turn, &self.turned_fails);
        let k = &*k;
        // (touch, result, whether it failed only with the part turned)
        let checked: Vec<(Pip, Result<(), _>, bool)> = pips
            .par_iter()
            .map(|(p, up)| {
                let tries = turned_fails.get(&p.point).copied().unwrap_or(0);
                let t = if tries < FRAGILE_AFTER { turn } else { 0.0 };
                let held = &held[&p.setup];
                match validate::check(k, machine, p, up, held, &opts.bans) {
                    Err(e) => (*p, Err(e), false),
                    Ok(()) => {
                        let turned = validate::clear_turned(k, machine, p, up, held, t);
                        let turned_only = turned.is_err();
                        (*p, turned, turned_only)
                    }
                }
            })
            .collect();
        let mut failures = Failures {
            invalid: Vec::new(),
            left: BTreeSet::new(),
            turned_only: BTreeSet::new(),
            failed: BTreeMap::new(),
            causes: BTreeMap::new(),
        };
        for (p, what, turned_only) in checked {
            if turned_only {
                *self.turned_fails.entry(p.point).or_default() += 1;
                failures.turned_only.insert(p);
            }
            match what {
                Ok(()) => {
                    self.validated.insert(p);
                }
                Err(w) => {
                    failures.left.insert(p);
                    failures
                        .causes
                        .entry(k.points[p.point].face)
                        .or_insert_with(|| (0, p.probe, w.clone()))
                        .0 += 1;
                    let e = failures
                        .failed
                        .entry(face_name(input, k, p.point))
                        .or_insert_with(|| (0, p.probe, w.clone()));
                    e.0 += 1;
                    failures.invalid.push((
                        p.point,
                        p.probe,
                        p.setup,
                        machine.head.indexable().then_some(p.orient),
                    ));
                }
            }
        }
        failures
    }

    /// The fallback's plan: its failed touches moved (with `turned`, those that failed
    /// only turned kept, and none may be left out), each of them then taken as
    /// validated at the nominal pose only, finished as a settled round's.
    fn finish_fallback(
        &mut self,
        k: &mut Knowledge,
        turned: bool,
        diags: &mut Diagnostics,
    ) -> Option<Hlip> {
        let f = self.fallback.take()?;
        let failed: Vec<usize> = f.left.iter().map(|p| p.point).collect();
        let mut own = Diagnostics::new();
        let r = f.settle(
            self.input,
            k,
            self.machine,
            (self.opts, self.ran),
            turned,
            &mut own,
        )?;
        if turned && r.unsettled.1 > 0 {
            return None;
        }
        for point in failed {
            self.turned_fails.insert(point, FRAGILE_AFTER);
        }
        let iterations = self.ran;
        let mut hlip = self.finish(k, r.branches, r.strategy, iterations, r.dropped, &mut own);
        hlip.summary.unsettled = Some(r.unsettled);
        diags.extend(own);
        Some(hlip)
    }

    /// The plan of a round whose touches all validated: the datums measured again where
    /// they are read, the setups' squareness, and why it needs more setups than the
    /// minimum.
    fn settle(
        &self,
        k: &mut Knowledge,
        root: &solve::Inst,
        best: &(Strategy, Vec<Branch>),
        iteration: usize,
        dropped: usize,
        diags: &mut Diagnostics,
    ) -> Hlip {
        debug_assert!(
            audit(k, self.machine, &best.1).is_empty(),
            "{:?}",
            audit(k, self.machine, &best.1)
        );
        let mut hlip = self.finish(k, best.1.clone(), best.0, iteration, dropped, diags);
        let machine = self.machine;
        if hlip.summary.setups > hlip.summary.min_setups.0 {
            let forcing = forcing_levels(root, k, machine, self.hierarchy, &best.1);
            hlip.summary.more_setups = Some(forcing.unwrap_or_else(|| {
                "no clustering found fewer; the minimum may need setups the hierarchy's order does not reach".into()
            }));
        }
        hlip
    }

    /// The plan of branches whose touches all validated: the datums measured again
    /// where the tolerances read against them are, and how square each setup must be
    /// set (the touches not validated turned are tried turned).
    fn finish(
        &self,
        k: &mut Knowledge,
        branches: Vec<Branch>,
        strategy: Strategy,
        iterations: usize,
        dropped: usize,
        diags: &mut Diagnostics,
    ) -> Hlip {
        let (input, machine, opts, turn) = (self.input, self.machine, self.opts, self.turn);
        let branches = roomy::roomier(k, machine, branches, turn, &opts.bans);
        let again =
            remeasure::datums_where_read(input, k, machine, &branches, turn, &opts.bans, diags);
        let branches: Vec<Branch> = branches.into_iter().chain(again).collect();
        let round = Round {
            branches: &branches,
            iterations,
            dropped,
            strategy: Some(strategy),
            exact_budget: opts.exact_budget,
        };
        let mut hlip = assemble(input, k, machine, &round);
        let turned_fails = &self.turned_fails;
        let fragile = |p: &Pip| turn == 0.0 || turned_fails.get(&p.point) >= Some(&FRAGILE_AFTER);
        placement::square_within(input, k, machine, &branches, &fragile, &mut hlip, diags);
        hlip
    }

    /// No round settled: the best plan found — the fallback's, finished as a settled
    /// round's — or the diagnostic saying why the last round failed. With a turn, in
    /// the first planning the fallback's touches that collided only turned stay (the
    /// setups then say how square to set the part), and a fallback that would leave
    /// touches out is no plan: the caller plans again at the nominal pose, where more
    /// configurations validate. A re-plan after the path stage's bans whose turned
    /// search does not settle is no plan either: a turned plan the rounds could not
    /// settle and the path stage could not route is not worth routing again (on MFCAD
    /// 1-1-5-8-13-23 sixteen such re-plans left the nominal one so many bans that it
    /// found no path).
    fn give_up(mut self, k: &mut Knowledge, diags: &mut Diagnostics) -> Option<Hlip> {
        if self.turn > 0.0 {
            let first = self.opts.bans.is_empty();
            return first
                .then(|| self.finish_fallback(k, true, diags))
                .flatten();
        }
        if let Some(hlip) = self.finish_fallback(k, false, diags) {
            return Some(hlip);
        }
        let plan = self.input.plan;
        diags.push(PlanError::NoConvergence {
            span: plan.span,
            plan: plan.name.clone(),
            iterations: self.ran,
            last: self.last,
        });
        None
    }
}

/// The faces whose touches failed in the last round, for the diagnostic: per face name,
/// how many and the first cause in words.
fn last_failures(
    failed: &BTreeMap<String, (usize, usize, crate::access::pose::Blocker)>,
    machine: &Machine,
) -> Vec<(String, usize, String, crate::access::pose::Blocker)> {
    failed
        .iter()
        .map(|(face, (n, probe, hit))| {
            let probe = machine.probes[*probe].name.clone();
            (face.clone(), *n, probe, hit.clone())
        })
        .collect()
}

/// The configurations of a plan that lie outside their point's domain (there should be
/// none): setup in the point's setups (or its table alternative), probe among those
/// reaching it there, orientation in D1′.
fn audit(k: &mut Knowledge, m: &Machine, branches: &[Branch]) -> Vec<String> {
    let mut out = Vec::new();
    for b in branches {
        let mut pts = Vec::new();
        solve::leaves(&b.tree, &mut pts);
        for f in pts {
            let ok = if f >= k.graph_points {
                k.tables
                    .iter()
                    .any(|t| t.points.contains(&f) && t.cell == b.setup && t.alive)
            } else {
                cluster::Set::has(&k.setups(f, m), b.setup)
                    && cluster::Set::has(&k.probes(f, b.setup, m), b.probe)
            };
            let o_ok = cluster::Set::has(&k.orientations(f, b.probe, b.setup, &b.up, m), b.orient);
            if !ok || !o_ok {
                out.push(format!(
                    "point {f}: setup {} probe {} orientation {}",
                    b.setup, b.probe, b.orient
                ));
            }
        }
    }
    out
}

/// What makes one plan better than another: the hierarchy's violations level by level,
/// then fewer setups, probe changes and orientation changes.
fn score(
    b: &[Branch],
    m: &Machine,
    h: &crate::model::Hierarchy,
) -> (Vec<u64>, usize, usize, usize) {
    let v = solve::violations(b, m, h);
    let setups: BTreeSet<usize> = b.iter().map(|x| x.setup).collect();
    let (pc, oc) = changes(b, m);
    (v, setups.len(), pc, oc)
}

/// Probe and orientation changes of branches taken in order.
fn changes(b: &[Branch], m: &Machine) -> (usize, usize) {
    let mut pc = 0;
    let mut oc = 0;
    for w in b.windows(2) {
        pc += usize::from(w[0].probe != w[1].probe);
        oc += usize::from(m.head.indexable() && m.grid[w[0].orient] != m.grid[w[1].orient]);
    }
    (pc, oc)
}

/// Teaches the knowledge base what failed: whole-probe cones for points known only by
/// half-lines (in parallel), removal of the configuration for the others.
fn learn(k: &mut Knowledge, m: &Machine, mut fails: Vec<(usize, usize, usize, Option<usize>)>) {
    fails.sort();
    fails.dedup();
    let full: Vec<bool> = fails
        .iter()
        .map(|&(f, p, _, _)| f >= k.graph_points || k.dom[f][p].full)
        .collect();
    // Neighbours on a face fail together and are clustered together (ch. 4.2): better
    // knowledge of a few of them usually moves the whole face, so acquire at most
    // ACQUIRE_PER_FACE points per face and probe in a round.
    let mut per_face: BTreeMap<(usize, usize), usize> = BTreeMap::new();
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for (&(f, p, _, _), &full) in fails.iter().zip(&full) {
        let n = per_face.entry((k.points[f].face.0, p)).or_default();
        if !full && *n < ACQUIRE_PER_FACE && !pairs.contains(&(f, p)) {
            *n += 1;
            pairs.push((f, p));
        }
    }
    k.acquire_many(&pairs, m);
    for (&(f, p, s, o), full) in fails.iter().zip(full) {
        if full {
            k.reject(f, p, s, o, m);
        }
    }
}

/// How many points per face and probe get the whole probe's cones in one round.
const ACQUIRE_PER_FACE: usize = 2;

/// Why a plan has more setups than the proven minimum, when the hierarchy is the cause:
/// clustered again without its per-tolerance and per-feature `same_setup` levels (the
/// `(*, *)` level kept), the plan needs fewer setups; those levels are named.
fn forcing_levels(
    root: &solve::Inst,
    k: &mut Knowledge,
    m: &Machine,
    h: &crate::model::Hierarchy,
    branches: &[Branch],
) -> Option<String> {
    use crate::model::{Group, SameVar};
    let count = |b: &[Branch]| b.iter().map(|x| x.setup).collect::<BTreeSet<_>>().len();
    let used = count(branches);
    let grouped = |l: &&crate::model::Level| l.var == SameVar::Setup && l.group != Group::All;
    let names: Vec<String> = h.levels.iter().filter(grouped).map(|l| l.text()).collect();
    if names.is_empty() {
        return None;
    }
    let mut relaxed = h.clone();
    relaxed.levels.retain(|l| !grouped(&l));
    let sets = solve::setup_sets(root, k, m);
    let trees = solve::setup_trees(root, k, &relaxed, &sets);
    let fewest = Strategy::ALL
        .into_iter()
        .zip(trees)
        .filter_map(|(s, tree)| solve::solve(root, k, m, &relaxed, s, tree).ok())
        .map(|b| count(&b))
        .min()?;
    (fewest < used).then(|| {
        format!(
            "{} {} for {used} setups; without {} {fewest} would do",
            names.join(", "),
            if names.len() == 1 { "asks" } else { "ask" },
            if names.len() == 1 { "it" } else { "them" }
        )
    })
}
