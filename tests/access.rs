//! The half-line GAC against brute force: one exact ray per pixel centre, at tip centres
//! of fpoints of every example and both NIST parts. The rasterizer must never call a
//! direction free that the exact ray finds blocked; agreement is reported.

mod common;

use inspc::access::{gac_halfline, triangles_of, Cell, CubeMap};
use inspc::geometry::line_triangle;
use inspc::source::FsWorld;
use std::path::PathBuf;

fn exact_blocked(
    p: &inspc::geometry::P3,
    tris: &[[inspc::geometry::P3; 3]],
    d: &inspc::geometry::V3,
) -> bool {
    tris.iter()
        .any(|t| line_triangle(p, d, &t[0], &t[1], &t[2]).is_some_and(|s| s > 1e-9))
}

/// (pixels compared, pixels that agree) over sampled fpoints of a spec.
fn verify(spec: &str, n: u32, every: usize) -> (usize, usize) {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(spec)]);
    assert!(!checked.has_errors(), "{spec}");
    let (mut total, mut agree) = (0usize, 0usize);
    for gr in &graphs {
        let g = &parts[gr.part].as_ref().unwrap().geometry;
        let tris = triangles_of(g);
        for f in gr.graph.fpoints.iter().step_by(every) {
            let p = f.tip_centre(1.0);
            let gac = gac_halfline(&p, &tris, n, &[]);
            let probe = CubeMap::full(n, &[]);
            for cell in probe.cells() {
                let Cell::Pixel(_) = cell else { continue };
                let d = probe.direction(cell);
                let blocked = exact_blocked(&p, &tris, &d);
                assert!(
                    !(blocked && gac.get(cell)),
                    "{spec}: direction {d:?} is blocked at {p:?} but reported free"
                );
                total += 1;
                agree += usize::from(blocked != gac.get(cell)); // blocked ⇔ not free
            }
        }
    }
    (total, agree)
}

#[test]
fn halfline_gac_is_conservative_on_the_examples() {
    for (spec, every) in [
        ("examples/f2.insp", 3),
        ("examples/f4.insp", 3),
        ("examples/swiss_block.insp", 61),
    ] {
        let (total, agree) = verify(spec, 32, every);
        let ratio = agree as f64 / total as f64;
        eprintln!(
            "{spec}: {agree}/{total} pixels agree ({:.2} %)",
            100.0 * ratio
        );
        assert!(
            ratio > 0.95,
            "{spec}: only {:.2} % of pixels agree",
            100.0 * ratio
        );
    }
}

#[test]
fn halfline_gac_is_conservative_on_nist_ctc_01() {
    common::require_shared_parts();
    let (total, agree) = verify("tests/real/nist_ctc_01.insp", 32, 19);
    let ratio = agree as f64 / total as f64;
    eprintln!(
        "nist_ctc_01: {agree}/{total} pixels agree ({:.2} %)",
        100.0 * ratio
    );
    assert!(ratio > 0.95, "only {:.2} % agree", 100.0 * ratio);
}
