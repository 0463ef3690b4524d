//! The planner's diagnostics, as data: names, counts, directions and the cause of each
//! problem as an enum ([`Unreachable`], [`Shortfall`], [`LastRound`], a
//! [`Blocker`]); their words are written here, in the `#[error]`/`help` of each variant
//! and the `Display` of its causes, and nowhere else. The stages that find a problem
//! say what they found, not how to phrase it (`explain.rs`, `account.rs`, `search.rs`).

use crate::access::pose::Blocker;
use crate::geometry::V3;
use crate::model::fmt_num;
use crate::source::Span;
use std::fmt;

/// Why a plan could not be made.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub enum PlanError {
    #[error("face `{face}` of feature `{feature}` cannot be inspected: {why}")]
    #[diagnostic(
        code(insp::plan::uninspectable_face),
        help("{}{}", .why.remedy(), left_out(*.allowed))
    )]
    UninspectableFace {
        #[label("`{face}` is part of this feature")]
        span: Span,
        face: String,
        feature: String,
        why: Unreachable,
        /// Whether `--allow-unmeasured` plans on without the face (a warning).
        allowed: bool,
    },
    #[error("planning `{plan}` did not settle after {iterations} rounds of generate-and-test")]
    #[diagnostic(
        code(insp::plan::no_convergence),
        help("{last}; a probe with more clearance, or a preferred setup, usually settles it")
    )]
    NoConvergence {
        #[label("this plan")]
        span: Span,
        plan: String,
        iterations: usize,
        last: LastRound,
    },
    #[error("{left} of the {total} points {} `{face}` {} left out: generate-and-test did not settle after {iterations} rounds, and in the best plan found {}", if *.on_table { "on the table under face" } else { "of face" }, if *.left == 1 { "is" } else { "are" }, blocked(.probe, .blocker))]
    #[diagnostic(
        code(insp::plan::points_left_out),
        severity(Warning),
        help("{}", unblock(.blocker))
    )]
    PointsLeftOut {
        #[label("`{face}` is part of this feature")]
        span: Span,
        face: String,
        /// Whether the points are on the table under the face (a datum face's stand-in).
        on_table: bool,
        /// Distinct points left out, of `total`.
        left: usize,
        total: usize,
        iterations: usize,
        /// The probe tried last.
        probe: String,
        /// What it met.
        blocker: Blocker,
    },
    #[error("tolerance `{tolerance}` reads the axis of `{feature}` over {touched} mm of the {sampled} mm its points on face `{face}` span: the points beyond no probe reaches, so a tilt reads at {share} % of its size")]
    #[diagnostic(
        code(insp::plan::short_axis),
        severity(Warning),
        help("a longer stylus or an extension in the rack reaches the far end, or a fixture that presents the bore along one of the head's orientations; until then a tilt of the axis reads smaller than it is by that share")
    )]
    ShortAxis {
        #[label("this tolerance")]
        span: Span,
        tolerance: String,
        feature: String,
        face: String,
        touched: String,
        sampled: String,
        share: String,
    },
    #[error("setup {setup} of `{plan}` runs only with the part set square to the machine axes {within}, not within {full}°: turned more, the stylus hits the part at {touches}")]
    #[diagnostic(
        code(insp::plan::placement_sensitive),
        severity(Warning),
        help("the setup's prompt asks the operator to square the part {within}; a stop or fixture that squares it, or a stylus with more room beside its stem at these faces, lets the program find the part anywhere within {full}°")
    )]
    PlacementSensitive {
        #[label("this plan")]
        span: Span,
        plan: String,
        setup: usize,
        within: String,
        full: String,
        touches: String,
    },
    #[error("tolerance `{tolerance}` reads its feature in setup {setup} against {datums}, which no probe reaches there: the plan measures {measured}")]
    #[diagnostic(
        code(insp::plan::datum_in_other_setup),
        severity(Warning),
        help("setup {setup}'s alignment, built on that setup's own features, carries the datum over as drawn, so an error between the feature and the datum can read as none; give the head an orientation or the rack a probe that reaches the datum in setup {setup}, or hold the part so that one setup presents both")
    )]
    DatumInOtherSetup {
        #[label("read against a datum measured in another setup")]
        span: Span,
        tolerance: String,
        datums: String,
        setup: usize,
        measured: String,
    },
    #[error("part `{part}` does not fit on the table of `{cmm}`: its smallest footprint is {footprint}, the table {table}")]
    #[diagnostic(
        code(insp::plan::part_off_table),
        help("plan it on a machine with a larger table (`table {{ size (…) }}`), or check the part's units")
    )]
    PartOffTable {
        #[label("this plan")]
        span: Span,
        part: String,
        cmm: String,
        footprint: String,
        table: String,
    },
    #[error("probe `{probe}` of `{cmm}` reaches {reach} mm below the head, as far as the ram travels ({ram} mm) or more")]
    #[diagnostic(
        code(insp::plan::probe_too_long),
        help("a probe longer than the ram cannot be lifted clear of the table; use a shorter stylus or extension")
    )]
    ProbeTooLong {
        #[label("this plan")]
        span: Span,
        probe: String,
        cmm: String,
        reach: String,
        ram: String,
    },
    #[error("tolerance `{tolerance}` is not measured: face `{face}` of feature `{feature}` {why}")]
    #[diagnostic(
        code(insp::plan::unmeasured),
        help("{}; {}", .why.remedy(), if *.allowed { "the program leaves it out" } else { "`inspc build --allow-unmeasured` writes the program without it" })
    )]
    Unmeasured {
        #[label("this tolerance")]
        span: Span,
        tolerance: String,
        feature: String,
        face: String,
        why: Shortfall,
        /// Whether `--allow-unmeasured` plans on without it (a warning).
        allowed: bool,
    },
    #[error("part `{part}` has no plan, so there is no machine to plan for")]
    #[diagnostic(
        code(insp::plan::no_plan),
        help("add `plan <name> {{ part {part}, cmm <machine> }}` to the spec")
    )]
    NoPlan {
        #[label("this part")]
        span: Span,
        part: String,
    },
    #[error("plan `{plan}` has nothing to judge: part `{part}` has no tolerance")]
    #[diagnostic(
        code(insp::plan::no_tolerance),
        help("give part `{part}` the drawing's tolerances (`tolerance t = flatness(top, 0.05 mm)`); for a CAD file without PMI, `inspc import` writes a default inspection to start from")
    )]
    NoTolerance {
        #[label("a program of this plan would measure points and judge nothing")]
        span: Span,
        plan: String,
        part: String,
    },
}

crate::diag::located!(PlanError {
    Unmeasured,
    UninspectableFace,
    NoConvergence,
    PointsLeftOut,
    ShortAxis,
    PlacementSensitive,
    DatumInOtherSetup,
    NoPlan,
    NoTolerance,
    PartOffTable,
    ProbeTooLong,
});

/// Why no configuration inspects a face: the probe that came closest and what stopped it.
#[derive(Debug, Clone, PartialEq)]
pub enum Unreachable {
    /// The plan allows no probe.
    NoProbeAllowed,
    /// The probe reaches enough points, but only with the part in a pose it cannot take.
    OnlyInPose {
        probe: String,
        reach: usize,
        points: usize,
        /// The part direction that would point up.
        up: V3,
    },
    /// The probe reaches too few points.
    TooFew {
        probe: String,
        reach: usize,
        points: usize,
        need: usize,
        stop: Stop,
    },
}

/// What stops a probe at a face's first point it cannot reach.
#[derive(Debug, Clone, PartialEq)]
pub enum Stop {
    /// The tip does not fit with room to back off at enough points: `fits` of `points`.
    TipDoesNotFit {
        probe: String,
        diameter: f64,
        points: usize,
        fits: usize,
        travel: f64,
    },
    /// Every straight line from the tip centre meets the part.
    NoLine,
    /// A component meets the part in every direction those below it leave open.
    Component {
        name: String,
        diameter: f64,
        closest: V3,
    },
    /// Clear at the contact, not on the way out (or beyond the head's tilt).
    OnTheWay { closest: V3 },
}

impl Unreachable {
    /// The fix for this cause.
    fn remedy(&self) -> &'static str {
        match self {
            Unreachable::OnlyInPose { .. } => "name a fixture that holds the part so (`fixtures [vise: VISE_150]` on the CMM, `fixtures [vise]` in the plan: a vise, a chuck, a sine or angle plate from `std::fixtures`); `inspc plan --explain-setups` lists the poses the part can take",
            _ => "use a smaller tip, a longer or thinner stylus, an extension, or an indexable head; `inspc cones --face` shows the cones",
        }
    }
}

impl fmt::Display for Unreachable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Unreachable::NoProbeAllowed => write!(f, "no probe is allowed"),
            Unreachable::OnlyInPose { probe, reach, points, up } => write!(
                f,
                "probe {probe} reaches {reach} of its {points} points only with the part turned so that {} points up, a pose in which it does not stand on the table and no fixture of the plan holds it",
                Dir(*up)
            ),
            Unreachable::TooFew { probe, reach, points, need, stop } => write!(
                f,
                "probe {probe} reaches {reach} of its {points} points (it needs {need}); {stop}"
            ),
        }
    }
}

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stop::TipDoesNotFit { probe, diameter, points, fits: 0, travel } => write!(
                f,
                "probe {probe}'s Ø{} mm tip does not fit at any of its {points} points with {} mm to back off the surface",
                fmt_num(*diameter),
                fmt_num(*travel)
            ),
            Stop::TipDoesNotFit { probe, diameter, points, fits, travel } => write!(
                f,
                "probe {probe}'s Ø{} mm tip fits at only {fits} of its {points} points with {} mm to back off the surface",
                fmt_num(*diameter),
                fmt_num(*travel)
            ),
            Stop::NoLine => write!(f, "no straight line leaves the tip centre without meeting the part"),
            Stop::Component { name, diameter, closest } => write!(
                f,
                "its {name} (Ø{} mm) meets the part from every direction the parts below it leave open; closest along {}",
                fmt_num(*diameter),
                Dir(*closest)
            ),
            Stop::OnTheWay { closest } => write!(
                f,
                "every component clears the part at the contact along {}, but not on the way to the retract point, or the head cannot tilt that far",
                Dir(*closest)
            ),
        }
    }
}

/// Why a tolerance's face is not measured by the plan.
#[derive(Debug, Clone, PartialEq)]
pub enum Shortfall {
    /// The face is asked of the laser scanner, which sees too little of it.
    Scanner {
        /// The best share seen, 0–1.
        best: f64,
        /// The face seen too little, where it is another face of the feature.
        other_face: Option<String>,
        /// The share the plan asks, 0–1.
        asked: f64,
    },
    /// Touched, but fewer times than its surface's fit needs.
    FewTouches(usize),
    /// Sampled, but no touch kept.
    NoTouch,
    /// No measuring point kept the sampling margin.
    NoPoint,
}

impl Shortfall {
    /// The fix for this cause.
    fn remedy(&self) -> &'static str {
        match self {
            Shortfall::Scanner { .. } => "touch it instead (`sensors { … touch }`), hold the part so the scanner sees more of it (a fixture), or lower `scan_coverage`",
            Shortfall::FewTouches(_) => "its other points were left out as hard to reach; a probe that reaches more of them, or more points (`sample`), keeps it",
            Shortfall::NoTouch => "its points were dropped as hard to reach; a probe that reaches more of them, or more points (`sample`), keeps it",
            Shortfall::NoPoint => "no point of it keeps the sampling margin from its edges; lower the sampling inset",
        }
    }
}

impl fmt::Display for Shortfall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Shortfall::Scanner {
                best,
                other_face,
                asked,
            } => {
                write!(
                f,
                "is asked of the laser scanner, which sees {} % of {} at best (the plan asks {} %)",
                percent(*best),
                other_face.as_ref().map_or("it".to_string(), |o| format!("face {o}")),
                percent(*asked)
            )
            }
            Shortfall::FewTouches(1) => write!(
                f,
                "gets 1 touch in the plan, fewer than its surface's fit needs"
            ),
            Shortfall::FewTouches(n) => write!(
                f,
                "gets {n} touches in the plan, fewer than its surface's fit needs"
            ),
            Shortfall::NoTouch => write!(f, "gets no touch in the plan"),
            Shortfall::NoPoint => write!(f, "gets no measuring point"),
        }
    }
}

/// Why the last round of generate-and-test failed, for the diagnostic when none settles.
#[derive(Debug, Clone, PartialEq)]
pub enum LastRound {
    /// No round ran.
    NotRun,
    /// Points found no probe orientation.
    NoOrientation(usize),
    /// Touches failed validation: per face name, how many, and the first cause — the
    /// probe and what it hit (all faces, sorted by name; four are named).
    Failed(Vec<(String, usize, String, Blocker)>),
}

impl fmt::Display for LastRound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LastRound::NotRun => write!(f, "no round was run"),
            LastRound::NoOrientation(n) => write!(f, "{n} points found no probe orientation"),
            LastRound::Failed(faces) => {
                write!(f, "in the last round touches failed on ")?;
                for (i, (face, n, probe, hit)) in faces.iter().take(4).enumerate() {
                    let sep = if i == 0 { "" } else { ", " };
                    write!(f, "{sep}{face} ({n} touches; probe {probe} hits {hit})")?;
                }
                match faces.len().saturating_sub(4) {
                    0 => Ok(()),
                    more => write!(f, " and {more} more faces"),
                }
            }
        }
    }
}

/// What the probe tried last met, in words.
fn blocked(probe: &str, blocker: &Blocker) -> String {
    match blocker {
        Blocker::Tip => format!("the tip of probe {probe} meets the part coming in or backing off"),
        Blocker::TipOnTable => format!("the tip of probe {probe} comes too near the table"),
        Blocker::Component(c) => format!("the {c} of probe {probe} meets the part"),
        Blocker::ComponentOnTable(c) => {
            format!("the {c} of probe {probe} comes too near the table")
        }
        Blocker::Fixture(c) => format!("the {c} of probe {probe} meets the fixture"),
        Blocker::Path => format!("no collision-free move brings probe {probe} to it"),
    }
}

/// The fix for what a probe met.
fn unblock(blocker: &Blocker) -> &'static str {
    match blocker {
        Blocker::Tip => "the tip meets the part on its way in or out: shorten `motion { retract }` and `prehit`, or use a smaller tip",
        Blocker::TipOnTable | Blocker::ComponentOnTable(_) => "the probe comes down to the table here: risers that lift the part (`fixture` of `kind risers`, std::fixtures::RISERS_25, named in the plan's `fixtures [..]`), another setup, or a probe with a longer stylus",
        Blocker::Component(_) => "a longer or thinner stylus, an extension, or another setup (`prefer setup`) gives the probe room",
        Blocker::Fixture(_) => "another fixture, or a setup on the table, leaves this face free; `inspc plan --explain-setups` lists them",
        Blocker::Path => "a longer stylus, another orientation or a larger `motion { clearance }` may open a way to it",
    }
}

/// The help's tail for a face `--allow-unmeasured` plans on without.
fn left_out(allowed: bool) -> &'static str {
    if allowed {
        "; the program leaves it out"
    } else {
        ""
    }
}

/// A share 0–1 as a percentage with one decimal.
fn percent(share: f64) -> String {
    fmt_num((share * 1000.0).round() / 10.0)
}

/// A direction rounded to three decimals: `(0, 0.707, 0.707)`.
struct Dir(V3);

impl fmt::Display for Dir {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = |v: f64| fmt_num((v * 1e3).round() / 1e3);
        write!(f, "({}, {}, {})", r(self.0.x), r(self.0.y), r(self.0.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn causes_read_as_sentences() {
        let up = V3::new(0.0, 0.6, -0.8);
        let pose = Unreachable::OnlyInPose {
            probe: "P1".into(),
            reach: 4,
            points: 6,
            up,
        };
        assert!(pose
            .to_string()
            .contains("so that (0, 0.6, -0.8) points up"));
        assert!(pose.remedy().starts_with("name a fixture"));
        let few = Unreachable::TooFew {
            probe: "P1".into(),
            reach: 0,
            points: 3,
            need: 3,
            stop: Stop::TipDoesNotFit {
                probe: "P1".into(),
                diameter: 2.0,
                points: 3,
                fits: 0,
                travel: 0.5,
            },
        };
        assert_eq!(
            few.to_string(),
            "probe P1 reaches 0 of its 3 points (it needs 3); probe P1's Ø2 mm tip does not fit at any of its 3 points with 0.5 mm to back off the surface"
        );
        let some = Unreachable::TooFew {
            probe: "P1".into(),
            reach: 1,
            points: 9,
            need: 3,
            stop: Stop::TipDoesNotFit {
                probe: "P1".into(),
                diameter: 1.0,
                points: 9,
                fits: 2,
                travel: 0.5,
            },
        };
        assert_eq!(
            some.to_string(),
            "probe P1 reaches 1 of its 9 points (it needs 3); probe P1's Ø1 mm tip fits at only 2 of its 9 points with 0.5 mm to back off the surface"
        );
        assert_eq!(
            Shortfall::FewTouches(1).to_string(),
            "gets 1 touch in the plan, fewer than its surface's fit needs"
        );
        let scan = Shortfall::Scanner {
            best: 0.4567,
            other_face: None,
            asked: 0.8,
        };
        assert!(scan
            .to_string()
            .contains("sees 45.7 % of it at best (the plan asks 80 %)"));
    }

    #[test]
    fn the_last_round_names_four_faces_and_counts_the_rest() {
        let faces = (0..6)
            .map(|i| (format!("f{i}"), 2, "P1".to_string(), Blocker::Tip))
            .collect();
        let text = LastRound::Failed(faces).to_string();
        assert!(text.starts_with(
            "in the last round touches failed on f0 (2 touches; probe P1 hits the tip), f1"
        ));
        assert!(text.ends_with("f3 (2 touches; probe P1 hits the tip) and 2 more faces"));
        assert_eq!(
            blocked("P2", &Blocker::Path),
            "no collision-free move brings probe P2 to it"
        );
    }

    #[test]
    fn points_left_out_on_the_table_say_so() {
        let e = PlanError::PointsLeftOut {
            span: Span::new(crate::source::FileId(0), 0, 0),
            face: "A".into(),
            on_table: true,
            left: 1,
            total: 4,
            iterations: 40,
            probe: "p1".into(),
            blocker: Blocker::TipOnTable,
        };
        let text = e.to_string();
        assert!(text.starts_with("1 of the 4 points on the table under face `A` is left out"));
    }
}
