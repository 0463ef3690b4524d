//! Whether a part and a machine can meet at all, checked before any planning: the part
//! must fit on the table in some pose, and no probe may be longer than the ram travels.

use super::PlanError;
use crate::access::ProbeShape;
use crate::diag::Diagnostics;
use crate::geometry::PartGeometry;
use crate::model::{fmt_num, Model, Plan};

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
