//! Helpers shared by the integration tests.
#![allow(dead_code)]

use inspc::source::MemoryWorld;
use std::path::PathBuf;

/// One diagnostic, flattened for assertions.
#[derive(Debug, Clone)]
pub struct Flat {
    pub code: String,
    pub message: String,
    pub help: String,
    pub file: String,
    /// The text under the first label.
    pub span_text: String,
    /// Where the first label starts and ends: 1-based line and column (counted in
    /// characters), the end exclusive, as `--message-format json` writes them; `None`
    /// without a label.
    pub range: Option<((usize, usize), (usize, usize))>,
    pub warning: bool,
    /// `error`, `warning` or `advice`.
    pub severity: &'static str,
}

/// The diagnostics of one check, with the rule of typst's test runner: once a test
/// states what it expects ([`Diags::saw`], through `expect`), every diagnostic must be
/// expected — one it did not annotate fails the test when the value is dropped.
pub struct Diags {
    items: Vec<Flat>,
    seen: std::cell::RefCell<Vec<bool>>,
    annotated: std::cell::Cell<bool>,
}

impl Diags {
    fn new(items: Vec<Flat>) -> Diags {
        let n = items.len();
        Diags {
            items,
            seen: std::cell::RefCell::new(vec![false; n]),
            annotated: std::cell::Cell::new(false),
        }
    }

    /// Marks the first not-yet-seen diagnostic that satisfies `pred` as expected and
    /// returns it (the first seen one when every match was seen already).
    pub fn saw(&self, pred: impl Fn(&Flat) -> bool) -> Option<&Flat> {
        self.annotated.set(true);
        let mut seen = self.seen.borrow_mut();
        let k = (0..self.items.len())
            .find(|&k| !seen[k] && pred(&self.items[k]))
            .or_else(|| (0..self.items.len()).find(|&k| pred(&self.items[k])))?;
        seen[k] = true;
        Some(&self.items[k])
    }

    /// The one diagnostic, marked expected; fails unless there is exactly one.
    #[track_caller]
    pub fn only(&self) -> &Flat {
        assert_eq!(
            self.items.len(),
            1,
            "expected one diagnostic, got {:?}",
            self.items.iter().map(|d| &d.code).collect::<Vec<_>>()
        );
        self.saw(|_| true).unwrap()
    }

    /// Marks every diagnostic with `code` as expected without asserting on it (for
    /// tests about something else that produce it on the way).
    pub fn allow(&self, code: &str) {
        let mut seen = self.seen.borrow_mut();
        for (k, d) in self.items.iter().enumerate() {
            if d.code == code {
                seen[k] = true;
            }
        }
    }

    /// The diagnostics not (yet) expected.
    pub fn unexpected(&self) -> Vec<&Flat> {
        let seen = self.seen.borrow();
        self.items
            .iter()
            .zip(seen.iter())
            .filter(|(_, s)| !**s)
            .map(|(d, _)| d)
            .collect()
    }
}

impl std::ops::Deref for Diags {
    type Target = [Flat];
    fn deref(&self) -> &[Flat] {
        &self.items
    }
}

impl Drop for Diags {
    fn drop(&mut self) {
        if std::thread::panicking() || !self.annotated.get() {
            return;
        }
        let left = self.unexpected();
        if !left.is_empty() {
            let lines: Vec<String> = left
                .iter()
                .map(|d| format!("  {} `{}`: {}", d.code, d.span_text, d.message))
                .collect();
            panic!("diagnostics the test did not expect:\n{}", lines.join("\n"));
        }
    }
}

/// Checks `files` (path, contents) in memory; the first file is the root.
pub fn check_files(files: &[(&str, &[u8])]) -> Diags {
    Diags::new(run_files(files, Stage::Graph))
}

/// [`check_files`] through the planner too.
#[allow(dead_code)]
pub fn plan_files(files: &[(&str, &[u8])]) -> Diags {
    Diags::new(run_files(files, Stage::Plan))
}

/// Diagnostics of the whole build (paths and program) over in-memory files.
pub fn build_files(files: &[(&str, &[u8])]) -> Diags {
    Diags::new(run_files(files, Stage::Build))
}

#[derive(PartialEq)]
enum Stage {
    Graph,
    Plan,
    Build,
}

fn run_files(files: &[(&str, &[u8])], stage: Stage) -> Vec<Flat> {
    let mut world = MemoryWorld::new();
    for (p, c) in files {
        world.insert(p, c.to_vec());
    }
    let roots = [PathBuf::from(files[0].0)];
    let opts = inspc::plan::PlanOptions::default();
    let checked = match stage {
        Stage::Build => inspc::build(&world, &roots, &opts, &|_, _, _| {}).0,
        Stage::Plan => inspc::plans(&world, &roots, &opts).0,
        Stage::Graph => inspc::measurement_graphs(&world, &roots).0,
    };
    checked
        .diagnostics
        .iter()
        .map(|d| {
            let file = checked.sources.get(d.file);
            let label = d.inner.labels().and_then(|mut l| l.next());
            let span_text = label
                .as_ref()
                .map(|l| {
                    file.text
                        .get(l.offset()..l.offset() + l.len())
                        .unwrap_or("")
                        .to_string()
                })
                .unwrap_or_default();
            let range = label.map(|l| {
                (
                    file.line_col(l.offset()),
                    file.line_col(l.offset() + l.len()),
                )
            });
            Flat {
                code: d.code(),
                message: d.message(),
                help: d.inner.help().map(|h| h.to_string()).unwrap_or_default(),
                file: file.name.clone(),
                span_text,
                range,
                warning: d.severity() == miette::Severity::Warning,
                severity: match d.severity() {
                    miette::Severity::Error => "error",
                    miette::Severity::Warning => "warning",
                    miette::Severity::Advice => "advice",
                },
            }
        })
        .collect()
}

/// Checks one in-memory file named `main.insp`.
pub fn check_src(src: &str) -> Diags {
    check_files(&[("main.insp", src.as_bytes())])
}

/// The NIST parts are expected in ../shared/parts/ beside the repository, as CI has them.
/// Whether the slow and external tests run: the golden cases marked `slow` (NIST CTC 02,
/// FTC 06, FTC 08), the deviation battery on the real parts, the GPU backend on lavapipe,
/// the browser and the VS Code extension's npm build. Set `INSPC_SLOW=1` to run them
/// (`.ci/run` does, so CI runs everything); plain `cargo test` is the fast local loop.
pub fn slow() -> bool {
    std::env::var_os("INSPC_SLOW").is_some()
}

/// True, having said so, when `what` is skipped because `INSPC_SLOW` is not set.
pub fn skip_unless_slow(what: &str) -> bool {
    let skip = !slow();
    if skip {
        eprintln!("skipped (set INSPC_SLOW=1 to run it): {what}");
    }
    skip
}

pub fn require_shared_parts() {
    assert!(
        std::path::Path::new("../shared/parts/nist_ctc_01_asme1_ap242-e1.obj").exists(),
        "the NIST parts are expected in ../shared/parts/ beside the repository, as CI has them"
    );
}

/// The first differing lines, enough to see what changed.
pub fn diff(expected: &str, actual: &str) -> String {
    let (e, a): (Vec<&str>, Vec<&str>) = (expected.lines().collect(), actual.lines().collect());
    let mut out = Vec::new();
    for i in 0..e.len().max(a.len()) {
        let (x, y) = (e.get(i), a.get(i));
        if x != y {
            out.push(format!(
                "line {}:\n  - {}\n  + {}",
                i + 1,
                x.unwrap_or(&"<none>"),
                y.unwrap_or(&"<none>")
            ));
            if out.len() == 5 {
                break;
            }
        }
    }
    out.join("\n")
}

/// The spec of a golden case folder: the path in its `source.txt`, else its `main.insp`.
#[allow(dead_code)]
pub fn spec_of(case: &std::path::Path) -> PathBuf {
    let source = case.join("source.txt");
    if source.exists() {
        PathBuf::from(std::fs::read_to_string(&source).unwrap().trim())
    } else {
        case.join("main.insp")
    }
}

/// The case folders under `dir`, sorted; at least `min` of them.
pub fn cases(dir: &str, min: usize) -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    assert!(
        cases.len() >= min,
        "expected the cases under {dir}, found {}",
        cases.len()
    );
    cases
}

/// An imported spec against its golden (written instead under `INSPC_BLESS`), which must
/// check clean.
pub fn check_imported_golden(text: &str, golden: &std::path::Path) {
    if std::env::var_os("INSPC_BLESS").is_some() {
        std::fs::write(golden, text).unwrap();
        return;
    }
    let expected = std::fs::read_to_string(golden)
        .unwrap_or_else(|_| panic!("{}: missing; bless it", golden.display()));
    assert!(
        text == expected,
        "the imported spec differs from {} (bless with INSPC_BLESS=1)",
        golden.display()
    );
    let checked = inspc::check(&inspc::source::FsWorld, &[golden.to_path_buf()]);
    assert!(
        !checked.has_errors(),
        "{}: {:?}",
        golden.display(),
        checked.diagnostics
    );
}

/// For each face of `a`, the face of `b` nearest by centroid and relative area: how two
/// readings of one part (STEP and QIF, STEP and a reference mesh) are matched when they
/// number faces differently.
pub fn nearest_faces(
    a: &inspc::geometry::PartGeometry,
    b: &inspc::geometry::PartGeometry,
) -> Vec<usize> {
    a.faces
        .iter()
        .map(|f| {
            (0..b.faces.len())
                .min_by(|&x, &y| {
                    let d = |j: usize| {
                        let g = &b.faces[j];
                        (g.centroid - f.centroid).norm() + (g.area - f.area).abs() / f.area.max(1.0)
                    };
                    d(x).total_cmp(&d(y))
                })
                .unwrap()
        })
        .collect()
}

/// The plan of the first plan of the spec at `path`, planned with `opts`; fails the test
/// on any error.
pub fn first_plan(path: &std::path::Path, opts: &inspc::plan::PlanOptions) -> inspc::plan::Hlip {
    let (checked, _, _, planned) =
        inspc::plans(&inspc::source::FsWorld, &[path.to_path_buf()], opts);
    let errors: Vec<String> = checked
        .diagnostics
        .iter()
        .filter(|d| d.severity() == miette::Severity::Error)
        .map(|d| d.message())
        .collect();
    assert!(errors.is_empty(), "{}: {errors:?}", path.display());
    planned
        .into_iter()
        .next()
        .and_then(|p| p.hlip)
        .expect("a plan")
}
