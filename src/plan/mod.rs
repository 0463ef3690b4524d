//! Stage 8, the planner (seed ch. 3 and 4): measurement graph + machine → high-level
//! inspection plan (HLIP): setups, probes, probe orientations, and what each inspects.
//!
//! Generate and test: the knowledge base ([`domain`]) holds each fpoint's domain per
//! probe, starting from cheap half-line cones; the solver ([`solve`]) clusters up the
//! graph under the plan's constraint hierarchy with several deterministic clustering
//! strategies ([`cluster`]) and keeps the best plan by the hierarchy's violation counts;
//! every primitive inspection plan of it is validated with parry ([`validate`]); what
//! fails teaches the knowledge base (the whole probe's cones, then removal of the
//! configuration) and the loop repeats. The entry point is [`plan`].
//!
//! **Architecture Invariant:** the result is a function of the input alone: clustering
//! visits sets in graph order, ties go to the lower index, and parallel work (cones,
//! validation) is collected in input order.

mod account;
mod axes;
pub mod cluster;
mod errors;
mod explain;
mod fallback;
mod filter;
mod hlip;
mod input;
mod knowledge;
mod machine;
mod memo;
mod placement;
pub mod poses;
mod remeasure;
mod render;
mod scan;
mod search;
mod solve;
mod validate;

pub use errors::PlanError;
pub use explain::explain_setups;
pub use hlip::{
    FaceVisit, Hlip, Inspection, OrientNode, PlanPoint, PointRef, ProbeNode, SetupNode, Summary,
    STEPS_PER_MM,
};
pub use input::{Ban, Input, PlanOptions};
pub use machine::check_machine;
pub use memo::Memo;
pub use render::{json, text, Names};
pub use search::plan_with;

use crate::diag::Diagnostics;

/// Plans one plan: the entry point of the planner. Faces that cannot be inspected, and
/// a search that never gets a plan to validate, are reported in `diags` and give `None`;
/// a search that does not settle ends with the best plan found ([`fallback`]).
pub fn plan(input: &Input, opts: &PlanOptions, diags: &mut Diagnostics) -> Option<Hlip> {
    plan_with(input, opts, &mut Memo::default(), diags)
}
