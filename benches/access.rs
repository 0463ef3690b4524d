//! Accessibility speed: the half-line GAC by the conservative CPU rasterizer against the
//! plain baseline of one exact ray per pixel centre (every triangle tested, no
//! acceleration), in the same run, at N = 32 and 64, at an fpoint's tip centre.
//!
//! Run with `cargo bench --bench access`.

use inspc::access::{gac_halfline, triangles_of, Cell, CubeMap};
use inspc::geometry::{line_triangle, P3};
use inspc::source::FsWorld;
use std::path::PathBuf;

fn main() {
    divan::main();
}

const CASES: [(&str, u32); 4] = [
    ("examples/swiss_block.insp", 32),
    ("examples/swiss_block.insp", 64),
    ("tests/real/nist_ctc_01.insp", 32),
    ("tests/real/nist_ctc_01.insp", 64),
];

/// The triangles and a tip centre (the middle fpoint, r = 1 mm) of a spec.
fn scene(spec: &str) -> (Vec<[P3; 3]>, P3) {
    let (_, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(spec)]);
    let g = &parts[graphs[0].part].as_ref().unwrap().geometry;
    let f = &graphs[0].graph.fpoints[graphs[0].graph.fpoints.len() / 2];
    (triangles_of(g), f.tip_centre(1.0))
}

#[divan::bench(args = CASES)]
fn halfline_raster(bencher: divan::Bencher, (spec, n): (&str, u32)) {
    let (tris, p) = scene(spec);
    bencher.bench(|| gac_halfline(divan::black_box(&p), &tris, n, &[]));
}

#[divan::bench(args = CASES)]
fn halfline_ray_per_pixel_baseline(bencher: divan::Bencher, (spec, n): (&str, u32)) {
    let (tris, p) = scene(spec);
    let dirs: Vec<_> = {
        let c = CubeMap::full(n, &[]);
        c.cells()
            .filter(|c| matches!(c, Cell::Pixel(_)))
            .map(|cell| (cell, c.direction(cell)))
            .collect()
    };
    bencher.bench(|| {
        let mut out = CubeMap::empty(n, &[]);
        for (cell, d) in &dirs {
            let free = !tris
                .iter()
                .any(|t| line_triangle(&p, d, &t[0], &t[1], &t[2]).is_some_and(|s| s > 1e-9));
            out.set(*cell, free);
        }
        out
    });
}
