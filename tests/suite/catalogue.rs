//! DIAGNOSTICS.md and the code stay in step: every code in `src/` is catalogued, every
//! catalogued code exists, and every catalogue example reports its code.

use crate::common;

use std::collections::BTreeSet;
use std::path::Path;

struct Entry {
    code: String,
    bytes: Vec<u8>,
    /// Further files of the example: (name, bytes).
    files: Vec<(String, Vec<u8>)>,
}

/// Codes no spec can produce, with the reason; each is still catalogued.
const NO_SPEC_EXAMPLE: &[(&str, &str)] = &[
    ("insp::geometry::boolean_failed", "a guard: inspc's primitives are closed and manifold and boolmesh accepts them all"),
    ("insp::geometry::mesh_unreadable", "a spec's mesh is checked to exist first; `inspc faces` on a missing file reports it (tests/suite/cli.rs)"),
    ("insp::access::unknown_face", "a command-line request; tests/suite/cli.rs"),
    ("insp::access::no_point", "a command-line request; tests/suite/cli.rs"),
    ("insp::access::unknown_probe", "a command-line request; tests/suite/cli.rs"),
    ("insp::access::no_machine", "a command-line request; tests/suite/cli.rs"),
    ("insp::plan::no_convergence", "a guard: generate-and-test removes a configuration every round, and every example and NIST part settles well inside the limit"),
    ("insp::plan::points_left_out", "needs `--rounds` cut short: the golden case fallback_best_plan_found"),
    ("insp::path::self_aligned", "arises only where no other face completes a setup's frame: the golden cases real_nist_ftc_08 and import_nist_ctc_01"),
    ("insp::path::no_path", "a touch that validates can almost always back out the way it came; src/path/roadmap.rs tests a sealed goal"),
    ("insp::dmis::long_line", "a DMIS file, not a spec: src/dmis/read/"),
    ("insp::dmis::syntax", "a DMIS file, not a spec: src/dmis/read/"),
    ("insp::dmis::bad_label", "a DMIS file, not a spec: tests/suite/cli.rs"),
    ("insp::dmis::duplicate_label", "a DMIS file, not a spec: src/dmis/read/"),
    ("insp::dmis::undefined", "a DMIS file, not a spec: tests/suite/cli.rs"),
    ("insp::dmis::structure", "a DMIS file, not a spec: tests/suite/cli.rs"),
    ("insp::dmis::datdef_form", "a DMIS file, not a spec: tests/suite/dmis_foreign.rs"),
    ("insp::dmis::not_run", "a DMIS file, not a spec: tests/suite/dmis_foreign.rs"),
    ("insp::dmis::vendor_extension", "a DMIS file, not a spec: tests/suite/dmis_foreign.rs"),
    ("insp::dmis::unknown_statement", "a DMIS file, not a spec: tests/suite/dmis_foreign.rs"),
    ("insp::simulate::collision", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::no_surface", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::inside_part", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::unknown_sensor", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::unsupported", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::no_plan", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::no_setup", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::bad_statement", "a program run on the virtual CMM: tests/suite/simulate.rs"),
    ("insp::simulate::bad_deviation", "a deviations file: tests/suite/simulate.rs"),
    ("insp::import::value_left_out", "an imported STEP or QIF file, not a spec: tests/suite/import.rs"),
    ("insp::import::general_tolerance", "an imported STEP or QIF file, not a spec: tests/suite/import.rs"),
    ("insp::io::unreadable", "a file named on the command line: tests/suite/cli.rs"),
    ("insp::io::unwritable", "an output of the command line: tests/suite/cli.rs"),
    ("insp::io::not_a_file", "an output of the command line: tests/suite/cli.rs"),
    ("insp::io::overwrites_input", "an output of the command line: tests/suite/cli.rs"),
    ("insp::io::same_output", "an output of the command line: tests/suite/cli.rs"),
];

fn catalogue() -> Vec<Entry> {
    let text = std::fs::read_to_string("DIAGNOSTICS.md").expect("DIAGNOSTICS.md is readable");
    let mut out = Vec::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let Some(rest) = line.strip_prefix("### `") else {
            continue;
        };
        let code = rest.split('`').next().unwrap().to_string();
        if NO_SPEC_EXAMPLE.iter().any(|(c, _)| *c == code) {
            out.push(Entry {
                code,
                bytes: vec![],
                files: vec![],
            });
            continue;
        }
        let fence = lines
            .by_ref()
            .find(|l| l.starts_with("```"))
            .unwrap_or_else(|| panic!("{code} has no example"));
        let raw = fence == "```insp-bytes";
        let body: Vec<&str> = lines
            .by_ref()
            .take_while(|l| !l.starts_with("```"))
            .collect();
        let body = body.join("\n") + "\n";
        let bytes = if raw {
            unescape_bytes(&body)
        } else {
            body.into_bytes()
        };
        // Extra files follow as ```file NAME or ```file-bytes NAME blocks.
        let mut files = Vec::new();
        let mut peek = lines.clone();
        while let Some(l) = peek.next() {
            if l.starts_with("### ") || l.starts_with("## ") {
                break;
            }
            if let Some(name) = l
                .strip_prefix("```file-bytes ")
                .or_else(|| l.strip_prefix("```file "))
            {
                let raw = l.starts_with("```file-bytes ");
                let body: Vec<&str> = peek
                    .by_ref()
                    .take_while(|l| !l.starts_with("```"))
                    .collect();
                let body = body.join("\n") + "\n";
                files.push((
                    name.trim().to_string(),
                    if raw {
                        unescape_bytes(body.trim_end())
                    } else {
                        body.into_bytes()
                    },
                ));
            }
        }
        out.push(Entry { code, bytes, files });
    }
    out
}

fn unescape_bytes(s: &str) -> Vec<u8> {
    let mut out = Vec::new();
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'\\' && b.get(i + 1) == Some(&b'x') && i + 3 < b.len() {
            out.push(u8::from_str_radix(&s[i + 2..i + 4], 16).expect("hex byte"));
            i += 4;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    out
}

fn codes_in_source() -> BTreeSet<String> {
    fn walk(dir: &Path, out: &mut BTreeSet<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let text = std::fs::read_to_string(&p).unwrap();
                for (i, _) in text.match_indices("code(insp::") {
                    let rest = &text[i + 5..];
                    out.insert(rest[..rest.find(')').unwrap()].to_string());
                }
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(Path::new("src"), &mut out);
    out
}

#[test]
fn catalogue_and_code_list_the_same_codes() {
    let documented: BTreeSet<String> = catalogue().into_iter().map(|e| e.code).collect();
    let in_code = codes_in_source();
    let undocumented: Vec<_> = in_code.difference(&documented).collect();
    let stale: Vec<_> = documented.difference(&in_code).collect();
    assert!(
        undocumented.is_empty(),
        "codes missing from DIAGNOSTICS.md: {undocumented:?}"
    );
    assert!(
        stale.is_empty(),
        "DIAGNOSTICS.md lists codes the source no longer has: {stale:?}"
    );
    assert!(
        in_code.len() >= 45,
        "expected the full set of codes, found {}",
        in_code.len()
    );
}

#[test]
fn every_catalogue_example_reports_its_code() {
    let mut failures = Vec::new();
    for e in catalogue() {
        if NO_SPEC_EXAMPLE.iter().any(|(c, _)| *c == e.code) {
            continue;
        }
        let mut files: Vec<(&str, &[u8])> = vec![("example.insp", &e.bytes)];
        files.extend(e.files.iter().map(|(n, b)| (n.as_str(), b.as_slice())));
        let diags = if e.code.starts_with("insp::plan::") {
            common::plan_files(&files)
        } else if e.code.starts_with("insp::path::") {
            common::build_files(&files)
        } else {
            common::check_files(&files)
        };
        if !diags.iter().any(|d| d.code == e.code) {
            failures.push(format!(
                "{}: got {:?}",
                e.code,
                diags.iter().map(|d| &d.code).collect::<Vec<_>>()
            ));
        }
        for d in diags.iter() {
            assert!(!d.help.is_empty(), "{} has no help line", d.code);
            assert!(
                !d.span_text.is_empty()
                    || d.code == "insp::load::unreadable"
                    || d.code == "insp::syntax::unexpected",
                "{} has an empty label",
                d.code
            );
        }
    }
    assert!(
        failures.is_empty(),
        "examples that do not report their code:\n{}",
        failures.join("\n")
    );
}
