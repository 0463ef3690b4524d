//! How square the operator must set the part: the touches of a plan validated at the
//! nominal pose only (a point whose configurations collided turned, or every touch of
//! `search::plan_placed`'s second try) that collide with the part turned
//! [`PLACEMENT_TURN`] about the vertical, and the turn each setup tolerates.

use super::explain::face_name;
use super::hlip::Hlip;
use super::knowledge::Knowledge;
use super::machine::Machine;
use super::solve::{self, Branch};
use super::validate::{tolerated_turn, Pip, PLACEMENT_TURN};
use super::{Input, PlanError};
use crate::diag::Diagnostics;
use crate::model::fmt_num;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// Touches per (face, probe) that ask for the part squarer.
type Touches = BTreeMap<(String, String), usize>;

/// Sets [`super::hlip::SetupNode::square_within`] of each setup some touch of which
/// stays clear only with the part nearer square than [`PLACEMENT_TURN`], and warns of
/// it. Only the `fragile` touches are tried: the others were validated turned.
pub(super) fn square_within(
    input: &Input,
    k: &mut Knowledge,
    m: &Machine,
    branches: &[Branch],
    fragile: &dyn Fn(&Pip) -> bool,
    hlip: &mut Hlip,
    diags: &mut Diagnostics,
) {
    let mut pips: Vec<(Pip, crate::geometry::V3)> = Vec::new();
    for b in branches {
        let mut pts = Vec::new();
        solve::leaves(&b.tree, &mut pts);
        pips.extend(
            pts.into_iter()
                .map(|p| (b.pip(p), b.up))
                .filter(|(p, _)| fragile(p)),
        );
    }
    let held: BTreeMap<usize, super::knowledge::Held> = pips
        .iter()
        .map(|(p, _)| (p.setup, k.held(p.setup).clone()))
        .collect();
    let k = &*k;
    let turns: Vec<f64> = pips
        .par_iter()
        .map(|(p, up)| tolerated_turn(k, m, p, up, &held[&p.setup], PLACEMENT_TURN))
        .collect();
    // Per setup (index into the plan's setups): the least turn, and per (face, probe)
    // the touches that ask for less than the full one.
    let mut by_setup: BTreeMap<usize, (f64, Touches)> = BTreeMap::new();
    for ((p, up), t) in pips.iter().zip(turns) {
        if t >= PLACEMENT_TURN {
            continue;
        }
        let Some(si) = hlip.setups.iter().position(|s| (s.up - up).norm() < 1e-6) else {
            continue;
        };
        let e = by_setup
            .entry(si)
            .or_insert((PLACEMENT_TURN, BTreeMap::new()));
        e.0 = e.0.min(t);
        let key = (face_name(input, k, p.point), m.probes[p.probe].name.clone());
        *e.1.entry(key).or_default() += 1;
    }
    for (si, (within, faces)) in by_setup {
        hlip.setups[si].square_within = Some(within);
        let mut listed: Vec<String> = faces
            .iter()
            .take(3)
            .map(|((face, probe), n)| {
                let s = if *n == 1 { "" } else { "es" };
                format!("probe {probe} on {face} ({n} touch{s})")
            })
            .collect();
        if faces.len() > 3 {
            listed.push(format!("{} more faces", faces.len() - 3));
        }
        diags.push(PlanError::PlacementSensitive {
            span: input.plan.span,
            plan: input.plan.name.clone(),
            setup: si + 1,
            within: if within > 0.0 {
                format!("within {}°", fmt_num(within))
            } else {
                "exactly (no turn of 0.1° is clear)".into()
            },
            full: fmt_num(PLACEMENT_TURN),
            touches: listed.join(", "),
        });
    }
}
