//! Cones drawn again exactly where the rasterizer closed them: a probe on an extension
//! standing in a deep, narrow recess.

use crate::access::{self, ConeOptions, ProbeShape};
use crate::sample::Fpoint;
use rayon::prelude::*;

/// The share of the sphere below which a point's half-line cone marks it as seen through
/// a narrow opening: 1 %, a cone of about 11° half-angle.
const NARROW_SKY: f64 = 0.01;

/// The cones, drawn again with exact tests at their boundaries, of the pairs of a probe
/// on an extension whose rasterised approach cone is empty although the tip fits, at
/// points seen through a narrow opening (the half-line cone under [`NARROW_SKY`]). The
/// floor or a wall of a deep pocket or slot is reached by such a probe standing in it,
/// its extension a little narrower than the opening: a cone a few pixels wide at the
/// far end of a long recess, which the rasterizer's pessimism (whole cells, dilation
/// rounded up: `access::cpu`) closes. Elsewhere the pessimism stays: it is a margin the
/// search relies on. Drawn for every probe, the exact cones cost 10 of 140 MFCAD parts
/// their plan (the search no longer settled) for 18 gained; so only the extension's
/// pairs, and with every part above the stylus grown by the motion margin (`margin`),
/// the room validation asks of a move. The exact tests cost about 10 µs a
/// pixel (`access::refine`), spent only on these pairs.
pub(super) fn rescue_empty(
    scene: &access::Scene,
    items: &[(&Fpoint, &ProbeShape)],
    opts: &ConeOptions,
    margin: f64,
    cones: &mut [access::PointCones],
) {
    let exact = ConeOptions {
        exact_boundary: true,
        ..opts.clone()
    };
    let (n, pref) = (opts.n, &opts.preferred[..]);
    let redo: Vec<usize> = (0..items.len())
        .into_par_iter()
        .filter(|&k| on_extension(items[k].1))
        .filter(|&k| cones[k].tip_fits && cones[k].approach.is_empty())
        .filter(|&k| {
            let (f, probe) = items[k];
            let sky = access::gac_halfline(scene, &f.tip_centre(probe.tip_radius), n, pref);
            let cells = 6 * (n as usize).pow(2) + sky.preferred_len();
            (sky.count() as f64) < NARROW_SKY * cells as f64
        })
        .collect();
    let again: Vec<access::PointCones> = redo
        .par_iter()
        .map(|&k| {
            let grown = grown_past_stylus(items[k].1, margin);
            access::point_cones(exact.backend.get(), scene, items[k].0, &grown, &exact)
        })
        .collect();
    for (k, c) in redo.into_iter().zip(again) {
        if !c.approach.is_empty() {
            cones[k] = c;
        }
    }
}

/// Whether the probe carries its stylus on an extension: the rack's reach into deep
/// features, the one probe whose cones [`rescue_empty`] draws again.
fn on_extension(probe: &ProbeShape) -> bool {
    probe.first.len() > 2
}

/// The probe with its extensions and body (not its stylus, which meets the part at the
/// contact when grown) `by` mm thicker.
fn grown_past_stylus(probe: &ProbeShape, by: f64) -> ProbeShape {
    let mut grown = probe.clone();
    for c in grown.first.iter_mut().skip(1) {
        c.radius += by;
    }
    grown
}
