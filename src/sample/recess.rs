//! The margin a recess floor's points keep: the floor of a pocket or blind hole deeper
//! than a stylus is long is touched with the probe standing in the recess, so the part
//! of the probe still below the opening (an extension, the body) must clear the walls
//! where the tip reaches the floor's edge. Such a floor's points keep that part's radius
//! and [`WALL_CLEARANCE`] from the floor's edges, the probe chosen being the rack's
//! slimmest that is long enough (`geometry::recess_depth` measures the recess).
//!
//! Renishaw's stylus guidance (*Styli and accessories*, H-1000-3200) says the same from
//! the other side: reach a deep feature with a stylus "long enough to reach all
//! features", keeping the effective working length short, and an extension where the
//! stylus alone does not reach, which is what the rack offers; points the extension
//! cannot reach are points the program could not touch.

use crate::geometry::{box_exit, recess_depth, PartGeometry, Surface};

/// The clearance (mm) kept between a recess wall and the probe part beside it: the
/// default motion margin (1 mm, which the planner's moves keep) and half a millimetre.
const WALL_CLEARANCE: f64 = 1.5;
/// How far (mm) above a recess's opening the probe's head must stay.
const HEAD_CLEARANCE: f64 = 5.0;

/// One probe as the margin sees it: from the tip centre up its axis, where each part
/// above the stylus (extensions, body) begins and its radius. The stylus's stem is left
/// out: it is thinner than its tip, whose radius every point keeps anyway.
#[derive(Debug, Clone, PartialEq)]
pub struct Shank {
    /// (distance from the tip centre where the part begins, its radius), in order.
    parts: Vec<(f64, f64)>,
    /// Distance from the tip centre to the head.
    reach: f64,
}

impl Shank {
    /// A probe from its stylus's length to the ball centre, its extensions from the
    /// stylus upwards (length, radius) and its body (length, radius).
    pub fn new(stylus_length: f64, extensions: &[(f64, f64)], body: (f64, f64)) -> Shank {
        let mut parts = Vec::new();
        let mut at = stylus_length;
        for &(length, radius) in extensions.iter().chain([&body]) {
            parts.push((at, radius));
            at += length;
        }
        Shank { parts, reach: at }
    }

    /// The widest part above the stylus within `depth` of the tip centre (0 when the
    /// stylus alone spans the depth), when the probe is long enough to keep its head
    /// out of a recess that deep.
    fn widest_below(&self, depth: f64) -> Option<f64> {
        if self.reach < depth + HEAD_CLEARANCE {
            return None;
        }
        Some(
            self.parts
                .iter()
                .filter(|(start, _)| *start < depth)
                .map(|(_, r)| *r)
                .fold(0.0, f64::max),
        )
    }

    /// Whether a part of the probe that begins within `depth` of its tip centre would
    /// keep points further than `margin` from a wall.
    fn widens_within(&self, depth: f64, margin: f64) -> bool {
        self.parts
            .iter()
            .any(|(start, r)| *start < depth && r + WALL_CLEARANCE > margin)
    }
}

/// Per face, the margin its points keep: `margin`, or more on a recess floor whose
/// slimmest reaching probe is wider than that below the opening.
pub fn recess_margins(g: &PartGeometry, shanks: &[Shank], margin: f64) -> Vec<f64> {
    let (lo, hi) = g.bounds();
    let slimmest = |depth: f64| {
        shanks
            .iter()
            .filter_map(|s| s.widest_below(depth))
            .reduce(f64::min)
    };
    g.faces
        .iter()
        .map(|f| {
            let Surface::Plane { normal, .. } = f.surface else {
                return margin;
            };
            // Cheap first: a recess is no deeper than the part's box above the face.
            let room = box_exit(&lo, &hi, &f.centroid, &normal).unwrap_or(f64::INFINITY);
            if !shanks.iter().any(|s| s.widens_within(room + 1.0, margin)) {
                return margin;
            }
            match recess_depth(&g.vertices, &g.triangles, &f.triangles, &normal).and_then(slimmest)
            {
                Some(r) if r > 0.0 => margin.max(r + WALL_CLEARANCE),
                _ => margin,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_probe_is_as_wide_as_its_widest_part_in_the_recess() {
        // A stylus 50 mm long on a Ø4 extension 50 mm long on a Ø13.2 body 50 mm long.
        let s = Shank::new(50.0, &[(50.0, 2.0)], (50.0, 6.6));
        assert_eq!(s.widest_below(20.0), Some(0.0));
        assert_eq!(s.widest_below(57.0), Some(2.0));
        assert_eq!(s.widest_below(120.0), Some(6.6));
        // Its head would enter a recess 150 mm deep.
        assert_eq!(s.widest_below(150.0), None);
    }
}
