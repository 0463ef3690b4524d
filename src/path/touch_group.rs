//! One touch group planned (seed ch. 5.4): a roadmap over its stand-offs, the blocks in
//! tour order (datum blocks first), and its way down from and up to the clearance plane.
//!
//! **Decision: tours respect `MEAS` blocks** (`plan_group`). DMIS measures a feature's
//! points in one block, so a group's tour orders blocks (datum features first, in datum
//! order, for the alignment) and then points within each; on swiss_block and CTC 01
//! that costs about 30 % over an unconstrained tour of the same stand-offs.
//!
//! **Decision: a group is entered and left where the probe can rise** (`entries`,
//! `lift`). A stand-off deep in a passage or under an overhang has no straight way up;
//! the group is entered down a neighbouring stand-off's way up and over the roadmap, as
//! it was already left. Where no stand-off rises straight or along the probe, the probe
//! first leaves the part's bounds square to the ram (16 directions), as an operator
//! backs a horizontal stylus out of a cross hole before lifting it. On the 200 MFCAD
//! blocks the two took the path stage's failures from 20 parts to 10.

use super::linearise::GroupIn;
use super::roadmap::{Disconnected, Paths, Roadmap};
use super::{no_path, polyline, tour, BlockPath, NoWay, Touch, Unreached};
use crate::access::pose::{Contact, Pose};
use crate::access::Scene;
use crate::geometry::{PartGeometry, P3, V3};
use crate::plan::{Hlip, Input};
use rayon::prelude::*;

/// A group's planned moves, before the moves between groups are joined.
pub(super) struct GroupOut {
    pub(super) entry: Vec<P3>,
    pub(super) blocks: Vec<BlockPath>,
    pub(super) exit: Vec<P3>,
    pub(super) added: usize,
    pub(super) checks: usize,
}

/// The shares of the plan's margin a stand-off tries, largest first.
const MARGIN_STEPS: [f64; 5] = [1.0, 0.5, 0.25, 0.125, 0.0];

/// Plans one group: roadmap, tour, entry and exit. Its moves first stay clear with the
/// part turned as far as the setup lets the operator set it (its prompt's
/// `square_within`, else [`crate::plan::PLACEMENT_TURN`]), as its touches were
/// validated: the alignment follows the part, an indexed stylus keeps its machine
/// direction, and a move that skims a rib with the stylus tilted meets it once the part
/// stands 2° off square (NIST FTC 06 imported from QIF, `inspc verify`). Where the
/// group has no such way, its moves are those clear at the nominal pose, as before:
/// the touches decide what a setup tolerates, and the prompt says it.
pub(super) fn plan_group(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    g: &GroupIn,
    standoff: f64,
) -> Result<GroupOut, Unreached> {
    let turn = hlip.setups[g.setup]
        .square_within
        .unwrap_or(crate::plan::PLACEMENT_TURN);
    let turned = crate::plan::turned_dirs(g.dir, &g.up, turn);
    if turned.is_empty() {
        return plan_group_posed(input, hlip, scene, g, standoff, &[]);
    }
    plan_group_posed(input, hlip, scene, g, standoff, &turned)
        .or_else(|_| plan_group_posed(input, hlip, scene, g, standoff, &[]))
}

/// [`plan_group`] with the probe also standing along each of `turned`.
fn plan_group_posed(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    g: &GroupIn,
    standoff: f64,
    turned: &[V3],
) -> Result<GroupOut, Unreached> {
    let full = input.plan.motion.margin;
    let mut pose = Pose::new(scene, g.probe, g.dir, g.up, g.table)
        .with_turned(g.probe, turned)
        .with_fixture(g.fixture)
        .with_margin(full);
    let (goals, owner) = standoffs(hlip, g);
    let margins = standoff_margins(&pose, &goals, full);
    for (x, &m) in goals.iter().zip(&margins) {
        if m < full {
            pose.set_tight(x, m);
        }
    }
    let pose = pose;
    let face_points = |goal: usize| face_samples(input.geometry, hlip, g, owner[goal], standoff);
    let mut map = Roadmap::new(
        &pose,
        goals.clone(),
        g.dir,
        &input.geometry.vertices,
        g.height,
    );
    let added = map
        .build(face_points)
        .map_err(|d| disconnected(input, g, &owner, d))?;
    let paths = map.shortest_paths();
    // The way up from each goal to the clearance plane.
    let (lifts, lift_checks): (Vec<Option<Vec<P3>>>, Vec<usize>) =
        goals.par_iter().map(|x| lift(&pose, x, g)).unzip();
    let checks = map.checks + lift_checks.iter().sum::<usize>();
    let lift_len = |k: usize| {
        lifts[k].as_ref().map_or(f64::INFINITY, |w| {
            let mut pts = vec![goals[k]];
            pts.extend(w.iter().copied());
            polyline(&pts)
        })
    };
    let entries = entries(&paths, &lift_len, goals.len());
    let entry_len = |k: usize| entries[k].1;
    let (order, cur) = block_order(g, &owner, &paths, &entry_len);
    let first = order
        .first()
        .and_then(|(_, s)| s.first())
        .copied()
        .unwrap_or(0);
    let down = Down {
        goals: &goals,
        lifts: &lifts,
        via: entries[first].0,
    };
    let entry = way_down(input, g, &owner, (&map, &paths), &down, first)?;
    let last = cur.unwrap_or(first);
    let exit = way_up((&map, &paths), &lifts, &lift_len, last, first);
    let blocks = blocks_in_order(g, order, &owner, (&map, &paths), &goals, &margins);
    Ok(GroupOut {
        entry,
        blocks,
        exit,
        added,
        checks,
    })
}

/// A group's goals, every touch's stand-off (tip centre) block by block, and the
/// (block, touch) each belongs to.
fn standoffs(hlip: &Hlip, g: &GroupIn) -> (Vec<P3>, Vec<(usize, usize)>) {
    let r = g.probe.tip_radius;
    let mut goals = Vec::new();
    let mut owner = Vec::new();
    for (bi, b) in g.blocks.iter().enumerate() {
        for (ti, t) in b.touches.iter().enumerate() {
            let p = &hlip.points[t.point];
            goals.push(p.position + p.normal * (r + b.standoff));
            owner.push((bi, ti));
        }
    }
    (goals, owner)
}

/// The margin each stand-off keeps: the largest of the plan's margin (`full`), a half, a
/// quarter, an eighth or none that its feature leaves room for; moves to and from it
/// keep that much.
fn standoff_margins(pose: &Pose, goals: &[P3], full: f64) -> Vec<f64> {
    goals
        .par_iter()
        .map(|x| {
            MARGIN_STEPS
                .iter()
                .map(|f| full * f)
                .find(|&m| pose.segment_with(x, x, m).is_ok())
                .unwrap_or(0.0)
        })
        .collect()
}

/// Points in front of the face of touch `(bi, ti)` of group `g`, `standoff` out from
/// the tip's surface: up to about 24 triangle centroids, which the roadmap tries as
/// nodes around a goal it cannot reach. None for a touch on the table.
fn face_samples(
    geometry: &PartGeometry,
    hlip: &Hlip,
    g: &GroupIn,
    (bi, ti): (usize, usize),
    standoff: f64,
) -> Vec<P3> {
    let r = g.probe.tip_radius;
    let b = &g.blocks[bi];
    if b.contact == Contact::Table {
        return vec![];
    }
    let face = hlip.points[b.touches[ti].point].face;
    let tris = &geometry.faces[face.0].triangles;
    let stride = tris.len().div_ceil(24).max(1);
    tris.iter()
        .step_by(stride)
        .filter_map(|&t| {
            let [a, b2, c] = geometry.triangles[t as usize].map(|i| geometry.vertices[i as usize]);
            let n = (b2 - a).cross(&(c - a));
            (n.norm() > 1e-12).then(|| {
                P3::from((a.coords + b2.coords + c.coords) / 3.0) + n.normalize() * (r + standoff)
            })
        })
        .collect()
}

/// The diagnostic for goals the roadmap could not connect. Every goal left out is
/// banned at once, so the planner's next try does not walk the face's unreachable
/// points one by one.
fn disconnected(
    input: &Input,
    g: &GroupIn,
    owner: &[(usize, usize)],
    d: Disconnected,
) -> Unreached {
    let (bi, _) = owner[d.goal];
    let point = |k: usize| {
        let (bi, ti) = owner[k];
        g.blocks[bi].touches[ti].point
    };
    let why = d.blocker.map_or(NoWay::RoadmapBlocked, NoWay::OnTheWay);
    no_path(
        input,
        &g.blocks[bi],
        g,
        why,
        d.stray.iter().map(|&k| point(k)).collect(),
    )
}

/// The order of a group's blocks, each with its goals in tour order: datum blocks first
/// (in datum order), then a tour over the rest, the first block from the clearance
/// plane (`entry_len`: the way down to a goal, see [`entries`]); also the last goal
/// visited.
fn block_order(
    g: &GroupIn,
    owner: &[(usize, usize)],
    paths: &Paths,
    entry_len: &dyn Fn(usize) -> f64,
) -> (Vec<(usize, Vec<usize>)>, Option<usize>) {
    // Goals of each block.
    let mut of_block: Vec<Vec<usize>> = vec![vec![]; g.blocks.len()];
    for (k, &(bi, _)) in owner.iter().enumerate() {
        of_block[bi].push(k);
    }
    let rank = |bi: usize| g.blocks[bi].datum.map(|d| d.0);
    let mut datum_blocks: Vec<usize> = (0..g.blocks.len()).filter(|&b| rank(b).is_some()).collect();
    datum_blocks.sort_by_key(|&b| (rank(b), b));
    let rest: Vec<usize> = (0..g.blocks.len()).filter(|&b| rank(b).is_none()).collect();
    let dist_from = |cur: Option<usize>, k: usize| match cur {
        None => entry_len(k),
        Some(c) => paths.d(c, k),
    };
    let mut order: Vec<(usize, Vec<usize>)> = Vec::new();
    let mut cur: Option<usize> = None;
    let visit = |bi: usize, cur: &mut Option<usize>, order: &mut Vec<(usize, Vec<usize>)>| {
        let ks = &of_block[bi];
        let m = tour::Matrix::new(
            ks.len(),
            |i, j| paths.d(ks[i], ks[j]),
            ks.iter().map(|&k| dist_from(*cur, k)).collect(),
        );
        let seq: Vec<usize> = tour::solve(&m).into_iter().map(|i| ks[i]).collect();
        *cur = seq.last().copied().or(*cur);
        order.push((bi, seq));
    };
    for &bi in &datum_blocks {
        visit(bi, &mut cur, &mut order);
    }
    if !rest.is_empty() {
        let near = |a: usize, b: usize| {
            of_block[a]
                .iter()
                .flat_map(|&x| of_block[b].iter().map(move |&y| (x, y)))
                .map(|(x, y)| paths.d(x, y))
                .fold(f64::INFINITY, f64::min)
        };
        let m = tour::Matrix::new(
            rest.len(),
            |i, j| near(rest[i], rest[j]),
            rest.iter()
                .map(|&b| {
                    of_block[b]
                        .iter()
                        .map(|&k| dist_from(cur, k))
                        .fold(f64::INFINITY, f64::min)
                })
                .collect(),
        );
        for i in tour::solve(&m) {
            visit(rest[i], &mut cur, &mut order);
        }
    }
    (order, cur)
}

/// Per goal, the goal with a way up through which it is entered soonest from the
/// clearance plane, and that way's length: down its way up, then over the roadmap. A
/// goal with its own way up is usually its own; one whose straight way up is blocked (a
/// bent stylus under an overhang, its head over a wall) is entered through a
/// neighbour's. `None` when no goal of the group has a way up.
fn entries(paths: &Paths, lift_len: &dyn Fn(usize) -> f64, n: usize) -> Vec<(Option<usize>, f64)> {
    let lifted: Vec<(usize, f64)> = (0..n)
        .map(|e| (e, lift_len(e)))
        .filter(|(_, l)| l.is_finite())
        .collect();
    (0..n)
        .into_par_iter()
        .map(|k| {
            lifted
                .iter()
                .map(|&(e, l)| (e, l + if e == k { 0.0 } else { paths.d(e, k) }))
                .filter(|(_, d)| d.is_finite())
                .min_by(|a, b| {
                    let own = |e: usize| e != k;
                    (a.1.total_cmp(&b.1))
                        .then(own(a.0).cmp(&own(b.0)))
                        .then(a.0.cmp(&b.0))
                })
                .map_or((None, f64::INFINITY), |(e, d)| (Some(e), d))
        })
        .collect()
}

/// What the way down to a group's first goal is made of.
struct Down<'a> {
    goals: &'a [P3],
    lifts: &'a [Option<Vec<P3>>],
    /// The goal whose way up is taken down ([`entries`]).
    via: Option<usize>,
}

/// The way down from the clearance plane to goal `first`: the way up of goal `via`,
/// reversed, then over the roadmap to `first`.
fn way_down(
    input: &Input,
    g: &GroupIn,
    owner: &[(usize, usize)],
    (map, paths): (&Roadmap, &Paths),
    down: &Down,
    first: usize,
) -> Result<Vec<P3>, Unreached> {
    let Some((via, up)) = down
        .via
        .and_then(|e| down.lifts[e].clone().map(|up| (e, up)))
    else {
        let (bi, ti) = owner[first];
        let b = &g.blocks[bi];
        let points = vec![b.touches[ti].point];
        return Err(no_path(input, b, g, NoWay::UpToClearance, points));
    };
    let mut entry: Vec<P3> = up.into_iter().rev().collect();
    if via != first {
        entry.push(down.goals[via]);
        entry.extend(paths.path(map, via, first));
        entry.pop();
    }
    if entry.is_empty() {
        entry.push(down.goals[first]);
    }
    Ok(entry)
}

/// The way from goal `last` up to the clearance plane: over the roadmap to the goal
/// whose way there and up is shortest (`first` when none has a way up), then up.
fn way_up(
    (map, paths): (&Roadmap, &Paths),
    lifts: &[Option<Vec<P3>>],
    lift_len: &dyn Fn(usize) -> f64,
    last: usize,
    first: usize,
) -> Vec<P3> {
    let exit_goal = (0..lifts.len())
        .filter(|&k| lifts[k].is_some())
        .min_by(|&a, &b| {
            (paths.d(last, a) + lift_len(a))
                .total_cmp(&(paths.d(last, b) + lift_len(b)))
                .then(a.cmp(&b))
        })
        .unwrap_or(first);
    let mut exit = paths.path(map, last, exit_goal);
    exit.extend(lifts[exit_goal].clone().unwrap_or_default());
    exit
}

/// The blocks in tour order, each touch with its way from the one before over the
/// roadmap, its stand-off and the margin it keeps.
fn blocks_in_order(
    g: &GroupIn,
    order: Vec<(usize, Vec<usize>)>,
    owner: &[(usize, usize)],
    (map, paths): (&Roadmap, &Paths),
    goals: &[P3],
    margins: &[f64],
) -> Vec<BlockPath> {
    let mut blocks = Vec::new();
    let mut prev: Option<usize> = None;
    for (bi, seq) in order {
        let mut b = g.blocks[bi].clone();
        b.touches = seq
            .iter()
            .map(|&k| {
                let (_, ti) = owner[k];
                let mut via: Vec<[f64; 3]> = match prev {
                    Some(p) => paths
                        .path(map, p, k)
                        .iter()
                        .map(|x| x.coords.into())
                        .collect(),
                    None => vec![],
                };
                via.pop();
                prev = Some(k);
                Touch {
                    point: g.blocks[bi].touches[ti].point,
                    via,
                    standoff: goals[k].coords.into(),
                    margin: margins[k],
                }
            })
            .collect();
        blocks.push(b);
    }
    blocks
}

/// The way from stand-off `x` up to the clearance plane: straight up the ram axis, or
/// first up the probe axis, or — from a passage or under an overhang — first out of the
/// part's bounds along one of its axes square to the ram, the probe as it stands
/// (as an operator backs a horizontal stylus out of a cross hole before lifting). The
/// waypoints after `x`, or `None` when every way is blocked; also how many segments it
/// checked.
pub(super) fn lift(pose: &Pose, x: &P3, g: &GroupIn) -> (Option<Vec<P3>>, usize) {
    let raise = |y: &P3| y + g.up * (g.height - y.coords.dot(&g.up)).max(0.0);
    let mut tries: Vec<Vec<P3>> = vec![vec![raise(x)]];
    for h in [5.0, 20.0, 60.0] {
        let y = x + g.dir * h;
        tries.push(vec![y, raise(&y)]);
    }
    let (found, checks) = first_clear(pose, x, tries);
    if found.is_some() {
        return (found, checks);
    }
    let (more, more_checks) = first_clear(pose, x, sideways(pose, x, g, &raise));
    (more, checks + more_checks)
}

/// Ways up that first leave the part's bounds square to the ram: in each of
/// [`SIDEWAYS`] directions around it, to [`SIDEWAYS_CLEAR`] past the bounds, then up.
fn sideways(pose: &Pose, x: &P3, g: &GroupIn, raise: &dyn Fn(&P3) -> P3) -> Vec<Vec<P3>> {
    let Some(mesh) = pose.scene().mesh() else {
        return vec![];
    };
    let aabb = mesh.local_aabb();
    let (e1, e2) = crate::sample::perpendicular_basis(&g.up);
    (0..SIDEWAYS)
        .filter_map(|k| {
            let t = std::f64::consts::TAU * k as f64 / SIDEWAYS as f64;
            let d = e1 * t.cos() + e2 * t.sin();
            let out = crate::geometry::box_exit(&aabb.mins, &aabb.maxs, x, &d)?;
            let y = x + d * (out.max(0.0) + SIDEWAYS_CLEAR);
            Some(vec![y, raise(&y)])
        })
        .collect()
}

/// How many directions square to the ram a sideways way up tries.
const SIDEWAYS: usize = 16;

/// How far past the part's bounds a sideways way up goes before it rises (mm).
const SIDEWAYS_CLEAR: f64 = 10.0;

/// The first of `tries` (waypoints after `x`) along which `pose` moves clear, and how
/// many segments were checked to find it.
pub(super) fn first_clear(pose: &Pose, x: &P3, tries: Vec<Vec<P3>>) -> (Option<Vec<P3>>, usize) {
    let mut checks = 0;
    let found = tries.into_iter().find(|w| {
        let mut from = *x;
        w.iter().all(|p| {
            checks += 1;
            let ok = pose.segment(&from, p).is_ok();
            from = *p;
            ok
        })
    });
    (found, checks)
}
