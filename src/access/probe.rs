//! A probe as accessibility sees it: the tip ball, then a chain of components along the
//! probe's axis, each a solid of revolution around a stretch (a, b) of the half-line from
//! the tip centre (seed ch. 2.4; Álvarez et al. model column, head, probe and stylus the
//! same way).

use super::pose::Head;
use crate::model::{Cmm, HeadKind, Model, Probe};

/// How a component ends towards the tip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    /// A capsule: a ball of the component's radius at each end (stylus stems, extensions).
    Round,
    /// A cylinder with flat ends (probe bodies, heads, the ram).
    Flat,
}

/// One component: the points within `radius` of the stretch a ≤ t ≤ b of the axis
/// (a cylinder for [`End::Flat`], a capsule for [`End::Round`]). `b` may be infinite.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// What it is (`stylus`, `extension M2_EXT_30`, `body`, `head`, `ram`).
    pub name: String,
    /// Start, from the tip centre along the axis (mm).
    pub a: f64,
    /// End (mm); infinite for the ram.
    pub b: f64,
    /// Radius (mm); 0 for the seed's bare half-line.
    pub radius: f64,
    /// Its end shape.
    pub end: End,
}

impl Component {
    /// The seed's half-line (0, ∞): a stylus of no thickness and no end.
    pub fn half_line() -> Component {
        Component {
            name: "half-line".into(),
            a: 0.0,
            b: f64::INFINITY,
            radius: 0.0,
            end: End::Round,
        }
    }

    /// The nearest distance from the tip centre any point of the component can have.
    pub fn near(&self) -> f64 {
        match self.end {
            End::Round => (self.a - self.radius).max(0.0),
            End::Flat => self.a,
        }
    }

    /// The farthest distance any point of the component can have (infinite for the ram).
    pub fn far(&self) -> f64 {
        match self.end {
            End::Round => self.b + self.radius,
            End::Flat => self.b.hypot(self.radius),
        }
    }

    /// The component moved `by` mm along the axis (towards the head for positive).
    pub fn shifted(&self, by: f64) -> Component {
        Component {
            a: self.a + by,
            b: self.b + by,
            ..self.clone()
        }
    }
}

/// The head a machine's probes hang from, and its second components — head and ram —
/// for a first component reaching `reach` from the tip: from the articulation point of
/// an indexable head (a bent probe), or continuing the first on a fixed head.
pub(crate) fn second_components(model: &Model, cmm: &Cmm, reach: f64) -> (Head, Vec<Component>) {
    let head = &model.heads[cmm.head.0];
    let kind = match head.kind {
        HeadKind::Fixed => Head::Fixed,
        HeadKind::Indexable { .. } => Head::Indexable,
    };
    let base = match kind {
        Head::Indexable => 0.0,
        Head::Fixed => reach,
    };
    let second = vec![
        Component {
            name: "head".into(),
            a: base,
            b: base + head.length,
            radius: head.diameter / 2.0,
            end: End::Flat,
        },
        Component {
            name: "ram".into(),
            a: base + head.length,
            b: f64::INFINITY,
            radius: cmm.ram_radius,
            end: End::Flat,
        },
    ];
    (kind, second)
}

/// A probe on a machine: its tip and its components, from the tip up.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeShape {
    /// The probe's label in the machine's rack (or its name).
    pub name: String,
    /// The tip ball's radius (mm).
    pub tip_radius: f64,
    /// Stylus, extensions, body: the first component of a bent probe, from the tip.
    pub first: Vec<Component>,
    /// Head and ram, from the articulation point of an indexable head (at `d` from the
    /// tip centre), or continuing the first for a fixed head.
    pub second: Vec<Component>,
    /// The head it hangs from: fixed (a straight probe in the seed's terms) or
    /// indexable (a bent probe).
    pub head: Head,
}

impl ProbeShape {
    /// A probe as mounted on a machine's head.
    pub fn new(model: &Model, cmm: &Cmm, name: &str, probe: &Probe) -> ProbeShape {
        let stylus = &model.styli[probe.stylus.0];
        let mut first = vec![Component {
            name: "stylus".into(),
            a: 0.0,
            b: stylus.length,
            radius: stylus.stem / 2.0,
            end: End::Round,
        }];
        let mut at = stylus.length;
        // Extensions are listed from the body outwards; walk them from the stylus in.
        for e in probe.extensions.iter().rev() {
            let e = &model.extensions[e.0];
            first.push(Component {
                name: format!("extension {}", e.name),
                a: at,
                b: at + e.length,
                radius: e.diameter / 2.0,
                end: End::Round,
            });
            at += e.length;
        }
        let body = &model.bodies[probe.body.0];
        first.push(Component {
            name: "body".into(),
            a: at,
            b: at + body.length,
            radius: body.diameter / 2.0,
            end: End::Flat,
        });
        at += body.length;
        let (kind, second) = second_components(model, cmm, at);
        ProbeShape {
            name: name.into(),
            tip_radius: model.styli[probe.stylus.0].tip / 2.0,
            first,
            second,
            head: kind,
        }
    }

    /// The length d of the first component: from the tip centre to the articulation
    /// point.
    pub fn reach(&self) -> f64 {
        self.first.last().map_or(0.0, |c| c.b)
    }

    /// A bare stylus of `length` mm (Ø1 stem, Ø2 tip) on a head of `head`'s kind, with
    /// no body, head or ram: the probe the unit tests pose.
    #[cfg(test)]
    pub(crate) fn bare_stylus(length: f64, head: Head) -> ProbeShape {
        ProbeShape {
            name: "p".into(),
            tip_radius: 1.0,
            first: vec![Component {
                name: "stylus".into(),
                a: 0.0,
                b: length,
                radius: 0.5,
                end: End::Round,
            }],
            second: vec![],
            head,
        }
    }

    /// Every component of a straight probe (fixed head), from the tip up.
    pub fn straight(&self) -> Vec<Component> {
        self.first.iter().chain(&self.second).cloned().collect()
    }

    /// The components whose cones make the approach cone: the first component of a bent
    /// probe (the second is the setup's business), every component of a straight one.
    pub fn leading(&self) -> Vec<Component> {
        match self.head {
            Head::Indexable => self.first.clone(),
            Head::Fixed => self.straight(),
        }
    }

    /// The probes of a machine's rack.
    pub fn of_cmm(model: &Model, cmm: &Cmm) -> Vec<ProbeShape> {
        cmm.probes
            .iter()
            .map(|(label, id)| ProbeShape::new(model, cmm, label, &model.probes[id.0]))
            .collect()
    }
}
