//! The planned groups joined into the LLIP: moves between a setup's groups along the
//! clearance plane, each setup's hand alignment, and the counts.

use super::linearise::GroupIn;
use super::touch_group::GroupOut;
use super::{
    align, no_path, polyline, Alignment, BlockPath, GroupPath, Llip, NoWay, PathSummary, SetupPath,
    Unreached,
};
use crate::access::pose::{Contact, Pose};
use crate::access::Scene;
use crate::geometry::{FaceId, P3, V3};
use crate::plan::{Hlip, Input};
use std::collections::BTreeMap;

/// Joins the planned groups: moves between groups of a setup run on the clearance
/// plane, each setup gets its alignment, and the counts are summed.
pub(super) fn join(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    groups: &[GroupIn],
    outs: Vec<GroupOut>,
) -> Result<Llip, Unreached> {
    let motion = input.plan.motion;
    let total = groups.len();
    let mut setups: Vec<SetupPath> = Vec::new();
    let (mut added, mut checks, mut length, mut touches) = (0, 0, 0.0, 0);
    // The previous group: its setup and where its head ends.
    let mut prev: Option<(usize, P3)> = None;
    for (g, o) in groups.iter().zip(outs) {
        added += o.added;
        checks += o.checks;
        let mut entry = o.entry;
        if let Some((s, head)) = prev {
            if s == g.setup {
                checks += 2;
                let across = sensor_change(input, scene, g, &o.blocks, head, &entry[0])?;
                entry.insert(0, across);
            }
        }
        let exit_end = o.exit.last().copied().unwrap_or(entry[0]);
        prev = Some((g.setup, exit_end + g.dir * g.probe.reach()));
        let (glen, group_touches) = travel(&entry, &o.blocks, &o.exit);
        length += glen;
        touches += group_touches;
        let gp = GroupPath {
            probe: g.slot,
            a: g.a,
            b: g.b,
            direction: g.dir.into(),
            entry: entry.iter().map(|p| p.coords.into()).collect(),
            blocks: o.blocks,
            exit: o.exit.iter().map(|p| p.coords.into()).collect(),
            records: g.records.clone(),
            length: glen,
        };
        match setups.last_mut() {
            Some(sp) if sp.setup == g.setup => sp.groups.push(gp),
            _ => setups.push(SetupPath {
                setup: g.setup,
                alignment: Alignment::default(),
                groups: vec![gp],
            }),
        }
    }
    for sp in &mut setups {
        sp.alignment = hand_alignment(input, hlip, scene, groups, sp);
    }
    let tight = tight_faces(&setups, motion.margin);
    Ok(Llip {
        motion,
        summary: PathSummary {
            groups: total,
            touches,
            length,
            added_nodes: added,
            checks,
            tight,
        },
        setups,
    })
}

/// The turn of the move from group to group of one setup after the sensor change, where
/// the head stays at `head`: the tip hangs from there, goes up or down to group `g`'s
/// height, then across to its `entry`. `blocks` are the group's, for the diagnostic when
/// something is in the way.
fn sensor_change(
    input: &Input,
    scene: &Scene,
    g: &GroupIn,
    blocks: &[BlockPath],
    head: P3,
    entry: &P3,
) -> Result<P3, Unreached> {
    let from = head - g.dir * g.probe.reach();
    let across = from + g.up * (g.height - from.coords.dot(&g.up));
    let pose = Pose::new(scene, g.probe, g.dir, g.up, g.table).with_fixture(g.fixture);
    let moves = pose
        .segment(&from, &across)
        .and_then(|_| pose.segment(&across, entry));
    if let Err(blocker) = moves {
        let b = &blocks[0];
        let points = b.touches.iter().map(|t| t.point).collect();
        return Err(no_path(input, b, g, NoWay::OnTheWay(blocker), points));
    }
    Ok(across)
}

/// A group's travel (mm) from its entry through every block's touches (in and out of
/// each stand-off) and passes to its exit, and how many touches it makes.
fn travel(entry: &[P3], blocks: &[BlockPath], exit: &[P3]) -> (f64, usize) {
    let mut glen = polyline(entry) + polyline(exit);
    let mut touches = 0;
    let mut at = entry.last().copied().unwrap_or_else(P3::origin);
    let mut first = true;
    for b in blocks {
        for t in &b.touches {
            let s = P3::from(t.standoff);
            let mut pts = vec![at];
            if !first {
                pts.extend(t.via.iter().map(|&v| P3::from(v)));
            }
            pts.push(s);
            glen += polyline(&pts);
            first = false;
            glen += 2.0 * b.standoff;
            at = s;
            touches += 1;
        }
        for p in &b.passes {
            let mut pts = vec![at];
            pts.extend(p.via.iter().map(|&v| P3::from(v)));
            pts.push(P3::from(p.start));
            pts.push(P3::from(p.end));
            glen += polyline(&pts);
            at = P3::from(p.end);
        }
    }
    (glen, touches)
}

/// A setup's hand alignment: by hand, the operator holds the probe as one of the
/// setup's groups does, or indexes the head to an orientation taken only to align.
fn hand_alignment(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    groups: &[GroupIn],
    sp: &SetupPath,
) -> Alignment {
    let motion = input.plan.motion;
    let standoff = motion.prehit.max(motion.retract);
    let own: Vec<&GroupIn> = groups.iter().filter(|g| g.setup == sp.setup).collect();
    let held: Vec<HandHeld> = own
        .iter()
        .enumerate()
        .map(|(gi, g)| (gi, None, g.dir))
        .chain(
            align_orients(input, &own)
                .into_iter()
                .map(|(gi, a, b, dir)| (gi, Some((a, b)), dir)),
        )
        .map(|(gi, orient, dir)| {
            let g = own[gi];
            HandHeld {
                pose: Pose::new(scene, g.probe, dir, g.up, g.table).with_fixture(g.fixture),
                group: gi,
                orient,
                dir,
            }
        })
        .collect();
    let clears: Vec<_> = held
        .iter()
        .map(|h| move |c: &P3, n: &V3| h.pose.approach(c, n, standoff, Contact::Part).is_ok())
        .collect();
    let touch: Vec<align::Touchable> = held
        .iter()
        .zip(&clears)
        .map(|(h, clear)| align::Touchable {
            group: h.group,
            orient: h.orient,
            probe: own[h.group].slot.0,
            dir: h.dir,
            tip: own[h.group].probe.tip_radius,
            clear,
        })
        .collect();
    align::align(input, hlip, sp, &touch)
}

/// The faces whose stand-offs keep less than `margin`, with the least kept.
fn tight_faces(setups: &[SetupPath], margin: f64) -> Vec<(FaceId, f64)> {
    let mut tight: BTreeMap<FaceId, f64> = BTreeMap::new();
    for sp in setups {
        for g in &sp.groups {
            for b in &g.blocks {
                for t in &b.touches {
                    if t.margin < margin {
                        let m = tight.entry(b.face).or_insert(t.margin);
                        *m = m.min(t.margin);
                    }
                }
            }
        }
    }
    tight.into_iter().collect()
}

/// Head orientations the operator may index to for the hand alignment beyond the
/// setup's own: per probe of the setup, the grid orientation nearest each part axis
/// (within [`ALIGN_ORIENT_CONE`]) that no group of that probe already takes and the
/// plan does not forbid. A setup
/// whose groups all look at one face from above can still be turned square by a touch
/// on a side face (3-2-1 needs faces along three axes); what the head cannot face stays
/// free and is said. `(group, A, B, direction)`: the group whose probe it is.
fn align_orients(input: &Input, groups: &[&GroupIn]) -> Vec<(usize, f64, f64, V3)> {
    let cmm = &input.model.cmms[input.plan.cmm.0];
    // The head's orientations less those the plan forbids.
    let grid: Vec<(f64, f64)> = input.model.heads[cmm.head.0]
        .orientations()
        .into_iter()
        .filter(|&(a, b)| {
            !input
                .plan
                .orientations
                .iter()
                .any(|o| matches!(o.stance, crate::model::Stance::Forbid) && o.names(a, b))
        })
        .collect();
    let mut out: Vec<(usize, f64, f64, V3)> = Vec::new();
    for (gi, g) in groups.iter().enumerate() {
        let first = groups.iter().position(|o| o.slot == g.slot) == Some(gi);
        if !first || g.blocks.iter().any(|b| !b.passes.is_empty()) {
            continue;
        }
        for k in 0..6 {
            let mut axis = V3::zeros();
            axis[k / 2] = if k % 2 == 0 { 1.0 } else { -1.0 };
            let best = grid
                .iter()
                .map(|&(a, b)| (a, b, crate::access::pose::orientation_dir(&g.up, a, b)))
                .max_by(|x, y| x.2.dot(&axis).total_cmp(&y.2.dot(&axis)));
            let Some((a, b, dir)) = best else { continue };
            let taken = |d: &V3| (d - dir).norm() < 1e-6;
            if dir.dot(&axis) < ALIGN_ORIENT_CONE.to_radians().cos()
                || groups.iter().any(|o| o.slot == g.slot && taken(&o.dir))
                || out
                    .iter()
                    .any(|o| groups[o.0].slot == g.slot && taken(&o.3))
            {
                continue;
            }
            out.push((gi, a, b, dir));
        }
    }
    out
}

/// How the operator holds the probe for a hand touch: as group `group` does, or with the
/// head indexed to `orient` ([`align_orients`]).
struct HandHeld<'a> {
    pose: Pose<'a>,
    group: usize,
    orient: Option<(f64, f64)>,
    dir: V3,
}

/// How far (degrees) an orientation [`align_orients`] offers may stand from the part
/// axis it is for.
const ALIGN_ORIENT_CONE: f64 = 20.0;
