//! The HLIP linearised (seed ch. 5): one group per (setup, probe, orientation), each with
//! its blocks of touches — one per feature face — and their stand-offs, datum groups
//! first within a setup.
//!
//! **Decision: stand-offs follow the feature** (`outlast`). In front of a narrow bore a
//! block's stand-off shrinks to half the free space (the bore's axis). Where a
//! feature's tolerances let its surface stand proud by more than the stand-off leaves —
//! twice the largest excursion they allow (half a profile zone, a position zone's
//! radius, a form or orientation zone, a size's farther limit) plus the motion margin —
//! the block's stand-off grows to that, when the longer approach validates and the
//! space in front allows: a part out by as much again as its tolerance reads OUT
//! instead of stopping the run (CTC 02's 2.5 mm profiles).

use super::{BlockPath, PassPath, Touch};
use crate::access::pose::{Contact, Pose};
use crate::access::{ProbeShape, Scene};
use crate::geometry::V3;
use crate::model::{DatumId, FeatureId, SlotId, TolKind, ToleranceId};
use crate::plan::{FaceVisit, Hlip, Input, Inspection, OrientNode, SetupNode};

/// Everything a group needs while it is planned.
pub(super) struct GroupIn<'a> {
    pub(super) setup: usize,
    pub(super) probe: &'a ProbeShape,
    pub(super) slot: SlotId,
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) dir: V3,
    pub(super) up: V3,
    pub(super) table: f64,
    /// The fixture's solids.
    pub(super) fixture: &'a [crate::access::pose::Solid],
    pub(super) height: f64,
    pub(super) blocks: Vec<BlockPath>,
    pub(super) records: Vec<ToleranceId>,
    pub(super) has_datum: bool,
}

/// Linearises the HLIP into groups — one per (setup, probe, orientation) — with their
/// blocks, datum groups first within a setup.
pub(super) fn linearise<'a>(
    input: &Input,
    hlip: &'a Hlip,
    probes: &'a [ProbeShape],
    scene: &Scene,
) -> Vec<GroupIn<'a>> {
    let datum_of = datum_of_features(input);
    let mut groups: Vec<GroupIn> = Vec::new();
    for (si, s) in hlip.setups.iter().enumerate() {
        let setup_groups = setup_groups(input, hlip, probes, scene, (si, s), &datum_of);
        groups.extend(datum_groups_first(setup_groups));
    }
    groups
}

/// Per feature, the datum it carries (the last declared, when several).
fn datum_of_features(input: &Input) -> Vec<Option<DatumId>> {
    let part = &input.model.parts[input.plan.part.0];
    let mut datum_of: Vec<Option<DatumId>> = vec![None; part.features.len()];
    for (k, d) in part.datums.iter().enumerate() {
        datum_of[d.feature.0] = Some(DatumId(k));
    }
    datum_of
}

/// One setup's groups in HLIP order, one per probe and orientation, each with its
/// blocks and the height it keeps on the clearance plane.
fn setup_groups<'a>(
    input: &Input,
    hlip: &Hlip,
    probes: &'a [ProbeShape],
    scene: &Scene,
    (si, s): (usize, &'a SetupNode),
    datum_of: &[Option<DatumId>],
) -> Vec<GroupIn<'a>> {
    let motion = input.plan.motion;
    let standoff = motion.prehit.max(motion.retract);
    let up = s.up;
    let table = s.table;
    let top = input
        .geometry
        .vertices
        .iter()
        .map(|v| v.coords.dot(&up))
        .fold(f64::NEG_INFINITY, f64::max);
    let mut setup_groups = Vec::new();
    let reach_max = s
        .probes
        .iter()
        .map(|p| probes[p.probe.0].reach())
        .fold(0.0, f64::max);
    for p in &s.probes {
        let probe = &probes[p.probe.0];
        for o in &p.orients {
            let dir = o.direction;
            // Every group of a setup keeps the head at one height on the clearance
            // plane, where the longest probe in any orientation swings clear.
            let lift = reach_max - probe.reach() * dir.dot(&up);
            let (mut blocks, records) = orient_blocks(input, hlip, scene, probe, o, datum_of);
            let poses: Vec<Pose> = placed_dirs(dir, up, s.square_within)
                .into_iter()
                .map(|d| Pose::new(scene, probe, d, up, table).with_fixture(&s.fixture))
                .collect();
            for b in &mut blocks {
                outlast(input, hlip, (scene, probe, &poses), b, standoff);
            }
            let has_datum = blocks.iter().any(|b| b.datum.is_some());
            setup_groups.push(GroupIn {
                setup: si,
                probe,
                slot: p.probe,
                a: o.a,
                b: o.b,
                dir,
                up,
                table,
                fixture: &s.fixture,
                height: top + motion.clearance + lift,
                blocks,
                records,
                has_datum,
            });
        }
    }
    setup_groups
}

/// The blocks of one orientation's inspections, one per feature face, and the
/// tolerances they complete (each once, in HLIP order).
fn orient_blocks(
    input: &Input,
    hlip: &Hlip,
    scene: &Scene,
    probe: &ProbeShape,
    o: &OrientNode,
    datum_of: &[Option<DatumId>],
) -> (Vec<BlockPath>, Vec<ToleranceId>) {
    let motion = input.plan.motion;
    let standoff = motion.prehit.max(motion.retract);
    let mut blocks = Vec::new();
    let mut records = Vec::new();
    for i in &o.inspections {
        for f in &i.faces {
            // The faces of a feature that lie on one surface (a bore in two
            // halves) are one block: one feature, one `MEAS`.
            let one = blocks.iter_mut().find(|b: &&mut BlockPath| {
                f.passes.is_empty()
                    && b.passes.is_empty()
                    && b.feature == i.feature
                    && b.contact == Contact::Part
                    && f.contact == Contact::Part
                    && input.geometry.one_surface(b.face, f.face)
            });
            if let Some(b) = one {
                let own = block_standoff(scene, hlip, &f.points, standoff, probe);
                b.standoff = b.standoff.min(own);
                for &k in &f.points {
                    if !b.touches.iter().any(|t| t.point == k) {
                        b.touches.push(Touch {
                            point: k,
                            via: vec![],
                            standoff: [0.0; 3],
                            margin: 0.0,
                        });
                    }
                }
                continue;
            }
            let own = block_standoff(scene, hlip, &f.points, standoff, probe);
            blocks.push(new_block(i, f, datum_of, own));
        }
        for r in &i.records {
            if !records.contains(r) {
                records.push(*r);
            }
        }
    }
    (blocks, records)
}

/// The block of face visit `f` of inspection `i`, its touches not yet planned.
fn new_block(
    i: &Inspection,
    f: &FaceVisit,
    datum_of: &[Option<DatumId>],
    standoff: f64,
) -> BlockPath {
    BlockPath {
        passes: f
            .passes
            .iter()
            .map(|x| PassPath {
                via: vec![],
                start: x.start.coords.into(),
                end: x.end.coords.into(),
            })
            .collect(),
        feature: i.feature,
        face: f.face,
        contact: f.contact,
        datum: i.feature.and_then(|x| datum_of[x.0]),
        standoff,
        touches: f
            .points
            .iter()
            .map(|&k| Touch {
                point: k,
                via: vec![],
                standoff: [0.0; 3],
                margin: 0.0,
            })
            .collect(),
    }
}

/// A setup's groups with datum groups first, keeping each probe's orientations together.
fn datum_groups_first(setup_groups: Vec<GroupIn>) -> Vec<GroupIn> {
    let probe_has_datum =
        |slot: SlotId, gs: &[GroupIn]| gs.iter().any(|g| g.slot == slot && g.has_datum);
    let keys: Vec<(bool, bool)> = setup_groups
        .iter()
        .map(|g| (!probe_has_datum(g.slot, &setup_groups), !g.has_datum))
        .collect();
    let mut idx: Vec<usize> = (0..setup_groups.len()).collect();
    idx.sort_by_key(|&k| keys[k]);
    let mut taken: Vec<Option<GroupIn>> = setup_groups.into_iter().map(Some).collect();
    let mut groups = Vec::new();
    for k in idx {
        if let Some(g) = taken[k].take() {
            groups.push(g);
        }
    }
    groups
}

/// How far a touch's surface may stand from its nominal on a part the program must
/// still measure and report (mm): twice the largest excursion the feature's tolerances
/// allow — half a profile's zone (equally disposed, ASME Y14.5-2018 §11.3.1), the radius
/// of a position's Ø zone, an orientation's or form's zone, a size's or distance's
/// farther limit — so that a part out by as much again as its tolerance reads OUT
/// rather than stopping the run with the probe already in the material.
fn excursion(input: &Input, feature: FeatureId) -> f64 {
    let part = &input.model.parts[input.plan.part.0];
    part.tolerances
        .iter()
        .filter(|t| t.targets.contains(&feature))
        .map(|t| match (&t.value, t.kind) {
            (_, TolKind::Angle) => 0.0,
            (crate::model::TolValue::Zone { width, .. }, k) => match k {
                TolKind::ProfileLine | TolKind::ProfileSurface | TolKind::Position => width / 2.0,
                _ => *width,
            },
            (
                crate::model::TolValue::Size {
                    nominal,
                    lower,
                    upper,
                },
                k,
            ) => {
                let far = (upper - nominal).abs().max((nominal - lower).abs());
                // A diameter's wall moves by half its change.
                if k == TolKind::Diameter {
                    far / 2.0
                } else {
                    far
                }
            }
        })
        .fold(0.0, f64::max)
        * 2.0
}

/// Lengthens a block's stand-off where its feature's tolerances allow its surface to
/// stand proud of the nominal by more than the stand-off leaves room for
/// ([`excursion`]): the approach then starts the motion margin beyond that (DMIS
/// `SNSET/APPRCH`; PC-DMIS's prehit distance is set the same way, larger than the
/// deviation expected). Where the longer approach (validated as the planner validated
/// the standard one, [`Pose::approach`], in each of `poses`: the probe's direction and
/// turned as the part may be placed) or the free space in front of a point does not
/// allow it, the block keeps the stand-off it had.
fn outlast(
    input: &Input,
    hlip: &Hlip,
    (scene, probe, poses): (&Scene, &ProbeShape, &[Pose]),
    b: &mut BlockPath,
    standoff: f64,
) {
    let Some(feature) = b.feature else { return };
    if b.contact != Contact::Part || !b.passes.is_empty() || b.standoff < standoff - 1e-9 {
        return;
    }
    let want = excursion(input, feature) + input.plan.motion.margin;
    if want <= standoff {
        return;
    }
    let points: Vec<usize> = b.touches.iter().map(|t| t.point).collect();
    let longer = block_standoff(scene, hlip, &points, want, probe);
    if longer <= standoff + 1e-9 {
        return;
    }
    let clear = points.iter().all(|&k| {
        let p = &hlip.points[k];
        let c = p.position + p.normal * probe.tip_radius;
        poses
            .iter()
            .all(|pose| pose.approach(&c, &p.normal, longer, Contact::Part).is_ok())
    });
    if clear {
        b.standoff = longer;
    }
}

/// The probe's directions (part frame) a setup's touches must stay clear in: `dir`,
/// and turned either way about `up` by the turn the setup tolerates (its prompt's
/// `square_within`, else [`crate::plan::PLACEMENT_TURN`]): the part set off square,
/// found by the alignment, sees the indexed stylus turned (as the planner validated
/// every touch, `plan::validate`).
fn placed_dirs(dir: V3, up: V3, square_within: Option<f64>) -> Vec<V3> {
    let turn = square_within.unwrap_or(crate::plan::PLACEMENT_TURN);
    std::iter::once(dir)
        .chain(crate::plan::turned_dirs(dir, &up, turn))
        .collect()
}

/// A block's stand-off: `standoff`, or half the free space in front of its points when
/// that is less (a small bore), so that the tip waits on the bore's axis.
fn block_standoff(
    scene: &Scene,
    hlip: &Hlip,
    points: &[usize],
    standoff: f64,
    probe: &ProbeShape,
) -> f64 {
    points.iter().fold(standoff, |s, &k| {
        let p = &hlip.points[k];
        s.min(crate::access::pose::backoff(
            scene,
            &p.position,
            &p.normal,
            probe.tip_radius,
            standoff,
        ))
    })
}
