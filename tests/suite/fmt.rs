//! `inspc fmt`: on every `.insp` of the repository that parses, formatting keeps the parse
//! tree (`syntax::outline`), formatting twice changes nothing, and the repository's own
//! files are formatted (the check CI makes); a spec laid out by hand comes out in the
//! canonical layout; `--check` and a file that does not parse.

use inspc::fmt::format;
use inspc::syntax::outline;
use std::path::{Path, PathBuf};

/// Every `.insp` file under the repository's examples, stdlib and tests.
fn repository_specs() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e == "insp") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    for dir in ["examples", "stdlib", "tests"] {
        walk(Path::new(dir), &mut out);
    }
    out
}

#[test]
fn formatting_keeps_the_spec_and_is_idempotent_and_the_repository_is_formatted() {
    let specs = repository_specs();
    assert!(specs.len() >= 40, "{} specs found", specs.len());
    let (mut parsed, mut unformatted) = (0, Vec::new());
    for path in &specs {
        let text = std::fs::read_to_string(path).unwrap();
        let Some(tree) = outline(&text) else {
            // Syntax-error cases are not formatted.
            continue;
        };
        parsed += 1;
        let once = format(&text);
        assert_eq!(outline(&once).as_ref(), Some(&tree), "{}", path.display());
        assert_eq!(format(&once), once, "{}: not idempotent", path.display());
        if once != text {
            unformatted.push(path.display().to_string());
        }
    }
    assert!(parsed >= 40, "{parsed} specs parsed");
    assert!(
        unformatted.is_empty(),
        "not formatted (run `inspc fmt` on them): {unformatted:?}"
    );
}

#[test]
fn a_spec_laid_out_by_hand_gets_the_canonical_layout() {
    let text = "\n\n// A block.\nuse std::probes::{ TP20_D2_L20 ,TP20_D3_L20 }\npart p {\n  units mm   \n\tstock box( 10 , 20,30 )\n\n\n   feature top=stock.top   // the top\n   feature bottom_face  =  stock.bottom\n        + stock.left // and a side\n  tolerance f = flatness(top, 0.1 mm)\n}\ncmm c { table { z 0 mm, size (1 m, 1 m) }\n    probes [p1:TP20_D2_L20]\n}\n\n";
    let want = "// A block.\nuse std::probes::{TP20_D2_L20, TP20_D3_L20}\npart p {\n    units mm\n    stock box(10, 20, 30)\n\n    feature top         = stock.top // the top\n    feature bottom_face = stock.bottom\n                          + stock.left // and a side\n    tolerance f = flatness(top, 0.1 mm)\n}\ncmm c { table { z 0 mm, size (1 m, 1 m) }\n    probes [p1: TP20_D2_L20]\n}\n";
    let got = format(text);
    assert_eq!(got, want, "\n{got}");
    assert_eq!(outline(&got), outline(text));
    assert_eq!(format(&got), got);
}

#[test]
fn fmt_formats_what_parses_names_what_does_not_and_tells_the_truth() {
    let dir = std::env::temp_dir().join(format!("inspc-fmt-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let messy = dir.join("messy.insp");
    std::fs::write(&messy, "part p {\n  units mm\n}\n").unwrap();
    let broken = dir.join("broken.insp");
    std::fs::write(&broken, "part p {\n  units mm\n").unwrap();
    let run = |args: &[&Path]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_inspc"))
            .arg("fmt")
            .args(args)
            .env("NO_COLOR", "1")
            .output()
            .unwrap()
    };
    let o = run(&[Path::new("--check"), &messy]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("messy.insp: not formatted"));
    assert_eq!(
        std::fs::read_to_string(&messy).unwrap(),
        "part p {\n  units mm\n}\n"
    );
    // A file that does not parse: its diagnostic, it is left as it is, the run fails,
    // and the one that parses is formatted all the same (as rustfmt and gofmt do).
    let o = run(&[&messy, &broken]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("insp::syntax::"), "{err}");
    assert!(
        err.contains("1 file formatted, 1 file with errors left as it was"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(&broken).unwrap(),
        "part p {\n  units mm\n"
    );
    assert_eq!(
        std::fs::read_to_string(&messy).unwrap(),
        "part p {\n    units mm\n}\n"
    );
    // Nothing to change: said so, not "formatted".
    for args in [&[Path::new("--check"), &messy][..], &[messy.as_path()][..]] {
        let o = run(args);
        assert_eq!(o.status.code(), Some(0));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("inspc: 1 file already formatted"), "{err}");
        assert!(
            o.stdout.is_empty(),
            "{}",
            String::from_utf8_lossy(&o.stdout)
        );
    }
}
