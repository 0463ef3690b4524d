//! The machine as the planner sees it ([`Machine`]: probe shapes and costs, the head and
//! its grid of orientations with their directions and weights), and whether a part and a
//! machine can meet at all, checked before any planning ([`check_machine`]): the part
//! must fit on the table in some pose, and no probe may be longer than the ram travels.

use super::cluster::Bits;
use super::PlanError;
use crate::access::pose::Head;
use crate::access::ProbeShape;
use crate::diag::Diagnostics;
use crate::geometry::PartGeometry;
use crate::geometry::V3;
use crate::model::{fmt_num, Model, Plan};
use crate::model::{HeadKind, Stance};

/// Reports a part too large for the table in every pose and probes longer than the ram.
/// True when the plan can go on.
pub fn check_machine(
    model: &Model,
    plan: &Plan,
    geometry: &PartGeometry,
    diags: &mut Diagnostics,
) -> bool {
    let cmm = &model.cmms[plan.cmm.0];
    let part = &model.parts[plan.part.0];
    let mut ok = true;
    if let (Some(table), false) = (cmm.table_size, geometry.vertices.is_empty()) {
        let (lo, hi) = geometry.bounds();
        let mut e = [hi.x - lo.x, hi.y - lo.y, hi.z - lo.z];
        e.sort_by(f64::total_cmp);
        let mut t = table;
        t.sort_by(f64::total_cmp);
        // Its smallest footprint is its two smallest extents; if even that does not
        // fit, no pose does.
        if e[0] > t[0] + 1e-9 || e[1] > t[1] + 1e-9 {
            diags.push(PlanError::PartOffTable {
                span: plan.span,
                part: part.name.clone(),
                cmm: cmm.name.clone(),
                footprint: format!("{} × {} mm", fmt_num(round(e[0])), fmt_num(round(e[1]))),
                table: format!("{} × {} mm", fmt_num(table[0]), fmt_num(table[1])),
            });
            ok = false;
        }
    }
    for shape in ProbeShape::of_cmm(model, cmm) {
        if shape.reach() >= cmm.ram_length {
            diags.push(PlanError::ProbeTooLong {
                span: plan.span,
                probe: shape.name.clone(),
                cmm: cmm.name.clone(),
                reach: fmt_num(round(shape.reach())),
                ram: fmt_num(cmm.ram_length),
            });
            ok = false;
        }
    }
    ok
}

fn round(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

/// The machine as the planner sees it.
pub(crate) struct Machine {
    /// Probe shapes in rack order.
    pub probes: Vec<ProbeShape>,
    /// Probe costs (plan overrides applied).
    pub costs: Vec<f64>,
    /// Probes the plan allows.
    pub allowed: Vec<bool>,
    /// The head: fixed, or indexing on `grid`.
    pub head: Head,
    /// The head's A/B grid (degrees); one (0, 0) for a fixed head.
    pub grid: Vec<(f64, f64)>,
    /// The grid's probe directions in the machine frame (`access::head_direction`),
    /// computed once: the planner asks for them per point, probe and setup.
    pub grid_dirs: Vec<V3>,
    /// Each grid direction's angle (radians) from the head's axis, the machine's z (A up
    /// to rounding), and whether they never decrease along the grid.
    pub grid_polar: (Vec<f64>, bool),
    /// The grid orientations the plan allows.
    pub grid_allowed: Bits,
    /// Preference weights of grid orientations (0.5 when unspecified).
    pub grid_weight: Vec<f64>,
    /// The largest A (degrees).
    pub a_max: f64,
}

impl Machine {
    pub(crate) fn new(model: &Model, plan: &Plan) -> Machine {
        let cmm = &model.cmms[plan.cmm.0];
        let head = &model.heads[cmm.head.0];
        let probes = ProbeShape::of_cmm(model, cmm);
        let mut costs: Vec<f64> = cmm
            .probes
            .iter()
            .map(|(_, p)| model.probes[p.0].cost)
            .collect();
        let mut allowed = vec![true; probes.len()];
        for pref in &plan.probes {
            if let Some(k) = cmm.probes.iter().position(|(l, _)| *l == pref.label) {
                match pref.stance {
                    Stance::Forbid => allowed[k] = false,
                    Stance::Prefer(Some(c)) => costs[k] = c,
                    Stance::Prefer(None) => {}
                }
            }
        }
        let (kind, a_max) = match head.kind {
            HeadKind::Fixed => (Head::Fixed, 0.0),
            HeadKind::Indexable { a, .. } => (Head::Indexable, a[1]),
        };
        let grid = match kind {
            Head::Indexable => head.orientations(),
            Head::Fixed => vec![(0.0, 0.0)],
        };
        let mut grid_allowed = Bits::full(grid.len());
        let mut grid_weight = vec![0.5; grid.len()];
        for o in &plan.orientations {
            for (k, g) in grid.iter().enumerate() {
                if o.names(g.0, g.1) {
                    match o.stance {
                        Stance::Forbid => grid_allowed.remove(k),
                        Stance::Prefer(w) => grid_weight[k] = w,
                    }
                }
            }
        }
        let grid_dirs: Vec<V3> = grid
            .iter()
            .map(|&(a, b)| crate::access::head_direction(a, b))
            .collect();
        let polar: Vec<f64> = grid_dirs
            .iter()
            .map(|d| d.z.clamp(-1.0, 1.0).acos())
            .collect();
        let sorted = polar.is_sorted();
        Machine {
            grid_polar: (polar, sorted),
            probes,
            costs,
            allowed,
            head: kind,
            grid,
            grid_dirs,
            grid_allowed,
            grid_weight,
            a_max,
        }
    }
}
