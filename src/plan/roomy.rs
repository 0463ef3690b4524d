//! Touches a ball fits only tight, moved to a roomier ball the setup already uses.
//!
//! A ball that fits a narrow feature with hundredths to spare touches the nominal part,
//! but not a real one: a 3 mm ball on the 3.175 mm floor of NIST FTC 06's counterbores
//! stands 0.09 mm from the counterbore's wall, and that wall at its size limit, or the
//! counterbore anywhere in its position zone, or the program's frame moved by a datum
//! feature at its limit, is in the ball's way (issue 44: every approach and stand-off
//! keeps its margin at both limits of a size). An operator picks the smaller ball there.
//!
//! **Decision: roomier within the setup, after the plan settles.** The search chooses
//! probes for the fewest setups and orientations and knows nothing of room; excluding
//! tight balls from its start (tried) made it add a setup for them, and its plans
//! stopped more often in `inspc verify`. So the settled plan keeps its setups, and a
//! touch whose ball keeps less than [`ROOM`] beside it at its stand-off moves to
//! another probe of the rack whose ball keeps that room there, in the same setup: an
//! orientation the plan already has (or an earlier moved touch took) first, then any
//! the probe reaches it from — validated, and turned as the plan's others were. A
//! touch none takes stays as it is (NIST FTC 06's Ø2 ball on a 2.65 mm counterbore
//! floor: only its 30 mm extension reaches there); the path stage then keeps what
//! margin fits and says so.

use super::knowledge::Knowledge;
use super::machine::Machine;
use super::solve::{self, Branch};
use super::validate::{self, Pip};
use super::Ban;
use crate::access;
use std::collections::{BTreeMap, BTreeSet};

/// The room (mm) a ball should keep beside it at a touch's stand-off, beyond its
/// radius and short of the touched face: the ±0.1–0.25 mm size limits of drilled and
/// bored holes (the NIST test parts' counterbores hold ±0.2–0.25 mm).
pub(super) const ROOM: f64 = 0.25;

/// A configuration: setup cell, probe, grid orientation.
type Config = (usize, usize, usize);

/// The most configurations tried for one tight touch.
const TRIES_PER_POINT: usize = 120;

/// `branches` with each touch its ball fits only tight moved to a configuration of its
/// own setup whose ball has room there and whose touch validates (with the part turned
/// `turn` degrees either way where the search validated turned).
pub(super) fn roomier(
    k: &mut Knowledge,
    m: &Machine,
    branches: Vec<Branch>,
    turn: f64,
    bans: &[Ban],
) -> Vec<Branch> {
    let mut used: BTreeSet<Config> = branches
        .iter()
        .map(|b| (b.setup, b.probe, b.orient))
        .collect();
    // Per (branch, configuration moved to), the points moved.
    let mut moved: BTreeMap<(usize, Config), BTreeSet<usize>> = BTreeMap::new();
    for (i, b) in branches.iter().enumerate() {
        let mut points = Vec::new();
        solve::leaves(&b.tree, &mut points);
        for f in points {
            if f >= k.graph_points || has_room(k, m, f, b.probe) {
                continue;
            }
            if let Some(to) = move_to(k, m, &b.pip(f), &used, turn, bans) {
                used.insert(to);
                moved.entry((i, to)).or_default().insert(f);
            }
        }
    }
    if moved.is_empty() {
        return branches;
    }
    let gone: BTreeMap<usize, BTreeSet<usize>> =
        moved
            .iter()
            .fold(BTreeMap::new(), |mut acc, ((i, _), pts)| {
                acc.entry(*i).or_insert_with(BTreeSet::new).extend(pts);
                acc
            });
    let mut out: Vec<Branch> = Vec::new();
    for (i, b) in branches.iter().enumerate() {
        match gone.get(&i) {
            None => out.push(b.clone()),
            Some(pts) => {
                if let Some(tree) = solve::prune(&b.tree, &|f| pts.contains(&f)) {
                    out.push(Branch { tree, ..b.clone() });
                }
            }
        }
    }
    for ((i, (setup, probe, orient)), pts) in moved {
        let b = &branches[i];
        if let Some(tree) = solve::prune(&b.tree, &|f| !pts.contains(&f)) {
            out.push(Branch {
                setup,
                up: b.up,
                probe,
                orient,
                tree,
            });
        }
    }
    out
}

/// Whether probe `p`'s ball keeps [`ROOM`] beside it at point `f`'s stand-off (or the
/// whole back-off, where that is less).
fn has_room(k: &Knowledge, m: &Machine, f: usize, p: usize) -> bool {
    let point = &k.points[f];
    let r = m.probes[p].tip_radius;
    let travel = access::pose::backoff(&k.scene, &point.position, &point.normal, r, k.opts.retract);
    let out = point.tip_centre(r) + point.normal * travel;
    k.scene.distance(&out) >= r + ROOM.min(travel) - 1e-9
}

/// The first configuration of `pip`'s setup, for another probe whose ball has room at
/// the point, that reaches it and validates: those in `used` first (the plan's own, and
/// where earlier touches moved), then an orientation the head already turns to in the
/// setup, then the probes' other orientations in grid order.
fn move_to(
    k: &mut Knowledge,
    m: &Machine,
    pip: &Pip,
    used: &BTreeSet<Config>,
    turn: f64,
    bans: &[Ban],
) -> Option<Config> {
    let s = pip.setup;
    let up = k.setup_dir(s);
    // The head's orientations in the setup: one the head already turns to first.
    let turned: BTreeSet<usize> = used.iter().filter(|c| c.0 == s).map(|c| c.2).collect();
    let mut candidates: Vec<(bool, bool, usize, usize)> = Vec::new();
    let probes: Vec<usize> = k.probes(pip.point, s, m).ones().collect();
    for p in probes {
        if p == pip.probe || !has_room(k, m, pip.point, p) {
            continue;
        }
        for o in k.orientations(pip.point, p, s, &up, m).ones() {
            candidates.push((!used.contains(&(s, p, o)), !turned.contains(&o), p, o));
        }
    }
    candidates.sort();
    let held = k.held(s).clone();
    candidates
        .into_iter()
        .take(TRIES_PER_POINT)
        .find(|&(_, _, p, o)| {
            let to = Pip {
                point: pip.point,
                probe: p,
                setup: s,
                orient: o,
            };
            validate::check(k, m, &to, &up, &held, bans).is_ok()
                && validate::clear_turned(k, m, &to, &up, &held, turn).is_ok()
        })
        .map(|(_, _, p, o)| (s, p, o))
}
