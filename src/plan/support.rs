//! Support polygons: how far a part tips over an edge of what it stands on, and the
//! polygon's area — shared by the table's rest poses and the risers' pads.

/// The tipping angle (degrees) of a convex counter-clockwise polygon about its nearest
/// edge with the centre of mass over `c` at height `h`; negative when `c` is outside.
pub(crate) fn tip(poly: &[(f64, f64)], c: (f64, f64), h: f64) -> f64 {
    if poly.len() < 3 {
        return -90.0;
    }
    let mut d = f64::INFINITY;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let len = (ex * ex + ey * ey).sqrt();
        if len < 1e-12 {
            continue;
        }
        // Left of a counter-clockwise edge is inside.
        d = d.min((ex * (c.1 - a.1) - ey * (c.0 - a.0)) / len);
    }
    d.atan2(h.max(1e-9)).to_degrees()
}

/// The area of a simple polygon (shoelace formula).
pub(crate) fn polygon_area(poly: &[(f64, f64)]) -> f64 {
    let mut s = 0.0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        s += a.0 * b.1 - b.0 * a.1;
    }
    s.abs() / 2.0
}
