//! Scan planning (Zhao et al. sec. 5, Álvarez et al. sec. V): the faces of the features
//! the sensor selection ([`crate::graph::sensors`]) gave a laser scanner are left out of
//! the touch plan and covered here, each in one setup, by the scanner's passes from few
//! head orientations ([`crate::access::scan::face_coverage`]).
//!
//! A face is scanned in the setup of the plan whose `up` its mean normal faces most that
//! reaches the plan's coverage (`scan_coverage`, 95 % of the area by default); where no
//! setup of the touch plan does and the plan asked the laser for the feature, in the
//! best of the part's other setups, which joins the plan (a feature the selection rule
//! chose goes back to the touch probe instead: the hierarchy puts fewer setups first). In a setup the scanner comes after the touch probes, one sensor change in: the
//! sensor is clustered under the setup as probes are, and a sensor change counts as a
//! probe change. A face no setup covers enough is returned: a feature the selection gave
//! the scanner by its rule goes back to the touch probe ([`super::plan_with`]); one the
//! plan asked the laser for is reported unmeasured.
//!
//! **Decision:** coverage is judged at a cube-map resolution of at most 32 (cones of
//! 6 × 32² directions, 2.8° pixels): the scanner's incidence limit and stripe are far
//! coarser than that, and each face costs a few hundred cones.
//!
//! **Decision: a scan stage after the touch plan, not a slot of the solver.** The
//! scanner's unit is a face's area (coverage, passes), not an fpoint, and Zhao et al.
//! plan it per face too; so the scanner's faces are planned here, after the touch plan,
//! rather than as a slot of the solver with per-fpoint domains. The hierarchy still
//! holds: a face goes to a setup the touch plan already has when that covers it (setups
//! first), the scanner is one sensor node per setup after the probes (its slot the
//! rack's probe count plus its index), and views are few by the greedy cover. What this
//! gives up: the solver cannot trade a touch setup for a scan. The touch plan made
//! without the scanner's faces may hold setups none of them suits (FTC 08: every upward
//! face goes to the scanner, so the touch plan has no `+z`): features sent back are
//! planned for touch, and the rounds go on until none is sent back; then each feature
//! sent back is offered to the scanner again in the final setups, and one it covers
//! there is scanned and its touches leave the plan (`Hlip::drop_touches`). A face's
//! cones do not depend on the setup: they are drawn once per face and kept in the memo
//! with the coverages, so re-plans after path bans reuse them. Each pass is checked
//! with `Pose::segment` as the path stage will run it.

use super::hlip::{quantise, ScanPass, ScannedFace};
use super::memo::ScanMemo;
use super::poses::Setups;
use super::{FaceVisit, Hlip, Input, Inspection, OrientNode, ProbeNode, SetupNode};
use crate::access::pose::{frame, Contact, Head, Pose};
use crate::access::scan::{FaceCones, FaceCoverage, ScannerShape, Views};
use crate::access::{ConeOptions, Scene};
use crate::geometry::{FaceId, P3, V3};
use crate::graph::sensors::Sensor;
use crate::graph::Node;
use crate::model::{FeatureId, SensorChoice, SlotId, ToleranceId};

/// The overlap of neighbouring passes, as a share of the stripe's width.
pub(crate) const OVERLAP: f64 = 0.2;

/// A feature the sensor selection gave a scanner.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Laser {
    /// The feature.
    pub feature: FeatureId,
    /// The scanner, by index among the machine's scanners.
    pub scanner: usize,
    /// Its faces.
    pub faces: Vec<FaceId>,
    /// Whether the plan asked for the laser (else the selection rule chose it).
    pub asked: bool,
    /// Why the scanner.
    pub why: String,
}

/// The features of the plan's graph that go to a scanner, in feature order.
pub(crate) fn lasers(input: &Input) -> Vec<Laser> {
    let g = input.graph;
    let mut faces_of: std::collections::BTreeMap<FeatureId, Vec<FaceId>> = Default::default();
    for (n, node) in g.nodes() {
        if let Node::Feature { feature, .. } = node {
            for (c, _) in g.children(n) {
                if let Node::Face { face, .. } = g.graph[c] {
                    faces_of.entry(*feature).or_default().push(face);
                }
            }
        }
    }
    g.sensors
        .iter()
        .filter_map(|s| match s.sensor {
            Sensor::Laser(k) => Some(Laser {
                feature: s.feature,
                scanner: k,
                faces: faces_of.get(&s.feature).cloned().unwrap_or_default(),
                asked: input
                    .plan
                    .sensors
                    .iter()
                    .any(|(f, c, _)| *f == s.feature && *c == SensorChoice::Laser),
                why: s.why.clone(),
            }),
            Sensor::Touch => None,
        })
        .filter(|l| !l.faces.is_empty())
        .collect()
}

/// A face no setup covers as the plan asks: the best share of its area any setup gave.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Uncovered {
    /// The feature.
    pub feature: FeatureId,
    /// The face.
    pub face: FaceId,
    /// The best coverage found.
    pub best: f64,
}

/// Where a face is scanned: the setup and the coverage there.
struct Placed {
    laser: usize,
    face: FaceId,
    setup: usize,
    coverage: FaceCoverage,
}

/// Plans the scans of `lasers` into `hlip`: per face the setup, views and passes, in
/// the setups' scanner nodes. Returns the faces no setup covers to the plan's
/// `scan_coverage`; those are left out of the plan.
pub(crate) fn plan_scans(
    input: &Input,
    hlip: &mut Hlip,
    lasers: &[Laser],
    opts: &super::PlanOptions,
    memo: &mut ScanMemo,
) -> Vec<Uncovered> {
    if lasers.is_empty() {
        return Vec::new();
    }
    let (model, plan, g) = (input.model, input.plan, input.geometry);
    let cmm = &model.cmms[plan.cmm.0];
    let machine = super::machine::Machine::new(model, plan);
    let scanning = Scanning {
        g,
        shapes: ScannerShape::of_cmm(model, cmm),
        scene: Scene::of_part(g),
        // The orientations the plan allows (one (0, 0) on a fixed head).
        grid: machine
            .grid_allowed
            .ones()
            .map(|k| machine.grid[k])
            .collect(),
        cone_opts: ConeOptions {
            n: opts.n.min(32),
            backend: opts.backend,
            ..Default::default()
        },
        backend: opts.backend.get(),
        target: plan.scan_coverage,
        margin: plan.motion.margin,
        setups: Setups::new(model, plan, g, input.fixtures),
    };
    // The setups a face may go to: the plan's, then the part's others that can be held.
    let mut ups: Vec<V3> = hlip.setups.iter().map(|s| s.up).collect();
    let others: Vec<V3> = scanning
        .setups
        .exact_dirs()
        .into_iter()
        .filter(|u| scanning.setups.holder(u).is_some())
        .filter(|u| !ups.iter().any(|v| (u - v).norm() < 1e-6))
        .collect();
    let mut placed: Vec<Placed> = Vec::new();
    let mut uncovered = Vec::new();
    for (li, l) in lasers.iter().enumerate() {
        for &face in &l.faces {
            match scanning.place(l, face, &mut ups, &others, memo) {
                Some((s, c)) if s != usize::MAX && c.covered >= scanning.target => {
                    placed.push(Placed {
                        laser: li,
                        face,
                        setup: s,
                        coverage: c,
                    })
                }
                b => uncovered.push(Uncovered {
                    feature: l.feature,
                    face,
                    best: b.map_or(0.0, |b| b.1.covered),
                }),
            }
        }
    }
    // A feature is scanned whole or not at all: one face short sends it all back.
    placed.retain(|p| {
        !uncovered
            .iter()
            .any(|u| u.feature == lasers[p.laser].feature)
    });
    add_setups(hlip, &ups, &placed, &scanning.setups);
    let setup_of = |p: &Placed| {
        hlip.setups
            .iter()
            .position(|s| (s.up - ups[p.setup]).norm() < 1e-5)
            .unwrap_or(0)
    };
    let placed: Vec<(usize, Placed)> = placed.into_iter().map(|p| (setup_of(&p), p)).collect();
    let part = &model.parts[plan.part.0];
    for (s, p) in &placed {
        record_scan(hlip, *s, p, &lasers[p.laser], part, cmm.probes.len());
    }
    hlip.scans.sort_by_key(|s| (s.feature, s.face));
    recount(hlip, machine.head);
    uncovered
}

/// What placing the scanners' faces in setups shares.
struct Scanning<'a> {
    g: &'a crate::geometry::PartGeometry,
    shapes: Vec<ScannerShape>,
    scene: Scene,
    grid: Vec<(f64, f64)>,
    cone_opts: ConeOptions,
    backend: &'static dyn crate::access::Backend,
    /// The plan's `scan_coverage`.
    target: f64,
    margin: f64,
    setups: Setups<'a>,
}

impl Scanning<'_> {
    /// The table's height under the part in a setup and the fixture's solids, as the
    /// setup holds it.
    fn held_at(&self, up: &V3) -> (f64, Vec<crate::access::pose::Solid>) {
        match self.setups.holder(up) {
            Some(h) => {
                let solids = self.setups.solids(&h, up);
                (self.setups.table(&h, up, &solids), solids)
            }
            None => (crate::access::pose::table_height(&self.scene, up), vec![]),
        }
    }

    /// The coverage of a face by `shape` in setup `up`, on the face's `cones`: the
    /// passes as the path stage will run them, so a view whose housing does not clear
    /// the part, table and fixture by the margin along every pass is not the plan's.
    fn cover(&self, cones: &FaceCones, shape: &ScannerShape, up: &V3) -> FaceCoverage {
        let (table, solids) = self.held_at(up);
        let views = Views {
            grid: &self.grid,
            overlap: OVERLAP,
            up: *up,
            table: (table, self.margin),
            fixture: &solids,
        };
        let mut c = cones.coverage(&self.scene, shape, &views);
        c.views.retain(|v| {
            let pose = Pose::new(&self.scene, &shape.probe, v.dir, *up, table)
                .with_fixture(&solids)
                .with_margin(self.margin);
            let ok = v
                .lines
                .iter()
                .all(|l| pose.segment(&l.start, &l.end).is_ok());
            if !ok {
                c.covered -= v.share;
            }
            ok
        });
        c
    }

    /// The setup (index into `ups`) that covers `face` best, and its coverage: the
    /// plan's setups, the one the face looks up in most first; for a feature the plan
    /// asked the scanner for, a setup the plan does not have yet (pushed onto `ups`), or
    /// `usize::MAX` for one that covers more without reaching the target.
    fn place(
        &self,
        l: &Laser,
        face: FaceId,
        ups: &mut Vec<V3>,
        others: &[V3],
        memo: &mut ScanMemo,
    ) -> Option<(usize, FaceCoverage)> {
        let shape = &self.shapes[l.scanner];
        let normal = mean_normal(self.g, face);
        let cones = || {
            FaceCones::new(
                self.backend,
                &self.scene,
                self.g,
                face.0,
                shape,
                &self.cone_opts,
            )
        };
        let cover = |cones: &FaceCones, up: &V3| self.cover(cones, shape, up);
        let mut order: Vec<usize> = (0..ups.len()).collect();
        order.sort_by(|&a, &b| {
            normal
                .dot(&ups[b])
                .total_cmp(&normal.dot(&ups[a]))
                .then(a.cmp(&b))
        });
        let mut best: Option<(usize, FaceCoverage)> = None;
        for s in order {
            let c = memo.get((l.scanner, face), &ups[s], &cones, &cover);
            let better = best
                .as_ref()
                .is_none_or(|b| c.covered > b.1.covered + 1e-12);
            if better {
                best = Some((s, c));
            }
            if best.as_ref().is_some_and(|b| b.1.covered >= self.target) {
                break;
            }
        }
        if !l.asked || best.as_ref().is_some_and(|b| b.1.covered >= self.target) {
            return best;
        }
        // A setup the plan does not have yet, for a feature the plan asked the scanner
        // for: the best of the others. (One the rule chose goes back to the touch probe
        // instead: a setup costs more than touching it.)
        let mut fresh: Option<(usize, FaceCoverage)> = None;
        for (k, up) in others.iter().enumerate() {
            if ups.iter().any(|v| (up - v).norm() < 1e-6) {
                continue;
            }
            let c = memo.get((l.scanner, face), up, &cones, &cover);
            if fresh
                .as_ref()
                .is_none_or(|f| c.covered > f.1.covered + 1e-12)
            {
                fresh = Some((k, c));
            }
        }
        if let Some((k, c)) = fresh {
            let gain = best
                .as_ref()
                .is_none_or(|b| c.covered > b.1.covered + 1e-12);
            if c.covered >= self.target && gain {
                ups.push(others[k]);
                best = Some((ups.len() - 1, c));
            } else if gain && best.as_ref().is_none_or(|b| b.1.covered < c.covered) {
                best = Some((usize::MAX, c));
            }
        }
        best
    }
}

/// The setups `ups` added beyond the plan's that a placed face uses join the plan, held
/// as the part's setups say.
fn add_setups(hlip: &mut Hlip, ups: &[V3], placed: &[Placed], setups: &Setups) {
    for &up in ups.iter().skip(hlip.setups.len()) {
        if !placed.iter().any(|p| (ups[p.setup] - up).norm() < 1e-6) {
            continue;
        }
        let Some(holder) = setups.holder(&up) else {
            continue;
        };
        let solids = setups.solids(&holder, &up);
        let table = super::hlip::round(setups.table(&holder, &up, &solids));
        let r = frame(&up).into_inner();
        hlip.setups.push(SetupNode {
            up: quantise(&up),
            rotation: [0, 1, 2].map(|i| [0, 1, 2].map(|j| super::hlip::round(r[(i, j)]))),
            on_table: vec![],
            holder,
            table,
            fixture: solids,
            probes: vec![],
            square_within: None,
        });
    }
}

/// A placed face's views into setup `s`'s scanner node (the scanner's slot after the
/// rack's probes), one orientation per view, and its line in `hlip.scans`.
fn record_scan(
    hlip: &mut Hlip,
    s: usize,
    p: &Placed,
    l: &Laser,
    part: &crate::model::Part,
    probes: usize,
) {
    let slot = SlotId(probes + l.scanner);
    let node = &mut hlip.setups[s];
    let pi = match node.probes.iter().position(|n| n.probe == slot) {
        Some(k) => k,
        None => {
            node.probes.push(ProbeNode {
                probe: slot,
                orients: vec![],
            });
            node.probes.len() - 1
        }
    };
    let last_view = p.coverage.views.len().saturating_sub(1);
    for (vi, v) in p.coverage.views.iter().enumerate() {
        let orients = &mut node.probes[pi].orients;
        let oi = match orients
            .iter()
            .position(|o| o.a.to_bits() == v.a.to_bits() && o.b.to_bits() == v.b.to_bits())
        {
            Some(k) => k,
            None => {
                orients.push(OrientNode {
                    a: v.a,
                    b: v.b,
                    direction: quantise(&v.dir),
                    inspections: vec![],
                });
                orients.len() - 1
            }
        };
        let passes: Vec<ScanPass> = v
            .lines
            .iter()
            .map(|x| ScanPass {
                start: P3::from(quantise(&x.start.coords)),
                end: P3::from(quantise(&x.end.coords)),
            })
            .collect();
        let visit = FaceVisit {
            face: p.face,
            contact: Contact::Part,
            points: vec![],
            passes,
        };
        // The tolerances reading the feature are recorded with its last view.
        let records: Vec<ToleranceId> = if vi == last_view {
            records_of(part, l.feature)
        } else {
            vec![]
        };
        add_visit(&mut orients[oi], l.feature, visit, records);
    }
    hlip.scans.push(ScannedFace {
        feature: l.feature,
        face: p.face,
        scanner: slot,
        setup: s,
        coverage: p.coverage.covered,
        views: p.coverage.views.len(),
        passes: p.coverage.views.iter().map(|v| v.passes).sum(),
        why: l.why.clone(),
    });
}

/// A face's visit joins its feature's inspection in an orientation (made if new), with
/// the tolerances it records.
fn add_visit(o: &mut OrientNode, feature: FeatureId, visit: FaceVisit, records: Vec<ToleranceId>) {
    match o
        .inspections
        .iter_mut()
        .find(|i| i.feature == Some(feature))
    {
        Some(i) => {
            i.faces.push(visit);
            for r in records {
                if !i.records.contains(&r) {
                    i.records.push(r);
                }
            }
        }
        None => o.inspections.push(Inspection {
            feature: Some(feature),
            faces: vec![visit],
            records,
        }),
    }
}

/// The tolerances that read a feature: as a target or through a datum it carries.
fn records_of(part: &crate::model::Part, f: FeatureId) -> Vec<ToleranceId> {
    part.tolerances
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            t.targets.contains(&f) || t.datums.iter().any(|d| part.datums[d.datum.0].feature == f)
        })
        .map(|(k, _)| ToleranceId(k))
        .collect()
}

/// A face's area-weighted mean outward normal (zero for a closed cylinder).
fn mean_normal(g: &crate::geometry::PartGeometry, face: FaceId) -> V3 {
    let mut n = V3::zeros();
    for &t in &g.faces[face.0].triangles {
        let [a, b, c] = g.triangles[t as usize].map(|i| g.vertices[i as usize]);
        n += (b - a).cross(&(c - a));
    }
    n.try_normalize(1e-12).unwrap_or_else(V3::zeros)
}

/// The plan's counts once scans joined it: setups, sensors used and sensor changes,
/// orientations and their changes, scanned faces and passes.
pub(crate) fn recount(hlip: &mut Hlip, head: Head) {
    let mut seq: Vec<(SlotId, (u64, u64))> = Vec::new();
    for s in &hlip.setups {
        for p in &s.probes {
            for o in &p.orients {
                seq.push((p.probe, (o.a.to_bits(), o.b.to_bits())));
            }
        }
    }
    let s = &mut hlip.summary;
    s.setups = hlip.setups.len();
    s.probe_changes = seq.windows(2).filter(|w| w[0].0 != w[1].0).count();
    s.probes_used = seq
        .iter()
        .map(|x| x.0)
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    if head == Head::Indexable {
        s.orientation_changes = seq.windows(2).filter(|w| w[0].1 != w[1].1).count();
        s.orientations = seq
            .iter()
            .map(|x| x.1)
            .collect::<std::collections::BTreeSet<_>>()
            .len();
    }
    s.scanned = (hlip.scans.len(), hlip.scans.iter().map(|x| x.passes).sum());
}
