//! The planned groups joined into the LLIP: moves between a setup's groups along the
//! clearance plane, each setup's hand alignment, and the counts.

use super::linearise::GroupIn;
use super::touch_group::GroupOut;
use super::{
    align, no_path, polyline, Alignment, GroupPath, Llip, PathSummary, SetupPath, Unreached,
};
use crate::access::pose::{Contact, Pose};
use crate::access::Scene;
use crate::geometry::{P3, V3};
use crate::plan::{Hlip, Input};

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
    let mut tight: std::collections::BTreeMap<crate::geometry::FaceId, f64> =
        std::collections::BTreeMap::new();
    // The previous group: its setup and where its head ends.
    let mut prev: Option<(usize, P3)> = None;
    for (g, o) in groups.iter().zip(outs) {
        added += o.added;
        checks += o.checks;
        let mut entry = o.entry;
        let arm = |g: &GroupIn| g.probe.reach();
        if let Some((s, head)) = prev {
            if s == g.setup {
                // After the sensor change the tip hangs from the same head position;
                // from there, up or down to this group's height, then across.
                let from = head - g.dir * arm(g);
                let across = from + g.up * (g.height - from.coords.dot(&g.up));
                let pose = Pose::new(scene, g.probe, g.dir, g.up, g.table).with_fixture(g.fixture);
                checks += 2;
                let moves = pose
                    .segment(&from, &across)
                    .and_then(|_| pose.segment(&across, &entry[0]));
                if let Err(blocker) = moves {
                    let b = &o.blocks[0];
                    let points = b.touches.iter().map(|t| t.point).collect();
                    let why = format!("{blocker} hits the part on the way");
                    return Err(no_path(input, b, g, &why, points));
                }
                entry.insert(0, across);
            }
        }
        let exit_end = o.exit.last().copied().unwrap_or(entry[0]);
        prev = Some((g.setup, exit_end + g.dir * arm(g)));
        let mut glen = polyline(&entry) + polyline(&o.exit);
        let mut at = entry.last().copied().unwrap_or_else(P3::origin);
        let mut first = true;
        for b in &o.blocks {
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
        length += glen;
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
        // By hand, the operator holds the probe as one of the setup's groups does, or
        // indexes the head to an orientation taken only to align.
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
        sp.alignment = align::align(input, hlip, sp, &touch);
        for g in &sp.groups {
            for b in &g.blocks {
                for t in &b.touches {
                    if t.margin < motion.margin {
                        let m = tight.entry(b.face).or_insert(t.margin);
                        *m = m.min(t.margin);
                    }
                }
            }
        }
    }
    let tight: Vec<(crate::geometry::FaceId, f64)> = tight.into_iter().collect();
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
