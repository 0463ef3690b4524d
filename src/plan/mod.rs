//! Stage 8, the planner (seed ch. 3 and 4): measurement graph + machine → high-level
//! inspection plan (HLIP): setups, probes, probe orientations, and what each inspects.
//!
//! The four strategies are weighted, smallest first, graph order and reverse; the round
//! keeps the best plan by the hierarchy's violations, then setups and changes, and
//! validates its PIPs in parallel, each once. [`plan_with`] and a [`Memo`] keep the
//! pure results (cones, D2 caps, depth maps, grid orientations, the scene) for a
//! re-plan of the same input; the path stage's attempts share its scene.
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
//!
//! **Decision: learning.** A failed PIP first buys its point the whole probe's cones
//! (at most two points per face and probe a round: neighbours cluster together, ch.
//! 4.2); once the point has them, the failing setup is removed (its pixel and
//! neighbours for a fixed head; a 5° cap for a bent probe with no orientation left
//! there) (`learn`).
//!
//! **Decision: filtering** (ch. 3.6.3, `filter`) drops fpoints no probe reaches, and
//! those reached from under a twentieth of the face's median setups while the face
//! keeps half its points and its minimum (3 on a plane, 5 on a cylinder, 6 on a cone, 4
//! on a sphere); a face below its minimum is `insp::plan::uninspectable_face`. The end
//! circles of a round face whose axis a tolerance or datum reads are spared
//! (`axes::end_circles`). Where points drop, or a datum is measured again on the points
//! one setup reaches (`remeasure`), a plane keeps points spread across an area
//! (`spans_area`: a second principal spread of at least 0.5 mm), never a row a plane
//! cannot be fitted to.
//!
//! **Decision: how plans are compared** (`score`): the hierarchy's levels first
//! (violated same-constraints, level by level), then setups, probe changes, orientation
//! changes. Preferences act inside clustering: a preferred setup is picked for a
//! cluster whenever its underlying set holds it (`solve::pick_setup`), so it is used
//! whenever a plan there costs no more than one elsewhere at every level above.
//!
//! **Decision: robust to the part set off square** (`plan_placed`). The program follows
//! the part (its alignment finds it), but an indexed probe keeps its machine direction:
//! with the part turned about the vertical the stylus stands turned in the part's
//! frame, and a stylus deep in a bore with little room beside its stem touches the
//! wall. Every touch is validated also with the part turned `validate::PLACEMENT_TURN`
//! (3°, a part set by eye) either way; a point whose configurations collide only turned
//! takes one clear at the nominal pose after `FRAGILE_AFTER` (6) tries, and where no
//! turned plan settles (or none the path stage routes after its re-plans,
//! `Memo::give_up_turned`) the plan is made at the nominal pose. A setup with touches
//! clear only nearer square says by how much in its prompt and warns
//! `insp::plan::placement_sensitive` (`placement`). The turned validation triples the
//! pose checks, and a part no turned plan settles for is planned twice.
//!
//! **Decision: unmeasured tolerances are errors** (`account`). After planning, every
//! face of every feature and datum feature of each tolerance must be touched; one that
//! is not fails the build (`insp::plan::unmeasured`) unless `--allow-unmeasured`, which
//! also plans around a face no probe inspects
//! (`insp::plan::uninspectable_face_allowed`) instead of stopping.

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
