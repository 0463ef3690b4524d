//! Planning speed: the whole generate-and-test planner (knowledge, clustering with four
//! strategies, parry validation, learning) from measurement graph to HLIP, on the seed's
//! swiss-block (612 fpoints, fixed head) and swiss-sphere (140 fpoints, fixed and
//! indexable heads). The seed took 37 s, 249 s and 2,541 s on its 1999 hardware. The
//! front end and sampling are done once, outside the timing.
//!
//! Run with `cargo bench --bench plan`.

use inspc::plan::PlanOptions;
use inspc::source::FsWorld;
use std::path::PathBuf;

fn main() {
    divan::main();
}

#[divan::bench(args = [
    "examples/swiss_block.insp",
    "examples/swiss_sphere_fixed.insp",
    "examples/swiss_sphere_indexed.insp",
], sample_count = 3, sample_size = 1)]
fn plan(bencher: divan::Bencher, spec: &str) {
    let (checked, parts, graphs) = inspc::measurement_graphs(&FsWorld, &[PathBuf::from(spec)]);
    let model = &checked.model;
    let g = &graphs[0];
    let plan = model
        .plans
        .iter()
        .find(|p| Some(&p.name) == g.graph.plan.as_ref())
        .unwrap();
    let input = inspc::plan::Input {
        model,
        plan,
        geometry: &parts[g.part].as_ref().unwrap().geometry,
        fixtures: &parts[g.part].as_ref().unwrap().fixtures,
        graph: &g.graph,
    };
    bencher.bench_local(|| {
        let mut diags = inspc::diag::Diagnostics::new();
        inspc::plan::plan(&input, &PlanOptions::default(), &mut diags).unwrap()
    });
}
