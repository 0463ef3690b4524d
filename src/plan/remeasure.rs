//! Datums measured where they are read. A tolerance relates its features to the datum
//! reference frame its datum features establish (ASME Y14.5-2018 ch. 7: the frame comes
//! from the datum features as they are, through their simulated datum features). A plan
//! that measures a feature in one setup and its datum in another relates the two sets of
//! points only through the alignments of the two placements: the second setup's
//! alignment is built on features of that setup, so it carries the datum over as the
//! nominal relation between them, and an orientation or location error between the
//! feature and the datum disappears into the alignment (f3's side hole read against the
//! top measured in the setup before: any tilt of the hole reads 0).
//!
//! So each datum feature a setup's tolerances read and the setup does not measure is
//! measured again there, with the setup's own probe orientations (then, on an indexable
//! head, with others the probe has there), on the points the plan gives it elsewhere,
//! each touch validated as the plan's own are; a datum face resting on the table in that
//! setup is measured by the table points standing in for it (seed ch. 3.6.2). The
//! program then defines the datum anew from that measurement before the setup's
//! tolerances ([`crate::dmis`]'s rounds). This is the practice of CMM part programming
//! after re-fixturing: the datums are measured again in the new setup and the features
//! are evaluated against them there (Hocken & Pereira, *Coordinate Measuring Machines
//! and Systems*, 2nd ed., ch. 13). Where no probe reaches a datum in the setup of the
//! features read against it, the plan says so ([`PlanError::DatumInOtherSetup`]).
//!
//! Where no probe reaches the datum, the program still reports the tolerance and the
//! warning names the tolerance, the datums and their setups. A feature measured across
//! setups is left as it is (joined through the setups' alignments).

use super::filter::min_points;
use super::hlip::collect;
use super::knowledge::Knowledge;
use super::machine::Machine;
use super::solve::{Branch, Inst, Kind};
use super::validate::{self, Pip};
use super::{Ban, Input, PlanError};
use crate::diag::Diagnostics;
use crate::geometry::{FaceId, PartGeometry, V3};
use crate::model::FeatureId;
use std::collections::{BTreeMap, BTreeSet};

/// What the plan measures where: per feature, per setup (index in plan order), per
/// face, the points (`table` for a face standing on the table).
type Measured = BTreeMap<FeatureId, BTreeMap<usize, BTreeMap<FaceId, BTreeSet<usize>>>>;

/// Branches that measure, in the setup of the features they read, the datum features
/// the plan measures only in other setups; a warning for each tolerance whose datum no
/// probe reaches there. `turn` is the placement the plan's touches were validated for.
pub(super) fn datums_where_read(
    input: &Input,
    k: &mut Knowledge,
    m: &Machine,
    branches: &[Branch],
    turn: f64,
    bans: &[Ban],
    diags: &mut Diagnostics,
) -> Vec<Branch> {
    let part = &input.model.parts[input.plan.part.0];
    // The setups in plan order (first appearance, as the plan is assembled).
    let mut cells: Vec<(usize, V3)> = Vec::new();
    for b in branches {
        if !cells.iter().any(|c| c.0 == b.setup) {
            cells.push((b.setup, b.up));
        }
    }
    let setup_of = |cell: usize| cells.iter().position(|c| c.0 == cell).unwrap_or(0);
    let mut measured: Measured = BTreeMap::new();
    for b in branches {
        collect(&b.tree, None, None, &mut |_, feature, face, _, points| {
            let Some(feature) = feature else { return };
            measured
                .entry(feature)
                .or_default()
                .entry(setup_of(b.setup))
                .or_default()
                .entry(face)
                .or_default()
                .extend(points.iter().copied());
        });
    }
    // (setup, datum feature) → the tolerances read against it there.
    let mut needs: BTreeMap<(usize, FeatureId), Vec<usize>> = BTreeMap::new();
    for (r, t) in part.tolerances.iter().enumerate() {
        let setups: BTreeSet<usize> = t
            .targets
            .iter()
            .flat_map(|f| measured.get(f).into_iter().flat_map(|s| s.keys().copied()))
            .collect();
        // A feature measured across setups is joined through their alignments anyway.
        let [si] = setups.iter().copied().collect::<Vec<_>>()[..] else {
            continue;
        };
        for d in &t.datums {
            let datum = part.datums[d.datum.0].feature;
            let Some(at) = measured.get(&datum) else {
                continue;
            };
            if !at.contains_key(&si) && !t.targets.contains(&datum) {
                needs.entry((si, datum)).or_default().push(r);
            }
        }
    }
    let mut extra: Vec<Branch> = Vec::new();
    // Per tolerance, the datums no probe reaches where it is read, and where they are.
    let mut unreached: BTreeMap<usize, Vec<(FeatureId, String)>> = BTreeMap::new();
    for ((si, datum), tols) in needs {
        let (cell, up) = cells[si];
        // The datum's faces and the points the plan touches them at, wherever.
        let mut faces: BTreeMap<FaceId, BTreeSet<usize>> = BTreeMap::new();
        for by_face in measured[&datum].values() {
            for (face, pts) in by_face {
                let part_points = pts.iter().filter(|&&p| p < k.graph_points);
                faces.entry(*face).or_default().extend(part_points);
            }
        }
        match measure_in(input.geometry, k, m, branches, cell, up, &faces, turn, bans) {
            Some(chosen) => extra.extend(branches_of(cell, up, datum, &tols, chosen)),
            None => {
                for &r in &tols {
                    let setups: Vec<String> = measured[&datum]
                        .keys()
                        .map(|s| (s + 1).to_string())
                        .collect();
                    let s = if setups.len() == 1 { "" } else { "s" };
                    unreached
                        .entry(r)
                        .or_default()
                        .push((datum, format!("setup{s} {}", setups.join(" and "))));
                }
            }
        }
    }
    for (r, datums) in unreached {
        let t = &part.tolerances[r];
        let setup = t
            .targets
            .iter()
            .find_map(|f| measured.get(f)?.keys().next().copied())
            .map_or(0, |s| s + 1);
        let name = |feature: FeatureId| {
            t.datums
                .iter()
                .map(|d| &part.datums[d.datum.0])
                .find(|d| d.feature == feature)
                .map_or(String::new(), |d| d.name.clone())
        };
        let letters: Vec<String> = datums.iter().map(|(f, _)| name(*f)).collect();
        let listed: Vec<String> = datums
            .iter()
            .map(|(f, at)| format!("{} in {at}", name(*f)))
            .collect();
        let s = if datums.len() == 1 { "" } else { "s" };
        diags.push(PlanError::DatumInOtherSetup {
            span: t.span,
            tolerance: t.name.clone(),
            datums: format!("datum{s} {}", letters.join(" and ")),
            setup,
            measured: listed.join(", "),
        });
    }
    extra
}

/// A face measured again: its configuration (probe, orientation), whether it is the
/// table standing in for it (its alternative's index), and the points.
struct Again {
    face: FaceId,
    probe: usize,
    orient: usize,
    table: Option<usize>,
    points: Vec<usize>,
}

/// How each face can be measured in setup `cell`: for each, the configuration that
/// touches the most of its points clear (the setup's own first), enough of them to fit
/// it; `None` when some face has no such configuration.
#[allow(clippy::too_many_arguments)]
fn measure_in(
    geometry: &PartGeometry,
    k: &mut Knowledge,
    m: &Machine,
    branches: &[Branch],
    cell: usize,
    up: V3,
    faces: &BTreeMap<FaceId, BTreeSet<usize>>,
    turn: f64,
    bans: &[Ban],
) -> Option<Vec<Again>> {
    let held = k.held(cell).clone();
    let mut configs: Vec<(usize, usize)> = Vec::new();
    for b in branches.iter().filter(|b| b.setup == cell) {
        if !configs.contains(&(b.probe, b.orient)) {
            configs.push((b.probe, b.orient));
        }
    }
    let mut out = Vec::new();
    for (&face, plan_points) in faces {
        // The table standing in for a datum face resting on it in this setup (a datum
        // feature simulator, Y14.5-2018 ch. 7), its points validated here like any touch
        // (the planner may have given the alternative up for a configuration it tried).
        let table = k
            .tables
            .iter()
            .position(|t| t.face == face && t.cell == cell);
        let points: Vec<usize> = match table {
            Some(t) => k.tables[t].points.clone(),
            None => plan_points.iter().copied().collect(),
        };
        let &first = points.first()?;
        let mut tries = configs.clone();
        if m.head.indexable() && table.is_none() {
            let probes: Vec<usize> = configs.iter().map(|c| c.0).collect();
            for p in probes {
                let reach = k.orientations(first, p, cell, &up, m);
                for o in reach.ones() {
                    if !tries.contains(&(p, o)) {
                        tries.push((p, o));
                    }
                }
            }
        }
        let kind = geometry.faces[face.0].surface.kind();
        let need = min_points(kind).min(points.len());
        let clear = |k: &Knowledge, pip: &Pip| {
            validate::check(k, m, pip, &up, &held, bans).is_ok()
                && validate::clear_turned(k, m, pip, &up, &held, turn).is_ok()
        };
        let mut best: Option<Again> = None;
        for (probe, orient) in tries {
            // A configuration is dropped as soon as it cannot beat the best so far.
            let beat = need.max(best.as_ref().map_or(0, |b| b.points.len() + 1));
            let mut ok: Vec<usize> = Vec::new();
            for (i, &point) in points.iter().enumerate() {
                if ok.len() + (points.len() - i) < beat {
                    break;
                }
                let pip = Pip {
                    point,
                    probe,
                    setup: cell,
                    orient,
                };
                if clear(k, &pip) {
                    ok.push(point);
                }
            }
            // A plane's touches must fix it: a row of points along one line does not.
            let fixes = table.is_some()
                || !matches!(
                    geometry.faces[face.0].surface,
                    crate::geometry::Surface::Plane { .. }
                )
                || super::filter::spans_area(
                    &ok.iter()
                        .map(|&q| &k.points[q].position)
                        .collect::<Vec<_>>(),
                );
            if fixes && ok.len() >= need && best.as_ref().is_none_or(|b| ok.len() > b.points.len())
            {
                let all = ok.len() == points.len();
                best = Some(Again {
                    face,
                    probe,
                    orient,
                    table,
                    points: ok,
                });
                if all {
                    break;
                }
            }
        }
        out.push(best?);
    }
    Some(out)
}

/// One branch per configuration: the datum feature's faces under each tolerance.
fn branches_of(
    cell: usize,
    up: V3,
    datum: FeatureId,
    tols: &[usize],
    again: Vec<Again>,
) -> Vec<Branch> {
    let mut by_config: BTreeMap<(usize, usize), Vec<Again>> = BTreeMap::new();
    for a in again {
        by_config.entry((a.probe, a.orient)).or_default().push(a);
    }
    by_config
        .into_iter()
        .map(|((probe, orient), faces)| {
            let face_insts: Vec<Inst> = faces
                .iter()
                .map(|a| {
                    let points = a
                        .points
                        .iter()
                        .map(|&point| Inst {
                            kind: Kind::Point { point, table: None },
                            children: vec![],
                        })
                        .collect();
                    Inst {
                        kind: match a.table {
                            Some(_) => Kind::Table { face: a.face },
                            None => Kind::Face {
                                face: a.face,
                                table: None,
                            },
                        },
                        children: points,
                    }
                })
                .collect();
            let tol_insts = tols
                .iter()
                .map(|&r| Inst {
                    kind: Kind::Tol(r),
                    children: vec![Inst {
                        kind: Kind::Feature(datum),
                        children: face_insts.clone(),
                    }],
                })
                .collect();
            Branch {
                setup: cell,
                up,
                probe,
                orient,
                tree: Inst {
                    kind: Kind::Part,
                    children: tol_insts,
                },
            }
        })
        .collect()
}
