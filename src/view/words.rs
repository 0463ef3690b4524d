//! A setup in words for the viewer and its images: how the part is held, naming each
//! face as the spec does (the datum or feature measured on it; a face no feature names
//! by the side of the part it faces), and which way up it stands.

use crate::geometry::{FaceId, PartGeometry, Surface, V3};
use crate::model::FeatureId;
use crate::plan::{Names, SetupNode};

/// A face as the spec names it: `datum A` where a datum's feature holds it, `feature
/// top` where a feature does, else its name (`stock.bottom`) — but a face an import
/// only numbered (`face_105`) as the side of the part it faces (`the part's -z side`)
/// where it is a plane facing an axis. Faces of one datum or side read the same, and
/// the holder's list says each once.
fn face_words(names: &Names, face_feature: &[Option<usize>], f: FaceId) -> String {
    if let Some(k) = face_feature.get(f.0).copied().flatten() {
        let part = names.part();
        return match part.datums.iter().find(|d| d.feature == FeatureId(k)) {
            Some(d) => format!("datum {}", d.name),
            None => format!("feature {}", names.feature(Some(FeatureId(k)))),
        };
    }
    let name = names.face(f);
    match plane_side(names.geometry, f) {
        Some(side) if is_numbered(name) => format!("the part's {side} side"),
        _ => name.to_string(),
    }
}

/// Whether a face's name is only a number an import gave it (`face_105`, a STEP or QIF
/// face in shell order), not a name the spec wrote (`stock.bottom`).
fn is_numbered(name: &str) -> bool {
    name.strip_prefix("face_")
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
}

/// The axis a planar face's outward normal points along (`+x` … `-z`), if it does.
fn plane_side(g: &PartGeometry, f: FaceId) -> Option<&'static str> {
    match g.faces.get(f.0)?.surface {
        Surface::Plane { normal, .. } => axis_words(&normal),
        _ => None,
    }
}

/// An axis direction's name (`+x` … `-z`), within a thousandth.
fn axis_words(v: &V3) -> Option<&'static str> {
    const AXES: [([f64; 3], &str); 6] = [
        ([1.0, 0.0, 0.0], "+x"),
        ([-1.0, 0.0, 0.0], "-x"),
        ([0.0, 1.0, 0.0], "+y"),
        ([0.0, -1.0, 0.0], "-y"),
        ([0.0, 0.0, 1.0], "+z"),
        ([0.0, 0.0, -1.0], "-z"),
    ];
    AXES.iter()
        .find(|(a, _)| (v.x - a[0]).abs() + (v.y - a[1]).abs() + (v.z - a[2]).abs() < 1e-3)
        .map(|(_, n)| *n)
}

/// How setup `s` holds the part, its faces named by [`face_words`].
pub(crate) fn held_by(names: &Names, face_feature: &[Option<usize>], s: &SetupNode) -> String {
    names.holder_naming(&s.holder, &s.up, &|f| face_words(names, face_feature, f))
}

/// Which way up the part stands in a setup: `part +z up`, or the part-frame direction.
pub(crate) fn up_words(up: &V3) -> String {
    match axis_words(up) {
        Some(a) => format!("part {a} up"),
        None => {
            let r = |x: f64| crate::model::fmt_num((x * 1e3).round() / 1e3);
            format!("part ({}, {}, {}) up", r(up.x), r(up.y), r(up.z))
        }
    }
}
