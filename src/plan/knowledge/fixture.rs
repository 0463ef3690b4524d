//! Setups whose fixture covers a point: out of that point's domain from the start.
//!
//! The cones see the part alone, so validation is what finds a fixture in the way, one
//! setup a round; a sine plate tried every 5° under eight faces offers hundreds of
//! setups, more than the search has rounds, and a face the plate clamps would stay
//! planned on the plate. The tip sweeps from the retract point to the contact along the
//! point's normal whatever the probe's orientation ([`access::pose::Pose::approach`]),
//! so where that sweep meets the fixture no orientation reaches the point: the setup is
//! taken out of the point's domain for that probe before the first round, as the table
//! takes out a face lying on it. A stylus or body meeting the fixture depends on the
//! orientation and stays with validation (sweeping every candidate orientation against
//! the fixture when D1′ is made made MFCAD builds several times slower).

use super::{Knowledge, Machine};
use crate::access;
use rayon::prelude::*;

impl Knowledge<'_> {
    /// Removes from every graph point's setups, per probe, the fixture setups in which
    /// the probe's tip meets the fixture on its approach to the point.
    pub(super) fn drop_tip_on_fixture(&mut self, machine: &Machine) {
        let real = &self.realisable;
        let cells: Vec<usize> = real.cells().map(|c| real.index(c)).collect();
        let mut held = Vec::new();
        for s in cells {
            let solids = &self.held(s).solids;
            if !solids.is_empty() {
                held.push((s, solids.clone()));
            }
        }
        if held.is_empty() {
            return;
        }
        let this = &*self;
        let blocked: Vec<Vec<(usize, usize)>> = (0..self.graph_points)
            .into_par_iter()
            .map(|f| {
                let point = &this.points[f];
                let mut out = Vec::new();
                for (p, probe) in machine.probes.iter().enumerate() {
                    if !this.dom[f][p].tip {
                        continue;
                    }
                    let r = probe.tip_radius;
                    let travel = access::pose::backoff(
                        &this.scene,
                        &point.position,
                        &point.normal,
                        r,
                        this.opts.retract,
                    );
                    let c = point.tip_centre(r);
                    for (s, solids) in &held {
                        let setup = &this.dom[f][p].setup;
                        if setup.get(setup.cell(*s))
                            && access::pose::tip_meets_fixture(solids, &c, &point.normal, travel, r)
                        {
                            out.push((p, *s));
                        }
                    }
                }
                out
            })
            .collect();
        for (f, pairs) in blocked.into_iter().enumerate() {
            for (p, s) in pairs {
                let setup = &mut std::sync::Arc::make_mut(&mut self.dom[f])[p].setup;
                let cell = setup.cell(s);
                setup.set(cell, false);
            }
        }
    }
}
