//! Golden tests: one folder per case under `tests/golden/`. See `tests/README.md`.

use inspc::diag::{render_human, RenderOptions};
use inspc::source::FsWorld;
use std::path::Path;

mod common;
use common::{diff, spec_of};

enum Outcome {
    Model(String),
    Diagnostics(String),
}

fn run(spec: &Path) -> Outcome {
    let checked = inspc::check(&FsWorld, &[spec.to_path_buf()]);
    let opts = RenderOptions {
        width: 100,
        color: false,
    };
    let rendered: String = checked
        .diagnostics
        .iter()
        .map(|d| render_human(&checked.sources, d, opts))
        .collect();
    if checked.has_errors() {
        Outcome::Diagnostics(rendered)
    } else {
        Outcome::Model(checked.summary() + &rendered)
    }
}

#[test]
fn golden_cases() {
    let bless = std::env::var_os("INSPC_BLESS").is_some();
    let cases = common::cases("tests/golden", 15);
    let mut failures = Vec::new();
    for case in &cases {
        let name = case.file_name().unwrap().to_string_lossy().into_owned();
        let (model_file, diag_file) = (case.join("model.txt"), case.join("diagnostics.txt"));
        let (actual, this, other, state) = match run(&spec_of(case)) {
            Outcome::Model(m) => (m, &model_file, &diag_file, "passes"),
            Outcome::Diagnostics(d) => (d, &diag_file, &model_file, "fails"),
        };
        if other.exists() {
            failures.push(format!(
                "{name}: now {state}, but it expects {}; if that is intended, delete it and bless",
                other.file_name().unwrap().to_string_lossy()
            ));
            continue;
        }
        if bless {
            std::fs::write(this, &actual).unwrap();
            continue;
        }
        match std::fs::read_to_string(this) {
            Ok(expected) if expected == actual => {}
            Ok(expected) => failures.push(format!(
                "{name}: output differs from {}\n{}",
                this.display(),
                diff(&expected, &actual)
            )),
            Err(_) => failures.push(format!(
                "{name}: no expectation; run `INSPC_BLESS=1 cargo test --test golden`"
            )),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
