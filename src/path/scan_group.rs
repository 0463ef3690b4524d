//! One scanner group planned: its passes in order, joined by moves clear of the part.

use super::linearise::GroupIn;
use super::touch_group::{first_clear, lift, GroupOut};
use super::{no_path, NoWay, Unreached};
use crate::access::pose::Pose;
use crate::access::Scene;
use crate::geometry::P3;
use crate::plan::Input;

/// Plans one scanner group: its blocks' passes in order, each pass run the way that
/// starts nearer the scanner, joined by straight moves where they are clear, else over
/// the passes lifted along the scanner's direction, else by the clearance plane; entry
/// from and exit to the clearance plane as a touch group's. The housing keeps the plan's
/// margin along every pass and move.
pub(super) fn plan_scan_group(
    input: &Input,
    scene: &Scene,
    g: &GroupIn,
) -> Result<GroupOut, Unreached> {
    let pose = Pose::new(scene, g.probe, g.dir, g.up, g.table)
        .with_fixture(g.fixture)
        .with_margin(input.plan.motion.margin);
    let mut checks = 0;
    let mut at: Option<P3> = None;
    let mut entry: Vec<P3> = Vec::new();
    let mut blocks = Vec::new();
    for b in &g.blocks {
        let mut out = b.clone();
        for pass in &mut out.passes {
            let (mut s, mut e) = (P3::from(pass.start), P3::from(pass.end));
            if at.is_some_and(|x| (x - e).norm() < (x - s).norm()) {
                std::mem::swap(&mut s, &mut e);
            }
            checks += 1;
            if let Err(blocker) = pose.segment(&s, &e) {
                return Err(no_path(input, b, g, NoWay::AlongPass(blocker), vec![]));
            }
            let via = match at {
                None => {
                    let (up, n) = lift(&pose, &s, g);
                    checks += n;
                    let Some(up) = up else {
                        return Err(no_path(input, b, g, NoWay::DownToPass, vec![]));
                    };
                    entry = up.into_iter().rev().collect();
                    vec![]
                }
                Some(x) => match scan_move(&pose, &x, &s, g) {
                    (Some(w), n) => {
                        checks += n;
                        w
                    }
                    (None, _) => {
                        return Err(no_path(input, b, g, NoWay::BetweenPasses, vec![]));
                    }
                },
            };
            pass.via = via.iter().map(|p| p.coords.into()).collect();
            pass.start = s.coords.into();
            pass.end = e.coords.into();
            at = Some(e);
        }
        blocks.push(out);
    }
    let last = at.unwrap_or_else(P3::origin);
    let (exit, n) = lift(&pose, &last, g);
    checks += n;
    let Some(exit) = exit else {
        let b = &g.blocks[g.blocks.len() - 1];
        return Err(no_path(input, b, g, NoWay::UpFromLastPass, vec![]));
    };
    if entry.is_empty() {
        entry.push(last);
    }
    Ok(GroupOut {
        entry,
        blocks,
        exit,
        added: 0,
        checks,
    })
}

/// The waypoints from `x` to `y` (the end of one pass and the start of the next) for a
/// scanner: straight across, or up along the scanner's direction by 10, 30 or 60 mm,
/// across and down, or up to the clearance plane and down. Also how many segments it
/// checked; `None` when every way is blocked.
fn scan_move(pose: &Pose, x: &P3, y: &P3, g: &GroupIn) -> (Option<Vec<P3>>, usize) {
    let mut tries: Vec<Vec<P3>> = vec![vec![*y]];
    for h in [10.0, 30.0, 60.0] {
        tries.push(vec![x + g.dir * h, y + g.dir * h, *y]);
    }
    let raise = |p: &P3| p + g.up * (g.height - p.coords.dot(&g.up)).max(0.0);
    tries.push(vec![raise(x), raise(y), *y]);
    let (found, checks) = first_clear(pose, x, tries);
    // The pass's start is the block's own position, not a waypoint.
    (
        found.map(|mut w| {
            w.pop();
            w
        }),
        checks,
    )
}
