//! A corpus of CAD parts end to end (issue 45): each STEP or QIF file of a folder imported
//! as `inspc import --scale S` writes it (the default inspection when the file has no
//! PMI), built as `inspc build` builds it, and its program verified as `inspc verify`
//! does (fewer placements: the battery of deviations is the same). One row per part,
//! then a summary: read, built, every tolerance measured, setups against the proven
//! minimum, programs the battery finds no problem in, median seconds.
//!
//! Run with `cargo bench --bench corpus`. The folder is `../shared/parts/mfcad` (the MFCAD
//! parts, modelled as 10-unit cubes of 100 mm blocks: scale 10) unless `INSPC_CORPUS`
//! names another; `INSPC_CORPUS_SCALE` sets the scale, `INSPC_CORPUS_LIMIT` takes the
//! first N files (by name), `INSPC_CORPUS_PLACEMENTS` the random placements verified
//! (default 4; 0 skips verification). Each part's spec and diagnostics stay in
//! `target/corpus/` to be read by hand.

use inspc::plan::PlanOptions;
use inspc::source::FsWorld;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn main() {
    let dir = PathBuf::from(env("INSPC_CORPUS", "../shared/parts/mfcad"));
    let scale: f64 = env("INSPC_CORPUS_SCALE", "10").parse().unwrap_or(10.0);
    let limit: usize = env("INSPC_CORPUS_LIMIT", "100000")
        .parse()
        .unwrap_or(100000);
    let placements: usize = env("INSPC_CORPUS_PLACEMENTS", "4").parse().unwrap_or(4);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    files.retain(|p| {
        let ext = p
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        matches!(ext.as_deref(), Some("step" | "stp" | "qif"))
    });
    files.sort();
    files.truncate(limit);
    if files.is_empty() {
        eprintln!("corpus: no STEP or QIF file in {}", dir.display());
        return;
    }
    let out = PathBuf::from("target/corpus");
    let _ = std::fs::create_dir_all(&out);
    println!("part | faces | tolerances | measured | setups | min | problems | s | note");
    let rows: Vec<Row> = files
        .iter()
        .map(|f| {
            let row = one(f, &out, scale, placements);
            println!("{}", row.line());
            row
        })
        .collect();
    summary(&rows);
}

fn env(key: &str, default: &str) -> String {
    std::env::var(key).unwrap_or_else(|_| default.to_string())
}

/// What became of one part.
#[derive(Default)]
struct Row {
    name: String,
    read: bool,
    faces: usize,
    built: bool,
    tolerances: usize,
    measured: usize,
    setups: usize,
    min_setups: (usize, bool),
    /// Problems the verification battery found (`None`: not verified).
    problems: Option<usize>,
    seconds: f64,
    /// The first error, or what was not inspected.
    note: String,
}

impl Row {
    fn line(&self) -> String {
        let min = match self.min_setups {
            (n, true) => n.to_string(),
            (n, false) => format!("≥{n}"),
        };
        let problems = self.problems.map_or("-".to_string(), |p| p.to_string());
        format!(
            "{} | {} | {} | {} | {} | {min} | {problems} | {:.2} | {}",
            self.name,
            self.faces,
            self.tolerances,
            self.measured,
            self.setups,
            self.seconds,
            self.note
        )
    }

    fn all_measured(&self) -> bool {
        self.built && self.tolerances > 0 && self.measured == self.tolerances
    }
}

fn one(file: &Path, out: &Path, scale: f64, placements: usize) -> Row {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut row = Row {
        name: stem.clone(),
        ..Row::default()
    };
    let start = Instant::now();
    let bytes = match std::fs::read(file) {
        Ok(b) => b,
        Err(e) => {
            row.note = format!("unreadable: {e}");
            return row;
        }
    };
    let absolute = std::fs::canonicalize(file).unwrap_or_else(|_| file.to_path_buf());
    let opts = inspc::import::ImportOptions {
        cad_path: absolute.to_string_lossy().into_owned(),
        part_name: inspc::import::identifier(&stem),
        scale,
    };
    let imported = match inspc::import::import(&bytes, &opts) {
        Ok(i) => i,
        Err(e) => {
            let mut why = format!("not read: {e:?}");
            why.truncate(160);
            row.note = why;
            row.seconds = start.elapsed().as_secs_f64();
            return row;
        }
    };
    row.read = true;
    row.faces = imported.faces;
    let spec = out.join(format!("{stem}.insp"));
    if std::fs::write(&spec, &imported.text).is_err() {
        row.note = "cannot write the spec".into();
        return row;
    }
    let r = inspc::run(
        &FsWorld,
        std::slice::from_ref(&spec),
        &PlanOptions::default(),
        inspc::Until::Build,
        &|_, _, _| {},
    );
    row.seconds = start.elapsed().as_secs_f64();
    let diagnostics: Vec<String> = r
        .checked
        .diagnostics
        .iter()
        .map(|d| format!("{:?} {}: {}", d.severity(), d.code(), d.message()))
        .collect();
    let _ = std::fs::write(
        out.join(format!("{stem}.diagnostics.txt")),
        diagnostics.join("\n"),
    );
    row.tolerances = r
        .checked
        .model
        .parts
        .first()
        .map_or(0, |p| p.tolerances.len());
    if let Some(e) = r
        .checked
        .diagnostics
        .iter()
        .find(|d| d.severity() == miette::Severity::Error)
    {
        row.note = format!("{}: {}", e.code(), e.message());
    }
    let Some(b) = r.built.first() else {
        if row.note.is_empty() {
            row.note = "no program".into();
        }
        return row;
    };
    row.built = !r.checked.has_errors();
    let s = &b.hlip.summary;
    row.measured = s.tolerances.0;
    row.setups = s.setups;
    row.min_setups = s.min_setups;
    if placements > 0 {
        let opts = inspc::verify::Options {
            placements,
            ..inspc::verify::Options::default()
        };
        row.problems = inspc::verify_built(&r, b, &opts).map(|v| v.problems());
    }
    row
}

fn summary(rows: &[Row]) {
    let n = rows.len();
    let count = |f: &dyn Fn(&Row) -> bool| rows.iter().filter(|r| f(r)).count();
    let pct = |k: usize| 100.0 * k as f64 / n as f64;
    let read = count(&|r| r.read);
    let built = count(&|r| r.built);
    let measured = count(&|r| r.all_measured());
    let at_min = count(&|r| r.built && r.setups == r.min_setups.0);
    let clean = count(&|r| r.built && r.problems == Some(0));
    let mut times: Vec<f64> = rows.iter().filter(|r| r.read).map(|r| r.seconds).collect();
    times.sort_by(f64::total_cmp);
    let median = times.get(times.len() / 2).copied().unwrap_or(0.0);
    let max = times.last().copied().unwrap_or(0.0);
    println!();
    println!("corpus: {n} parts");
    println!("  read                      {read} ({:.1} %)", pct(read));
    println!("  built                     {built} ({:.1} %)", pct(built));
    println!(
        "  every tolerance measured  {measured} ({:.1} %)",
        pct(measured)
    );
    println!("  setups at the minimum     {at_min} of {built} built");
    println!("  verified without problem  {clean} of {built} built");
    println!("  seconds per part          median {median:.2}, most {max:.2}");
    let mut causes: std::collections::BTreeMap<String, usize> = std::collections::BTreeMap::new();
    for r in rows.iter().filter(|r| !r.all_measured()) {
        let code = r.note.split(": ").next().unwrap_or("").to_string();
        *causes.entry(code).or_default() += 1;
    }
    for (code, k) in causes {
        println!("  not all measured: {k} × {code}");
    }
}
