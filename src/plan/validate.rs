//! Validation (seed ch. 4.1): one primitive inspection plan — setup, probe, orientation,
//! fpoint — checked with parry. The tip sweeps from the retract point to the contact as
//! an exact capsule; stylus, extensions, body, head and ram are tested at positions along
//! the approach with their radii grown to cover the motion between positions; the part is
//! an obstacle, and the table is a plane under the part in that setup.

use super::domain::{lowest, Knowledge, Machine, TIP_CLEARANCE};
use crate::access::{component_hits, Component};
use crate::geometry::{P3, V3};
use parry3d_f64::math::Isometry;
use parry3d_f64::query::intersection_test;
use parry3d_f64::shape::Capsule;

/// A primitive inspection plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) struct Pip {
    /// The point (graph fpoint or table point).
    pub point: usize,
    /// The probe, by rack index.
    pub probe: usize,
    /// The setup's cell index.
    pub setup: usize,
    /// The grid orientation (0 for a fixed head).
    pub orient: usize,
}

/// The spacing of the positions tested along the approach (mm).
const SWEEP_STEP: f64 = 0.25;

/// The table may come no closer to the probe than this (mm).
const TABLE_MARGIN: f64 = 0.1;

/// Checks one PIP; `None` when it is collision-free, else what collides.
pub(crate) fn check(k: &Knowledge, m: &Machine, pip: &Pip, up: &V3, t0: f64) -> Option<String> {
    let probe = &m.probes[pip.probe];
    let f = &k.points[pip.point];
    let table_point = pip.point >= k.graph_points;
    let c = f.tip_centre(probe.tip_radius);
    let travel = k.opts.retract;
    let n = f.normal;
    let mesh = k.scene.mesh()?;
    let id = Isometry::identity();
    // The tip sweeps from the retract point to the contact.
    let tip = Capsule::new(c, c + n * travel, TIP_CLEARANCE * probe.tip_radius);
    if intersection_test(&id, &tip, &id, mesh).unwrap_or(true) {
        return Some("the tip".into());
    }
    if !table_point
        && (c.coords.dot(up).min((c + n * travel).coords.dot(up))) - probe.tip_radius < t0 - 1e-9
    {
        return Some("the tip (on the table)".into());
    }
    let dir = if m.bent {
        super::domain::orientation_dir(up, m.grid[pip.orient].0, m.grid[pip.orient].1)
    } else {
        *up
    };
    let mut parts: Vec<(Component, V3, f64)> = Vec::new();
    if m.bent {
        for comp in &probe.first {
            parts.push((comp.clone(), dir, 0.0));
        }
        for comp in &probe.second {
            parts.push((comp.clone(), *up, probe.reach()));
        }
    } else {
        for comp in probe.straight() {
            parts.push((comp, *up, 0.0));
        }
    }
    for (comp, d, base) in &parts {
        // `base`: how far along the first component's direction the component starts.
        let origin = |t: f64| -> P3 { c + n * t + dir * *base };
        // The table: the lowest point is linear along the approach, so the ends decide.
        let low = lowest(comp, &origin(0.0), d, up).min(lowest(comp, &origin(travel), d, up));
        if low < t0 + TABLE_MARGIN {
            return Some(format!("the {} (on the table)", comp.name));
        }
        if component_hits(&k.scene, &origin(0.0), d, comp)
            || component_hits(&k.scene, &origin(travel), d, comp)
        {
            return Some(format!("the {}", comp.name));
        }
        let lateral = (n - d * n.dot(d)).norm();
        let grown = |extra: f64| Component {
            radius: comp.radius + extra,
            ..comp.clone()
        };
        // Two ends, radius grown by half the travel: covers every position between.
        let coarse = grown(travel / 2.0 * lateral);
        if !component_hits(&k.scene, &origin(0.0), d, &coarse)
            && !component_hits(&k.scene, &origin(travel), d, &coarse)
        {
            continue;
        }
        // Positions every SWEEP_STEP, radius grown by half a step.
        let steps = (travel / SWEEP_STEP).ceil().max(1.0) as usize;
        let fine = grown(travel / steps as f64 / 2.0 * lateral);
        for s in 0..=steps {
            if component_hits(
                &k.scene,
                &origin(travel * s as f64 / steps as f64),
                d,
                &fine,
            ) {
                return Some(format!("the {}", comp.name));
            }
        }
    }
    None
}
