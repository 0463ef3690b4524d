//! One touch group planned (seed ch. 5.4): a roadmap over its stand-offs, the blocks in
//! tour order (datum blocks first), and its way down from and up to the clearance plane.
//!
//! **Decision: tours respect `MEAS` blocks** (`plan_group`). DMIS measures a feature's
//! points in one block, so a group's tour orders blocks (datum features first, in datum
//! order, for the alignment) and then points within each; on swiss_block and CTC 01
//! that costs about 30 % over an unconstrained tour of the same stand-offs.

use super::linearise::GroupIn;
use super::roadmap::{Disconnected, Paths, Roadmap};
use super::{no_path, polyline, tour, BlockPath, NoWay, Touch, Unreached};
use crate::access::pose::{Contact, Pose};
use crate::access::Scene;
use crate::geometry::{PartGeometry, P3};
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

/// Plans one group: roadmap, tour, entry and exit.
pub(super) fn plan_group(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    g: &GroupIn,
    standoff: f64,
) -> Result<GroupOut, Unreached> {
    let full = input.plan.motion.margin;
    let mut pose = Pose::new(scene, g.probe, g.dir, g.up, g.table)
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
    let (order, cur) = block_order(g, &owner, &paths, &lift_len);
    let first = order
        .first()
        .and_then(|(_, s)| s.first())
        .copied()
        .unwrap_or(0);
    let entry = way_down(input, g, &owner, &goals, &lifts, first)?;
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
/// plane (`lift_len`: the way up from a goal); also the last goal visited.
fn block_order(
    g: &GroupIn,
    owner: &[(usize, usize)],
    paths: &Paths,
    lift_len: &dyn Fn(usize) -> f64,
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
        None => lift_len(k),
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

/// The way down from the clearance plane to goal `first`: its way up, reversed.
fn way_down(
    input: &Input,
    g: &GroupIn,
    owner: &[(usize, usize)],
    goals: &[P3],
    lifts: &[Option<Vec<P3>>],
    first: usize,
) -> Result<Vec<P3>, Unreached> {
    // Unreachable distances mean the goals are not all connected (cannot happen after
    // a successful build) or no lift exists at all.
    let Some(entry_up) = lifts[first].clone() else {
        let (bi, ti) = owner[first];
        let b = &g.blocks[bi];
        let points = vec![b.touches[ti].point];
        return Err(no_path(input, b, g, NoWay::UpToClearance, points));
    };
    let mut entry: Vec<P3> = entry_up.into_iter().rev().collect();
    if entry.is_empty() {
        entry.push(goals[first]);
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
/// first up the probe axis; the waypoints after `x`, or `None` when every way is blocked.
/// Also returns how many segments it checked.
pub(super) fn lift(pose: &Pose, x: &P3, g: &GroupIn) -> (Option<Vec<P3>>, usize) {
    let raise = |y: &P3| y + g.up * (g.height - y.coords.dot(&g.up)).max(0.0);
    let mut tries: Vec<Vec<P3>> = vec![vec![raise(x)]];
    for h in [5.0, 20.0, 60.0] {
        let y = x + g.dir * h;
        tries.push(vec![y, raise(&y)]);
    }
    first_clear(pose, x, tries)
}

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
