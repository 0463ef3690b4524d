//! Validation (seed ch. 4.1): one primitive inspection plan — setup, probe, orientation,
//! fpoint — posed and checked by [`crate::access::pose`]: the tip sweeps from the retract
//! point to the contact, every other component is tested along the approach, the part is
//! an obstacle and the table is a plane under the part in that setup.
//!
//! Each PIP is validated at the nominal pose and with the part turned
//! [`PLACEMENT_TURN`] (3°) either way about the vertical (the stylus then stands turned
//! the other way in the part's frame): see `plan_placed` for why.

use super::knowledge::{Held, Knowledge};
use super::machine::Machine;
use crate::access::pose::{orientation_dir, Blocker};
use crate::geometry::V3;
use nalgebra::{Rotation3, Unit};

/// How far (degrees) the operator may set the part turned about the vertical from the
/// pose the setup's prompt asks for, and the program still run: the placement `inspc
/// verify` tries. The program follows the part (its alignment finds it), but an indexed
/// probe keeps its machine direction, so in the part's frame the stylus stands turned
/// by as much; a stylus fitted deep into a bore with little room beside its stem touches
/// the wall. Placing a part on a table by eye, square to the machine axes, to within
/// 3° is what an operator does without a fixture (the target of issue 44).
pub(crate) const PLACEMENT_TURN: f64 = 3.0;

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
    if banned(m, pip, up, bans) {
        return Err(Blocker::Path);
    }
    k.pose_check(m, pip.point, pip.probe, probe_dir(m, pip, up), *up, held)
}

/// Whether one of `bans` (the path stage's) covers a PIP in setup `up`.
pub(crate) fn banned(m: &Machine, pip: &Pip, up: &V3, bans: &[super::Ban]) -> bool {
    let dir = probe_dir(m, pip, up);
    bans.iter().any(|b| b.is(pip.point, pip.probe, up, &dir))
}

/// The probe's direction (tip to head, part frame) of a PIP in setup `up`.
fn probe_dir(m: &Machine, pip: &Pip, up: &V3) -> V3 {
    if m.head.indexable() {
        let (a, b) = m.grid[pip.orient];
        orientation_dir(up, a, b)
    } else {
        *up
    }
}

/// Whether a PIP that [`check`] passed stays clear with the part turned `turn` degrees
/// either way about the vertical (the stylus turned the other way in the part's frame).
/// A probe along the vertical turns into itself.
pub(crate) fn clear_turned(
    k: &Knowledge,
    m: &Machine,
    pip: &Pip,
    up: &V3,
    held: &Held,
    turn: f64,
) -> Result<(), Blocker> {
    for turned in turned_dirs(probe_dir(m, pip, up), up, turn) {
        k.pose_check(m, pip.point, pip.probe, turned, *up, held)?;
    }
    Ok(())
}

/// A probe direction `dir` turned `turn` degrees either way about `up` (the part set
/// off square under an indexed stylus); none where there is no turn or the probe
/// stands along `up` (it turns into itself).
pub(crate) fn turned_dirs(dir: V3, up: &V3, turn: f64) -> Vec<V3> {
    if turn <= 0.0 || dir.cross(up).norm() < 1e-9 {
        return Vec::new();
    }
    let axis = Unit::new_normalize(*up);
    [1.0, -1.0]
        .into_iter()
        .map(|sign| Rotation3::from_axis_angle(&axis, sign * turn.to_radians()) * dir)
        .collect()
}

/// The largest of the turns tried (degrees: `turn`, then 2, 1, 0.5, 0.25 and 0.1 where
/// smaller) with which the touch stays clear; 0 when only the nominal pose is.
pub(crate) fn tolerated_turn(
    k: &Knowledge,
    m: &Machine,
    pip: &Pip,
    up: &V3,
    held: &Held,
    turn: f64,
) -> f64 {
    [turn, 2.0, 1.0, 0.5, 0.25, 0.1]
        .into_iter()
        .filter(|&t| t <= turn)
        .find(|&t| clear_turned(k, m, pip, up, held, t).is_ok())
        .unwrap_or(0.0)
}
