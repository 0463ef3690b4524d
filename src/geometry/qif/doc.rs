//! Lookups and readers of a QIF document's values shared by its geometry and PMI
//! readers: elements by id, references, numbers, points and lengths in millimetres, and
//! the error for content that does not fit its type.

use super::xml::Node;
use super::QifError;
use crate::geometry::step::curve::{Curve, Frame};
use crate::geometry::{P3, V3};
use std::cell::{Cell, RefCell};
use std::collections::HashMap;

/// Lookups over the document.
pub struct Doc<'a> {
    /// Every element with an id.
    pub ids: HashMap<u64, &'a Node>,
    /// Millimetres of the part per length of its geometry: the file's unit divided by
    /// the product's scale coefficient.
    pub unit: f64,
    /// Millimetres per file length unit, for stated values (tolerances, sizes).
    pub value_unit: f64,
    /// How many more points the aggregates' sub-curves may be sampled at
    /// ([`MAX_SAMPLES`] for the document).
    pub samples: Cell<usize>,
    /// Curves read, by id: every edge on one shares it.
    pub curves: RefCell<HashMap<u64, (Curve, Option<P3>)>>,
}

/// How many points all the aggregate curves of a document may be sampled at together:
/// an aggregate's sub-curves become one polyline, so its points are what the file
/// costs to mesh (a million-triangle part has far fewer bound points).
pub(crate) const MAX_SAMPLES: usize = 4_000_000;

impl<'a> Doc<'a> {
    /// The element `id` refers to, from the element `from`.
    pub fn get(&self, id: u64, from: &Node) -> Result<&'a Node, QifError> {
        self.ids.get(&id).copied().ok_or(QifError::Missing {
            id,
            from: from.id(),
            line: from.line,
        })
    }

    /// The id in `<name><Id>…</Id></name>` under `n`.
    pub(crate) fn ref_id(&self, n: &Node, name: &str) -> Result<u64, QifError> {
        n.at(&[name, "Id"])
            .and_then(|i| i.text.trim().parse().ok())
            .ok_or_else(|| malformed(n, &format!("it has no <{name}><Id>")))
    }

    /// The ids listed under `n`'s child `name` (`<FaceIds><Id>…`).
    pub(crate) fn id_list(n: &Node, name: &str) -> Vec<u64> {
        n.child(name)
            .map(|l| {
                l.all("Id")
                    .filter_map(|i| i.text.trim().parse().ok())
                    .collect()
            })
            .unwrap_or_default()
    }
}

/// The error for an element whose content does not fit its type.
pub(crate) fn malformed(n: &Node, message: &str) -> QifError {
    QifError::Malformed {
        id: n.id(),
        element: n.name.to_string(),
        line: n.line,
        message: message.to_string(),
    }
}

/// The numbers of a child's text, exactly `len` of them.
fn nums(n: &Node, name: &str, len: usize) -> Result<Vec<f64>, QifError> {
    let c = n
        .child(name)
        .ok_or_else(|| malformed(n, &format!("it has no <{name}>")))?;
    match c.numbers() {
        Some(v) if v.len() == len => Ok(v),
        _ => Err(malformed(c, &format!("<{name}> is not {len} numbers"))),
    }
}

pub(super) fn num(n: &Node, name: &str) -> Result<f64, QifError> {
    Ok(nums(n, name, 1)?[0])
}

pub(super) fn vec3(n: &Node, name: &str) -> Result<V3, QifError> {
    let v = nums(n, name, 3)?;
    Ok(V3::new(v[0], v[1], v[2]))
}

impl Doc<'_> {
    pub(super) fn point(&self, n: &Node, name: &str) -> Result<P3, QifError> {
        Ok(P3::from(vec3(n, name)? * self.unit))
    }

    pub(super) fn length(&self, n: &Node, name: &str) -> Result<f64, QifError> {
        let x = num(n, name)? * self.unit;
        if x < 0.0 {
            return Err(malformed(n, &format!("<{name}> is negative")));
        }
        Ok(x)
    }
}

pub(super) fn frame(n: &Node, o: P3, z: V3, x: Option<V3>) -> Result<Frame, QifError> {
    Frame::new(o, Some(z), x).ok_or_else(|| malformed(n, "its directions are zero or parallel"))
}

/// The core element of a geometry element (`Plane23` → `Plane23Core`).
pub(super) fn core(n: &Node) -> Result<&Node, QifError> {
    let name = format!("{}Core", n.name);
    n.child(&name)
        .ok_or_else(|| malformed(n, &format!("it has no <{name}>")))
}

pub(super) fn positive(n: &Node, x: f64, what: &str) -> Result<(), QifError> {
    if x > 0.0 {
        Ok(())
    } else {
        Err(malformed(n, &format!("{what} is zero")))
    }
}

/// The `domain="a b"` of a curve core.
pub(super) fn domain(c: &Node) -> Option<(f64, f64)> {
    let v: Vec<f64> = c
        .attr("domain")?
        .split_ascii_whitespace()
        .map(|t| t.parse().ok())
        .collect::<Option<_>>()?;
    (v.len() == 2).then(|| (v[0], v[1]))
}
