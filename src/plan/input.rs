//! What the planner takes: the [`Input`] (model, plan, geometry, fixtures, measurement
//! graph) and the [`PlanOptions`] (cube-map resolution, round and search budgets, the
//! path stage's [`Ban`]s, the cones' backend).

use super::STEPS_PER_MM;
use crate::geometry::{PartGeometry, V3};
use crate::graph::MeasurementGraph;
use crate::model::{Model, Plan, PlanId};

/// Planner settings.
#[derive(Debug, Clone)]
pub struct PlanOptions {
    /// Cube-map resolution of the cones.
    pub n: u32,
    /// The most generate-and-test rounds before giving up.
    pub max_iterations: usize,
    /// Search nodes for the exact minimum number of setups.
    pub exact_budget: usize,
    /// Tolerances the plan cannot measure are warnings, not errors.
    pub allow_unmeasured: bool,
    /// Configurations the path stage found no move to: validation fails them.
    pub bans: Vec<Ban>,
    /// Which backend computes the cones.
    pub backend: crate::access::BackendKind,
}

/// A touch configuration the path stage could not reach: the point (index into
/// [`super::Hlip::points`]), the probe (rack index), the setup's up direction and the probe's
/// direction, both in the part frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Ban {
    /// The point.
    pub point: usize,
    /// The probe's rack index.
    pub probe: usize,
    /// The setup: the part direction facing the ram.
    pub up: V3,
    /// The probe direction, tip to head.
    pub dir: V3,
    /// Every direction of the probe at the point in this setup, not only `dir`: the
    /// path stage failed there twice ([`Ban::widen`]).
    pub any_dir: bool,
}

impl Ban {
    /// Whether the configuration is this one (directions to within the plan's
    /// quantisation, [`STEPS_PER_MM`]).
    pub(crate) fn is(&self, point: usize, probe: usize, up: &V3, dir: &V3) -> bool {
        let eps = 10.0 / STEPS_PER_MM;
        self.point == point
            && self.probe == probe
            && (self.up - up).norm() < eps
            && (self.any_dir || (self.dir - dir).norm() < eps)
    }

    /// The bans of a path failure, given those of the failures before: a point, probe
    /// and setup that failed before with another direction is banned in every
    /// direction. A re-plan that only turns the head for the same touch tends to turn
    /// it to a neighbour that fails the same way (a horizontal stylus in a narrow
    /// vertical passage, at another azimuth); the second failure says the probe does
    /// not get there in this setup, so the next re-plan takes another probe or setup.
    pub fn widen(new: Vec<Ban>, before: &[Ban]) -> Vec<Ban> {
        new.into_iter()
            .map(|mut b| {
                b.any_dir |= before.iter().any(|o| o.is(b.point, b.probe, &b.up, &o.dir));
                b
            })
            .collect()
    }
}

impl Default for PlanOptions {
    fn default() -> Self {
        PlanOptions {
            n: 64,
            max_iterations: 40,
            exact_budget: 200_000,
            allow_unmeasured: false,
            bans: Vec::new(),
            backend: crate::access::BackendKind::Cpu,
        }
    }
}

/// What planning needs.
pub struct Input<'a> {
    /// The model.
    pub model: &'a Model,
    /// The plan.
    pub plan: &'a Plan,
    /// The part's geometry.
    pub geometry: &'a PartGeometry,
    /// The mesh fixtures placed with the part.
    pub fixtures: &'a [crate::geometry::FixtureMesh],
    /// The plan's measurement graph.
    pub graph: &'a MeasurementGraph,
}

impl Input<'_> {
    /// The plan's id in the model.
    pub fn plan_id(&self) -> PlanId {
        PlanId(
            self.model
                .plans
                .iter()
                .position(|p| std::ptr::eq(p, self.plan))
                .unwrap_or(0),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::{Ban, V3};

    fn ban(point: usize, dir: V3) -> Ban {
        Ban {
            point,
            probe: 0,
            up: V3::z(),
            dir,
            any_dir: false,
        }
    }

    /// A second failure of a point, probe and setup bans every direction there; a
    /// first failure, or another point's, bans only its direction.
    #[test]
    fn a_second_failure_of_a_touch_bans_every_direction_of_its_probe() {
        let first = Ban::widen(vec![ban(7, V3::x())], &[]);
        assert!(!first[0].any_dir);
        assert!(!first[0].is(7, 0, &V3::z(), &V3::y()));
        let second = Ban::widen(vec![ban(7, V3::y()), ban(8, V3::y())], &first);
        assert!(second[0].any_dir);
        assert!(second[0].is(7, 0, &V3::z(), &-V3::x()));
        assert!(
            !second[0].is(7, 1, &V3::z(), &-V3::x()),
            "another probe stays free"
        );
        assert!(!second[1].any_dir);
    }
}
