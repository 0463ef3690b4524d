//! Planning at density (issue 47): CTC 02 and FTC 06 built with `hammersley(points N)` on
//! every face, one row per N — the points the plan holds (fpoints and table points), touches, setups, probes, orientations, the plan
//! stage's and the whole build's seconds, and the peak memory — so that growth, and any
//! change of setups or probes with density, shows at a glance. The plan at the spec's own
//! sampling is the first row of each part: the baseline in the same run.
//!
//! Each row runs in a child process (this binary again, `INSPC_DENSITY_ONE=spec:N`), so its
//! peak memory (`VmHWM`) is its own. Sizes are `INSPC_DENSITY_SIZES` (default
//! `12,48,200,455`: 10,010 points on CTC 02's 22 sampled faces; FTC 06's 108 faces pass
//! the 20,000-point limit at 455 and say so). A build that fails prints its diagnostic
//! codes in place of the counts.
//!
//! Run with `cargo bench --bench density` (needs `../shared/parts`).

use inspc::plan::PlanOptions;
use inspc::source::FsWorld;
use std::path::PathBuf;
use std::time::Instant;

const SPECS: [&str; 2] = ["tests/real/nist_ctc_02.insp", "tests/real/nist_ftc_06.insp"];

fn main() {
    if let Ok(one) = std::env::var("INSPC_DENSITY_ONE") {
        let (spec, n) = one.split_once(':').expect("spec:N");
        println!("{}", row(spec, n.parse().ok()));
        return;
    }
    let sizes: Vec<usize> = std::env::var("INSPC_DENSITY_SIZES")
        .unwrap_or_else(|_| "12,48,200,455".into())
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let me = std::env::current_exe().expect("this bench's path");
    println!(
        "{:<28} {:>6} {:>7} {:>7} {:>6} {:>6} {:>7} {:>8} {:>8} {:>8}",
        "part",
        "N",
        "points",
        "touches",
        "setups",
        "probes",
        "orients",
        "plan s",
        "build s",
        "peak MiB"
    );
    for spec in SPECS {
        if !std::path::Path::new(spec).exists() {
            continue;
        }
        let runs = std::iter::once("spec".to_string()).chain(sizes.iter().map(|n| n.to_string()));
        for n in runs {
            let out = std::process::Command::new(&me)
                .env("INSPC_DENSITY_ONE", format!("{spec}:{n}"))
                .output()
                .expect("the bench runs itself");
            print!("{}", String::from_utf8_lossy(&out.stdout));
        }
    }
}

/// One build of `spec`, at `n` Hammersley points a face (`None`: its own sampling), as a
/// row of the table.
fn row(spec: &str, n: Option<usize>) -> String {
    let text = std::fs::read_to_string(spec).expect("the spec");
    let text = match n {
        Some(n) => dense(&absolute_meshes(&text, spec), n),
        None => absolute_meshes(&text, spec),
    };
    // Written where the build can read it, its mesh named by an absolute path.
    let dir = PathBuf::from("target/density");
    std::fs::create_dir_all(&dir).expect("target/density");
    let path = dir.join(format!("{}.insp", std::process::id()));
    std::fs::write(&path, text).expect("the dense spec");
    let started = Instant::now();
    let (checked, built, timings) = inspc::build(
        &FsWorld,
        std::slice::from_ref(&path),
        &PlanOptions::default(),
        &|_, _, _| {},
    );
    let secs = started.elapsed().as_secs_f64();
    std::fs::remove_file(&path).ok();
    let plan = timings
        .stages
        .iter()
        .filter(|s| s.0 == "plan")
        .map(|s| s.1)
        .sum::<f64>();
    let name = std::path::Path::new(spec)
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let n = n.map_or("spec".into(), |n| n.to_string());
    let peak = peak_mib();
    let Some(b) = built.first() else {
        let mut codes: Vec<String> = checked
            .diagnostics
            .iter()
            .filter(|d| d.severity() == miette::Severity::Error)
            .map(|d| d.code().to_string())
            .collect();
        codes.dedup();
        return format!(
            "{name:<28} {n:>6} failed after {secs:.1} s ({peak:.0} MiB): {}",
            codes.join(", ")
        );
    };
    let s = &b.hlip.summary;
    let fpoints = b.hlip.points.len();
    format!(
        "{name:<28} {n:>6} {fpoints:>7} {:>7} {:>6} {:>6} {:>7} {plan:>8.2} {secs:>8.2} {peak:>8.0}",
        s.points, s.setups, s.probes_used, s.orientations
    )
}

/// The spec's `mesh "…"` paths made absolute (they are relative to the spec's folder).
fn absolute_meshes(text: &str, spec: &str) -> String {
    let folder = std::path::Path::new(spec)
        .parent()
        .map(|p| p.canonicalize().unwrap_or_else(|_| p.to_path_buf()))
        .unwrap_or_default();
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        match line.trim_start().strip_prefix("mesh \"") {
            Some(rest) => {
                let (path, tail) = rest.split_once('"').unwrap_or((rest, ""));
                let indent = &line[..line.len() - line.trim_start().len()];
                let full = folder.join(path);
                out.push_str(&format!("{indent}mesh \"{}\"{tail}", full.display()));
            }
            None => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

/// The spec with a sampling of `n` Hammersley points on every surface kind, for its plan.
fn dense(text: &str, n: usize) -> String {
    let plan_at = text.find("\nplan ").expect("the spec has a plan");
    let open = plan_at + text[plan_at..].find('{').expect("the plan's body");
    let mut out = String::with_capacity(text.len() + 256);
    out.push_str(&text[..=open]);
    out.push_str("\n    sampling dense");
    out.push_str(&text[open + 1..]);
    out.push_str(&format!(
        "\nsampling dense {{\n    plane hammersley(points {n})\n    cylinder hammersley(points {n})\n    cone hammersley(points {n})\n    sphere hammersley(points {n})\n    freeform hammersley(points {n})\n}}\n"
    ));
    out
}

/// This process's peak resident memory (MiB), from `/proc/self/status` (0 elsewhere).
fn peak_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(0.0, |kb| kb / 1024.0)
}
