//! Stage 8, the planner (seed ch. 3 and 4): measurement graph + machine → high-level
//! inspection plan (HLIP): setups, probes, probe orientations, and what each inspects.
//!
//! The four strategies are weighted, smallest first, graph order and reverse; the round
//! keeps the best plan by the hierarchy's violations, then setups and changes, and
//! validates its PIPs in parallel, each once. [`plan_with`] and a [`Memo`] keep the
//! pure results (cones, D2 caps, depth maps, grid orientations, the scene) for a
//! re-plan of the same input; the path stage's attempts share its scene.
//!
//! Generate and test ([`search`]): the knowledge base ([`knowledge`]) holds each fpoint's
//! domain per probe, starting from cheap half-line cones; the solver ([`solve`]) clusters
//! up the graph under the plan's constraint hierarchy with several deterministic
//! clustering strategies ([`cluster`]) and keeps the best plan by the hierarchy's
//! violation counts; every primitive inspection plan of it is validated with parry
//! ([`validate`]); what fails teaches the knowledge base (the whole probe's cones, then
//! removal of the configuration) and the loop repeats. The entry point is [`plan`].
//!
//! The files: [`input`] what planning takes; [`search`] the rounds; [`filter`] which
//! points a round plans; [`knowledge`] and [`memo`] what is known and what a re-plan
//! reuses; [`machine`] the machine as the planner sees it; [`solve`] and [`cluster`] the
//! clustering; [`validate`] and [`placement`] the checks of a touch; [`hlip`] and
//! [`render`] the result; [`account`] what it measures; [`remeasure`], [`axes`],
//! [`poses`], [`scan`], [`fallback`] and [`explain`] the rules named for them.
//!
//! **Architecture Invariant:** the result is a function of the input alone: clustering
//! visits sets in graph order, ties go to the lower index, and parallel work (cones,
//! validation) is collected in input order.
//!

mod account;
mod axes;
pub mod cluster;
mod dense;
mod errors;
mod explain;
mod fallback;
mod filter;
mod hlip;
mod input;
mod journal;
mod knowledge;
mod machine;
mod memo;
mod placement;
pub mod poses;
mod remeasure;
mod render;
mod risers;
mod roomy;
mod scan;
mod search;
mod solve;
mod support;
mod validate;

pub use errors::PlanError;
pub use explain::explain_setups;
pub(crate) use filter::spans_area;
pub(crate) use hlip::STEPS_PER_MM;
pub use hlip::{
    FaceVisit, Hlip, Inspection, OrientNode, PlanPoint, PointRef, ProbeNode, SetupNode, Summary,
};
pub use input::{Ban, Input, PlanOptions};
pub use machine::check_machine;
pub use memo::Memo;
pub use render::{json, text, Names};
pub use search::plan_with;
pub(crate) use validate::{turned_dirs, PLACEMENT_TURN};

use crate::diag::Diagnostics;

/// Plans one plan: the entry point of the planner. Faces that cannot be inspected, and
/// a search that never gets a plan to validate, are reported in `diags` and give `None`;
/// a search that does not settle ends with the best plan found ([`fallback`]).
pub fn plan(input: &Input, opts: &PlanOptions, diags: &mut Diagnostics) -> Option<Hlip> {
    plan_with(input, opts, &mut Memo::default(), diags)
}
