//! Diagnostic cases written as specs: every case under `tests/diagnostics/` is checked
//! the way `common::check_files` checks a spec, and must report exactly the diagnostics
//! its comments annotate — severity, code, labelled span, message and help — none left
//! unannotated and no annotation left unmatched (typst's rule). `tests/README.md`
//! describes the annotations; this module reads them, runs every case and reports every
//! failing case at once.

use crate::common::{self, Flat};
use std::path::{Path, PathBuf};

/// Where the cases live.
const DIR: &str = "tests/diagnostics";

/// The file a case folder is checked from, and the name a one-file case is checked as.
const ROOT: &str = "main.insp";

#[test]
fn annotated_cases() {
    let cases = collect(Path::new(DIR));
    assert!(
        cases.len() >= 100,
        "expected the cases under {DIR}, found {}",
        cases.len()
    );
    let failures = run_all(&cases);
    assert!(
        failures.is_empty(),
        "{} of {} diagnostic cases failed:\n\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n\n")
    );
}

/// One case: a `.insp` file, or a folder with a `main.insp` and the files it reads.
struct Case {
    /// The file, or the folder.
    path: PathBuf,
    /// Its files, the root first.
    files: Vec<CaseFile>,
}

struct CaseFile {
    /// The name the check reads it under: `main.insp` or its path in the folder.
    name: String,
    /// Where it is, for reports.
    path: PathBuf,
    bytes: Vec<u8>,
}

/// The cases under `dir`: its `.insp` files, and its folders that hold a `main.insp`;
/// other folders are walked for more. Anything else is refused, so that a misnamed case
/// cannot go unchecked.
fn collect(dir: &Path) -> Vec<Case> {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    let mut cases = Vec::new();
    for path in entries {
        if path.is_dir() && path.join(ROOT).is_file() {
            let mut files = Vec::new();
            folder_files(&path, &path, &mut files);
            files.sort_by_key(|f| (f.name != ROOT, f.name.clone()));
            cases.push(Case { path, files });
        } else if path.is_dir() {
            cases.extend(collect(&path));
        } else if path.extension().is_some_and(|e| e == "insp") {
            let bytes = std::fs::read(&path).unwrap();
            let files = vec![CaseFile {
                name: ROOT.to_string(),
                path: path.clone(),
                bytes,
            }];
            cases.push(Case { path, files });
        } else {
            panic!(
                "{}: neither a `.insp` case nor a folder (a case folder holds a `{ROOT}`)",
                path.display()
            );
        }
    }
    cases
}

/// Every file under a case folder, named by its path inside it.
fn folder_files(root: &Path, dir: &Path, out: &mut Vec<CaseFile>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            folder_files(root, &path, out);
            continue;
        }
        let name = path.strip_prefix(root).unwrap();
        let name = name
            .components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/");
        let bytes = std::fs::read(&path).unwrap();
        out.push(CaseFile { name, path, bytes });
    }
}

/// Runs the cases on every core; the report of each one that failed.
fn run_all(cases: &[Case]) -> Vec<String> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut failures: Vec<(usize, String)> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                s.spawn(|| {
                    let mut failed = Vec::new();
                    loop {
                        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(case) = cases.get(k) else {
                            return failed;
                        };
                        if let Err(report) = run(case) {
                            failed.push((k, report));
                        }
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    failures.sort();
    failures.into_iter().map(|(_, r)| r).collect()
}

/// How far a case runs (`// until: …` in its root file).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Until {
    /// The measurement graphs (`common::check_files`), the default.
    Graph,
    /// The plans (`common::plan_files`).
    Plan,
    /// The program (`common::build_files`).
    Build,
}

/// One expected diagnostic.
#[derive(Debug)]
struct Note {
    /// The file it is in (an index into the case's files) and its line there.
    file: usize,
    line: usize,
    severity: String,
    code: String,
    /// The span: 1-based line and column (in characters), the end exclusive.
    start: (usize, usize),
    end: (usize, usize),
    /// The message, `...` standing for any text.
    message: String,
    /// The help, `...` standing for any text (`None` only while parsing: every
    /// annotation has one, as every diagnostic does).
    help: Option<String>,
}

/// Checks one case: `Err` with its report when it fails.
fn run(case: &Case) -> Result<(), String> {
    let mut notes = Vec::new();
    let mut until = Until::Graph;
    let mut problems: Vec<(usize, usize, String)> = Vec::new();
    for (k, file) in case.files.iter().enumerate() {
        if !file.name.ends_with(".insp") {
            continue;
        }
        let text = String::from_utf8_lossy(&file.bytes);
        match parse(&text, k) {
            Ok((mut found, stage)) => {
                notes.append(&mut found);
                if let Some((line, stage)) = stage {
                    if k == 0 {
                        until = stage;
                    } else {
                        problems.push((k, line, "`until:` belongs in `main.insp`".into()));
                    }
                }
            }
            Err(errors) => {
                problems.extend(errors.into_iter().map(|(line, e)| (k, line, e)));
            }
        }
    }
    if problems.is_empty() {
        let inputs: Vec<(&str, &[u8])> = case
            .files
            .iter()
            .map(|f| (f.name.as_str(), f.bytes.as_slice()))
            .collect();
        let diags = match until {
            Until::Graph => common::check_files(&inputs),
            Until::Plan => common::plan_files(&inputs),
            Until::Build => common::build_files(&inputs),
        };
        problems = compare(case, &notes, &diags);
    }
    if problems.is_empty() {
        return Ok(());
    }
    problems.sort();
    let lines: Vec<String> = problems
        .iter()
        .map(|(file, line, what)| match case.files.get(*file) {
            Some(f) => format!("{}:{line}: {what}", f.path.display()),
            None => format!("{}: {what}", case.path.display()),
        })
        .collect();
    Err(lines.join("\n"))
}

/// Matches the diagnostics to the notes; a problem (file, line, text) for each one of
/// either that is left over.
fn compare(case: &Case, notes: &[Note], diags: &[Flat]) -> Vec<(usize, usize, String)> {
    let mut used = vec![false; notes.len()];
    let mut left = Vec::new();
    for d in diags {
        let file = case.files.iter().position(|f| f.name == d.file);
        let found = (0..notes.len())
            .find(|&k| !used[k] && Some(notes[k].file) == file && fits(&notes[k], d));
        match found {
            Some(k) => used[k] = true,
            None => left.push((file, d)),
        }
    }
    let mut problems = Vec::new();
    // Diagnostics come sorted by file and place (`Diagnostics::sorted`): within a file,
    // each starts no earlier than the one before it.
    for pair in diags.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.file == b.file && b.range.map(|r| r.0) < a.range.map(|r| r.0) {
            let file = case.files.iter().position(|f| f.name == b.file);
            problems.push((
                file.unwrap_or(usize::MAX),
                b.range.map_or(0, |r| r.0 .0),
                format!(
                    "reported after a diagnostic that starts later: {}",
                    describe(b)
                ),
            ));
        }
    }
    for d in diags.iter().filter(|d| d.help.is_empty()) {
        let file = case.files.iter().position(|f| f.name == d.file);
        problems.push((
            file.unwrap_or(usize::MAX),
            d.range.map_or(0, |r| r.0 .0),
            format!(
                "a diagnostic without help (every one has a help line): {}",
                describe(d)
            ),
        ));
    }
    for (file, d) in &left {
        let Some(file) = *file else {
            problems.push((
                usize::MAX,
                0,
                format!(
                    "a diagnostic in `{}`, outside the case, which no annotation can name: {}",
                    d.file,
                    describe(d)
                ),
            ));
            continue;
        };
        let line = d.range.map_or(1, |(start, _)| start.0);
        let text = String::from_utf8_lossy(&case.files[file].bytes);
        problems.push((
            file,
            line,
            format!("not annotated: {}\n{}", describe(d), suggest(&text, d)),
        ));
    }
    for (k, note) in notes.iter().enumerate() {
        if used[k] {
            continue;
        }
        // What comes nearest: a diagnostic of the same code, else one at the same place.
        let near = left
            .iter()
            .filter(|(file, _)| *file == Some(note.file))
            .map(|(_, d)| d)
            .find(|d| d.code == note.code)
            .or_else(|| {
                left.iter()
                    .filter(|(file, _)| *file == Some(note.file))
                    .map(|(_, d)| d)
                    .find(|d| d.range == Some((note.start, note.end)))
            });
        let near = near.map_or(String::new(), |d| {
            format!(
                "\n  the nearest diagnostic left over differs in its {}: {}",
                differences(note, d),
                describe(d)
            )
        });
        problems.push((
            note.file,
            note.line,
            format!(
                "no diagnostic matches: {} {} at {}: {}{}{near}",
                note.severity,
                note.code,
                range(note.start, note.end),
                note.message,
                note.help
                    .as_ref()
                    .map_or(String::new(), |h| format!("\n  help: {h}")),
            ),
        ));
    }
    problems
}

/// Whether a note expects this diagnostic.
fn fits(note: &Note, d: &Flat) -> bool {
    d.range == Some((note.start, note.end))
        && d.severity == note.severity
        && d.code == note.code
        && matches(&note.message, &d.message)
        && note
            .help
            .as_ref()
            .is_some_and(|help| !d.help.is_empty() && matches(help, &d.help))
}

/// What keeps `d` from fitting `note`: `place, message`.
fn differences(note: &Note, d: &Flat) -> String {
    let help = note.help.as_deref().unwrap_or_default();
    [
        ("place", d.range == Some((note.start, note.end))),
        ("severity", d.severity == note.severity),
        ("code", d.code == note.code),
        ("message", matches(&note.message, &d.message)),
        ("help", !d.help.is_empty() && matches(help, &d.help)),
    ]
    .iter()
    .filter(|(_, same)| !same)
    .map(|(what, _)| *what)
    .collect::<Vec<_>>()
    .join(", ")
}

/// Whether `text` is `pattern`, where each `...` in the pattern stands for any text.
fn matches(pattern: &str, text: &str) -> bool {
    let pieces: Vec<&str> = pattern.split("...").collect();
    let [first, middle @ .., last] = pieces.as_slice() else {
        return pattern == text;
    };
    if text.len() < first.len() + last.len() || !text.starts_with(first) || !text.ends_with(last) {
        return false;
    }
    let mut rest = &text[first.len()..text.len() - last.len()];
    for piece in middle {
        match rest.find(piece) {
            Some(at) => rest = &rest[at + piece.len()..],
            None => return false,
        }
    }
    true
}

/// A diagnostic as a report names it.
fn describe(d: &Flat) -> String {
    let at = d
        .range
        .map_or("no label".to_string(), |(start, end)| range(start, end));
    let help = if d.help.is_empty() {
        "no help".to_string()
    } else {
        format!("help: {}", d.help)
    };
    format!(
        "{} {} at {at} `{}`: {}\n  {help}",
        d.severity, d.code, d.span_text, d.message
    )
}

/// `line:column-line:column`.
fn range(start: (usize, usize), end: (usize, usize)) -> String {
    format!("{}:{}-{}:{}", start.0, start.1, end.0, end.1)
}

/// The annotation that would expect `d`, to paste under the line it names: carets
/// where they can be drawn (a span on one line, not empty, right of the comment's `//`),
/// else a position.
fn suggest(text: &str, d: &Flat) -> String {
    let Some((start, end)) = d.range else {
        return "  (a diagnostic without a label cannot be annotated)".into();
    };
    let lines: Vec<&str> = text.split('\n').collect();
    let texts: Vec<usize> = (0..lines.len())
        .filter(|&j| classify(lines[j]) == Kind::Text)
        .collect();
    // The line to write under: the span's first, or the one before the end of the file.
    let Some(mut anchor) = texts.iter().position(|&j| j + 1 == start.0) else {
        return "  (the span starts inside an annotation)".into();
    };
    if anchor > 0 && anchor + 1 == texts.len() && lines[texts[anchor]].is_empty() {
        anchor -= 1;
    }
    let under = lines[texts[anchor]];
    let indent = under.len() - under.trim_start().len();
    let pad = " ".repeat(indent);
    let what = format!(
        "{} {}: {}\n  {pad}// help: {}",
        d.severity, d.code, d.message, d.help
    );
    let head = format!("  annotate it under line {}:\n  {pad}//", texts[anchor] + 1);
    if start.0 == end.0 && end.1 > start.1 && start.1 > indent + 2 && texts[anchor] + 1 == start.0 {
        let carets = "^".repeat(end.1 - start.1);
        return format!(
            "{head}{}{carets} {what}",
            " ".repeat(start.1 - 1 - indent - 2)
        );
    }
    let line_of = |l: usize| {
        texts
            .iter()
            .position(|&j| j + 1 == l)
            .map(|k| k - anchor + 1)
    };
    let (Some(from), Some(to)) = (line_of(start.0), line_of(end.0)) else {
        return "  (the span ends inside an annotation)".into();
    };
    let at = if start == end {
        format!("{from}:{}", start.1)
    } else if from == to {
        format!("{from}:{}-{}", start.1, end.1)
    } else {
        format!("{from}:{}-{to}:{}", start.1, end.1)
    };
    format!("{head} @{at} {what}")
}

/// The notes of one file and its `until:` line, or what is wrong with its annotations
/// (line, text).
#[allow(clippy::type_complexity)]
fn parse(
    text: &str,
    file: usize,
) -> Result<(Vec<Note>, Option<(usize, Until)>), Vec<(usize, String)>> {
    let lines: Vec<&str> = text.split('\n').collect();
    let kinds: Vec<Kind> = lines.iter().map(|l| classify(l)).collect();
    // The lines annotations point into (0-based), in order.
    let texts: Vec<usize> = (0..lines.len())
        .filter(|&j| kinds[j] == Kind::Text)
        .collect();
    let (mut notes, mut errors, mut until): (Vec<Note>, Vec<(usize, String)>, _) =
        (Vec::new(), Vec::new(), None);
    // The note the next `help:` line belongs to, while only annotations intervene.
    let mut open: Option<usize> = None;
    for (k, kind) in kinds.iter().enumerate() {
        let line = k + 1;
        let (place, rest) = match kind {
            Kind::Text => {
                open = None;
                continue;
            }
            Kind::Until(stage) => {
                let stage = match *stage {
                    "graph" => Until::Graph,
                    "plan" => Until::Plan,
                    "build" => Until::Build,
                    other => {
                        errors.push((
                            line,
                            format!("unknown stage `{other}` (graph, plan or build)"),
                        ));
                        continue;
                    }
                };
                if until.replace((line, stage)).is_some() {
                    errors.push((line, "a second `until:` line".into()));
                }
                continue;
            }
            Kind::Help(help) => {
                match open {
                    Some(n) if notes[n].help.is_none() => notes[n].help = Some(help.to_string()),
                    Some(_) => errors.push((line, "a second `help:` for one annotation".into())),
                    None => {
                        errors.push((line, "a `help:` line with no annotation above it".into()))
                    }
                }
                continue;
            }
            Kind::Carets { col, len, rest } => (Place::Carets(*col, *len), rest),
            Kind::At { range, rest } => (Place::At(range), rest),
        };
        // An annotation points into the nearest line above it that is not one.
        let Some(target) = texts.iter().rposition(|&j| j < k) else {
            errors.push((
                line,
                "an annotation with no line above it to point at".into(),
            ));
            continue;
        };
        let span = match place {
            Place::Carets(col, len) => {
                let at = texts[target];
                if col + len - 1 > lines[at].chars().count() {
                    errors.push((
                        line,
                        format!("the carets run past the end of line {}", at + 1),
                    ));
                    continue;
                }
                ((at + 1, col), (at + 1, col + len))
            }
            Place::At(range) => match position(range, &texts[target..]) {
                Some(span) => span,
                None => {
                    errors.push((
                        line,
                        format!(
                            "`@{range}` is not a position like `@1:5-1:9`, `@1:5-9` or `@2:1` \
                             (lines counted from 1 at line {}, skipping annotations)",
                            texts[target] + 1
                        ),
                    ));
                    continue;
                }
            },
        };
        match note(rest, file, line, span) {
            Ok(n) => {
                notes.push(n);
                open = Some(notes.len() - 1);
            }
            Err(e) => errors.push((line, e)),
        }
    }
    for n in notes.iter().filter(|n| n.help.is_none()) {
        errors.push((
            n.line,
            "an annotation without a `help:` line under it (`help: ...` takes any)".into(),
        ));
    }
    if errors.is_empty() {
        Ok((notes, until))
    } else {
        Err(errors)
    }
}

/// Where an annotation puts its span.
enum Place<'a> {
    /// The 1-based column of the first caret, and how many.
    Carets(usize, usize),
    /// `@…`, without the `@`.
    At(&'a str),
}

/// What a line of a case file is.
#[derive(Debug, PartialEq)]
enum Kind<'a> {
    /// Spec text, an empty line or an ordinary comment.
    Text,
    /// `// ^^^ error insp::…: message`: `col` is the first caret's 1-based column.
    Carets {
        col: usize,
        len: usize,
        rest: &'a str,
    },
    /// `// @1:5-1:9 error insp::…: message`.
    At { range: &'a str, rest: &'a str },
    /// `// help: text`.
    Help(&'a str),
    /// `// until: plan`.
    Until(&'a str),
}

fn classify(line: &str) -> Kind<'_> {
    let Some(body) = line.trim_start().strip_prefix("//") else {
        return Kind::Text;
    };
    let body = body.trim_start();
    if body.starts_with('^') {
        let before = line.len() - body.len();
        let len = body.chars().take_while(|&c| c == '^').count();
        Kind::Carets {
            col: line[..before].chars().count() + 1,
            len,
            rest: &body[len..],
        }
    } else if let Some(at) = body.strip_prefix('@') {
        let (range, rest) = at.split_once(char::is_whitespace).unwrap_or((at, ""));
        Kind::At { range, rest }
    } else if let Some(help) = body.strip_prefix("help:") {
        Kind::Help(help.trim())
    } else if let Some(stage) = body.strip_prefix("until:") {
        Kind::Until(stage.trim())
    } else {
        Kind::Text
    }
}

/// `line:column-line:column`, `line:column-column` or `line:column` (an empty span):
/// line 1 is `lines[0]` (0-based lines of the file), line 2 `lines[1]`, and so on.
fn position(text: &str, lines: &[usize]) -> Option<((usize, usize), (usize, usize))> {
    let pos = |s: &str, line: Option<usize>| -> Option<(usize, usize)> {
        let (l, c) = match (s.split_once(':'), line) {
            (Some((l, c)), _) => (l.parse().ok()?, c.parse().ok()?),
            (None, Some(line)) => (line, s.parse().ok()?),
            (None, None) => return None,
        };
        (l >= 1 && c >= 1).then_some((l, c))
    };
    let (start, end) = match text.split_once('-') {
        Some((a, b)) => {
            let start = pos(a, None)?;
            (start, pos(b, Some(start.0))?)
        }
        None => {
            let start = pos(text, None)?;
            (start, start)
        }
    };
    let place = |(l, c): (usize, usize)| Some((lines.get(l - 1)? + 1, c));
    if start > end {
        return None;
    }
    Some((place(start)?, place(end)?))
}

/// An annotation's `severity code: message`.
fn note(
    rest: &str,
    file: usize,
    line: usize,
    (start, end): ((usize, usize), (usize, usize)),
) -> Result<Note, String> {
    let rest = rest.trim();
    let form = "an annotation reads `error insp::stage::name: message` after its place";
    let (severity, rest) = rest.split_once(' ').ok_or(form)?;
    if !["error", "warning", "advice"].contains(&severity) {
        return Err(format!(
            "unknown severity `{severity}` (error, warning or advice); {form}"
        ));
    }
    let (code, message) = match rest.split_once(": ") {
        Some((code, message)) => (code, message.trim()),
        None => (rest.strip_suffix(':').ok_or(form)?, ""),
    };
    let stable = code.split("::").collect::<Vec<_>>();
    if stable.len() != 3 || stable[0] != "insp" || stable.iter().any(|p| p.is_empty()) {
        return Err(format!("`{code}` is not a code `insp::<stage>::<name>`"));
    }
    Ok(Note {
        file,
        line,
        severity: severity.to_string(),
        code: code.to_string(),
        start,
        end,
        message: message.to_string(),
        help: None,
    })
}

#[test]
fn patterns_match_whole_texts_with_gaps() {
    assert!(matches("unknown datum `B`", "unknown datum `B`"));
    assert!(!matches("unknown datum", "unknown datum `B`"));
    assert!(matches("...datum `B`", "unknown datum `B`"));
    assert!(matches("unknown...", "unknown datum `B`"));
    assert!(matches("...datum...", "unknown datum `B`"));
    assert!(matches("un...`B`", "unknown datum `B`"));
    assert!(!matches("unknown...unknown", "unknown"));
    assert!(matches("...", ""));
}
