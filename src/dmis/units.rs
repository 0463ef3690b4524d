//! The unit stretches a zone per unit length or area is checked on (ASME Y14.5-2018
//! § 5.4.1.4 straightness per unit length, § 5.4.2.2 flatness per unit area; ISO 1101
//! `0.02/25×25`).
//!
//! The standard's zone holds for *every* unit stretch of the feature, wherever it lies.
//! A CMM checks it on the touched points, as its software's "per unit" evaluation does:
//! the unit window stepped over the points and each window's points fitted and judged
//! on their own. DMIS 5.3 has no statement for a moving window, so the writer
//! constructs one feature per window from the touches that fall in it
//! (`CONST/PLANE,F(X_U3),BF,FA(X_P7),…`) and outputs the unit zone on each.
//!
//! **Decision: a window at every point.** A window's points are those of the window
//! whose edges run through its lowest points, so windows starting at every point's own
//! coordinates (and one flush with the last) hold every set of points any window of that
//! size holds, wherever it lies; of those, windows whose points another window holds
//! too are dropped (the larger set's zone is never narrower). A rectangle is tried both
//! ways round, the standard fixing no orientation; its long side first runs along the
//! direction the points spread most. A circle's windows are centred on the same steps. A
//! feature shorter than the unit is one window of all its points: the unit zone then
//! holds over the whole feature. With the sampler's rows a third of a unit apart
//! (`graph::PER_UNIT_ROWS`), a window on the face holds at least 3 × 3 points, and a
//! deviation narrower than a third of the unit may fall between rows: the program sees
//! abrupt change down to that width, as any sampled measurement sees down to its pitch.
//!
//! **Decision: a window needs enough points to fit.** A plane's window keeps at least
//! 4 points not on one line, a line's (straightness along a plane) 3, a cylinder's or
//! cone's 6 at two heights or more; a window with fewer lies mostly off the face (over a
//! hole, past an edge) and its points are judged in the windows beside it. Windows
//! with the same points are one.

use crate::geometry::{Surface, P3, V3};
use crate::model::UnitOf;
use crate::sample::perpendicular_basis;

/// The windows over `points` (nominal, on `surface`) for a unit stretch `unit`: each the
/// indices of the points inside it, in order. Empty where the surface has no windows
/// (a sphere, a free-form face).
pub(super) fn windows(surface: &Surface, unit: UnitOf, points: &[P3]) -> Vec<Vec<usize>> {
    let Some(frame) = Frame::of(surface, points) else {
        return Vec::new();
    };
    let coords: Vec<(f64, f64)> = points.iter().map(|p| frame.coords(p)).collect();
    // A rectangle lies either way round: the standard fixes no orientation.
    let shapes: Vec<(f64, f64)> = match unit {
        UnitOf::Length(l) => vec![(l, f64::INFINITY)],
        UnitOf::Rectangle(a, b) if (a - b).abs() <= EPS => vec![(a, b)],
        UnitOf::Rectangle(a, b) => vec![(a, b), (b, a)],
        UnitOf::Circle(d) => vec![(d, d)],
    };
    let mut sets: Vec<Vec<usize>> = Vec::new();
    for (su, sv) in shapes {
        for u0 in starts(coords.iter().map(|c| c.0), su) {
            for v0 in starts(coords.iter().map(|c| c.1), sv) {
                let inside = |c: &(f64, f64)| match unit {
                    UnitOf::Circle(d) => {
                        let (cu, cv) = (u0 + d / 2.0, v0 + d / 2.0);
                        (c.0 - cu).hypot(c.1 - cv) <= d / 2.0 + EPS
                    }
                    _ => {
                        c.0 >= u0 - EPS
                            && c.0 <= u0 + su + EPS
                            && c.1 >= v0 - EPS
                            && c.1 <= v0 + sv + EPS
                    }
                };
                let members: Vec<usize> =
                    (0..points.len()).filter(|&i| inside(&coords[i])).collect();
                if frame.fits(&members, &coords) {
                    sets.push(members);
                }
            }
        }
    }
    largest(sets)
}

/// How far outside a window a point on its edge may lie (mm).
const EPS: f64 = 1e-6;

/// Where the windows of size `size` start along a direction whose points lie at
/// `values`: at each point's own coordinate (the window whose edge it is), and one more
/// flush with the last point; one at the first point where the window is unbounded that
/// way. A window anywhere holds no point the window started at its first point's
/// coordinate does not.
fn starts(values: impl Iterator<Item = f64>, size: f64) -> Vec<f64> {
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= EPS);
    let (Some(&lo), Some(&hi)) = (v.first(), v.last()) else {
        return Vec::new();
    };
    if !size.is_finite() {
        return vec![lo];
    }
    let mut out: Vec<f64> = v.into_iter().filter(|x| *x + size < hi + EPS).collect();
    out.push(hi - size);
    out.sort_by(f64::total_cmp);
    out.dedup_by(|a, b| (*a - *b).abs() <= EPS);
    out
}

/// The sets none of the others contains, in their sorted order: a window whose points
/// all lie in another window is judged there (the larger set's fit is never flatter: a
/// minimum zone, ISO 12781-1, of a superset contains the subset's).
fn largest(mut sets: Vec<Vec<usize>>) -> Vec<Vec<usize>> {
    sets.sort();
    sets.dedup();
    let contains = |a: &Vec<usize>, b: &Vec<usize>| b.iter().all(|x| a.binary_search(x).is_ok());
    (0..sets.len())
        .filter(|&i| {
            !sets
                .iter()
                .any(|t| t.len() > sets[i].len() && contains(t, &sets[i]))
        })
        .map(|i| sets[i].clone())
        .collect()
}

/// The coordinates windows are laid out in: on a plane, the direction the points
/// spread most and the one across it; on a cylinder or cone, the axis (a length runs
/// along it, the whole way round).
struct Frame {
    origin: P3,
    u: V3,
    v: V3,
    kind: Kind,
}

#[derive(Clone, Copy, PartialEq)]
enum Kind {
    Plane,
    Round,
}

impl Frame {
    fn of(surface: &Surface, points: &[P3]) -> Option<Frame> {
        let origin = *points.first()?;
        match surface {
            Surface::Plane { normal, .. } => {
                let (e1, e2) = perpendicular_basis(normal);
                let u = spread_direction(points, &e1, &e2);
                Some(Frame {
                    origin,
                    u,
                    v: normal.cross(&u),
                    kind: Kind::Plane,
                })
            }
            Surface::Cylinder { axis, .. } | Surface::Cone { axis, .. } => Some(Frame {
                origin,
                u: *axis,
                v: V3::zeros(),
                kind: Kind::Round,
            }),
            _ => None,
        }
    }

    fn coords(&self, p: &P3) -> (f64, f64) {
        let d = p - self.origin;
        (d.dot(&self.u), d.dot(&self.v))
    }

    /// Whether the points `members` fix the window's feature and show its form.
    fn fits(&self, members: &[usize], coords: &[(f64, f64)]) -> bool {
        match self.kind {
            Kind::Plane => members.len() >= 4 && !collinear(members, coords),
            Kind::Round => {
                let heights = members
                    .iter()
                    .map(|&i| (coords[i].0 * 1e3).round() as i64)
                    .collect::<std::collections::BTreeSet<_>>();
                members.len() >= 6 && heights.len() >= 2
            }
        }
    }
}

/// Whether the points lie on one line (within a micrometre of the line through the two
/// farthest apart).
fn collinear(members: &[usize], coords: &[(f64, f64)]) -> bool {
    let p = |i: usize| coords[members[i]];
    let (mut a, mut b, mut far) = (0, 0, 0.0);
    for i in 0..members.len() {
        for j in i + 1..members.len() {
            let d = (p(i).0 - p(j).0).hypot(p(i).1 - p(j).1);
            if d > far {
                (a, b, far) = (i, j, d);
            }
        }
    }
    if far < EPS {
        return true;
    }
    let (ax, ay) = p(a);
    let (dx, dy) = ((p(b).0 - ax) / far, (p(b).1 - ay) / far);
    (0..members.len()).all(|i| ((p(i).0 - ax) * dy - (p(i).1 - ay) * dx).abs() < 1e-3)
}

/// The direction in the plane of `e1`, `e2` along which the points spread most (the
/// principal axis of their covariance), its sign fixed so that it is the same for the
/// same points in any order.
fn spread_direction(points: &[P3], e1: &V3, e2: &V3) -> V3 {
    let n = points.len() as f64;
    let c = points.iter().fold(V3::zeros(), |a, p| a + p.coords) / n;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for p in points {
        let d = p.coords - c;
        let (x, y) = (d.dot(e1), d.dot(e2));
        xx += x * x;
        xy += x * y;
        yy += y * y;
    }
    // The major axis of [[xx, xy], [xy, yy]] is at half the angle atan2(2xy, xx − yy).
    let angle = 0.5 * (2.0 * xy).atan2(xx - yy);
    let u = e1 * angle.cos() + e2 * angle.sin();
    // A square's covariance is round: the angle is then 0, along e1.
    if u.dot(e1) < -EPS || (u.dot(e1).abs() <= EPS && u.dot(e2) < 0.0) {
        -u
    } else {
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(nx: usize, ny: usize, step: f64) -> Vec<P3> {
        (0..ny)
            .flat_map(|j| (0..nx).map(move |i| P3::new(i as f64 * step, j as f64 * step, 0.0)))
            .collect()
    }

    fn plane() -> Surface {
        Surface::Plane {
            origin: P3::origin(),
            normal: V3::z(),
        }
    }

    #[test]
    fn a_square_unit_starts_at_every_row() {
        // 100 × 50 mm, rows 25/3 mm apart: 13 × 7 points; a 25 mm window holds 4 × 4.
        let pts = grid(13, 7, 100.0 / 12.0);
        let w = windows(&plane(), UnitOf::Rectangle(25.0, 25.0), &pts);
        // Starts along 100 mm: the 9 rows before 75, and 75; along 50 mm: 3 and 25.
        assert_eq!(w.len(), 40);
        assert!(w.iter().all(|m| m.len() == 16), "{w:?}");
    }

    #[test]
    fn a_rectangle_lies_both_ways_round() {
        let pts = grid(13, 7, 100.0 / 12.0);
        let one = windows(&plane(), UnitOf::Rectangle(25.0, 25.0), &pts).len();
        let both = windows(&plane(), UnitOf::Rectangle(25.0, 40.0), &pts);
        // 25 × 40: 4 × 5 points either way; none holds another's points.
        assert!(both.len() > one / 2, "{}", both.len());
        assert!(both.iter().all(|m| m.len() == 20));
    }

    #[test]
    fn windows_inside_others_are_dropped() {
        // A ragged edge: the short last column's windows lie in the full ones.
        let mut pts = grid(4, 4, 5.0);
        pts.push(P3::new(17.0, 2.0, 0.0));
        let w = windows(&plane(), UnitOf::Rectangle(16.0, 16.0), &pts);
        for (i, a) in w.iter().enumerate() {
            for (j, b) in w.iter().enumerate() {
                assert!(i == j || !b.iter().all(|x| a.contains(x)), "{w:?}");
            }
        }
    }

    #[test]
    fn a_plate_smaller_than_the_unit_is_one_window() {
        let pts = grid(3, 3, 5.0);
        let w = windows(&plane(), UnitOf::Rectangle(25.0, 25.0), &pts);
        assert_eq!(w, vec![(0..9).collect::<Vec<_>>()]);
    }

    #[test]
    fn a_length_takes_the_whole_width() {
        let pts = grid(13, 3, 100.0 / 12.0);
        let w = windows(&plane(), UnitOf::Length(25.0), &pts);
        assert_eq!(w.len(), 10);
        assert!(w.iter().all(|m| m.len() == 12));
    }

    #[test]
    fn a_window_on_one_line_is_dropped() {
        let pts = vec![
            P3::new(0.0, 0.0, 0.0),
            P3::new(10.0, 0.0, 0.0),
            P3::new(20.0, 0.0, 0.0),
            P3::new(30.0, 0.0, 0.0),
        ];
        assert!(windows(&plane(), UnitOf::Rectangle(50.0, 50.0), &pts).is_empty());
    }

    #[test]
    fn starts_at_each_value_and_end_flush() {
        let v = [0.0, 12.5, 25.0, 37.5, 50.0, 60.0];
        assert_eq!(starts(v.into_iter(), 25.0), vec![0.0, 12.5, 25.0, 35.0]);
        assert_eq!(starts([0.0, 20.0].into_iter(), 25.0), vec![-5.0]);
    }
}
