//! Validation (seed ch. 4.1): one primitive inspection plan — setup, probe, orientation,
//! fpoint — posed and checked by [`crate::access::pose`]: the tip sweeps from the retract
//! point to the contact, every other component is tested along the approach, the part is
//! an obstacle and the table is a plane under the part in that setup.

use super::domain::{Held, Knowledge, Machine};
use crate::access::pose::{orientation_dir, Blocker};
use crate::geometry::V3;

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

/// Checks one PIP in setup `up` held as `held` says; what collides, if anything.
pub(crate) fn check(
    k: &Knowledge,
    m: &Machine,
    pip: &Pip,
    up: &V3,
    held: &Held,
    bans: &[super::Ban],
) -> Result<(), Blocker> {
    let dir = if m.head.indexable() {
        let (a, b) = m.grid[pip.orient];
        orientation_dir(up, a, b)
    } else {
        *up
    };
    if bans.iter().any(|b| b.is(pip.point, pip.probe, up, &dir)) {
        return Err(Blocker::Path);
    }
    k.pose_check(m, pip.point, pip.probe, dir, *up, held)
}
