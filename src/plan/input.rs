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
}

impl Ban {
    /// Whether the configuration is this one (directions to within the plan's
    /// quantisation, [`STEPS_PER_MM`]).
    pub(crate) fn is(&self, point: usize, probe: usize, up: &V3, dir: &V3) -> bool {
        let eps = 10.0 / STEPS_PER_MM;
        self.point == point
            && self.probe == probe
            && (self.up - up).norm() < eps
            && (self.dir - dir).norm() < eps
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
