//! DMIS written by others: NIST's I++ simple-part program and its output file are read
//! with no error and no warning, and the program runs unchanged on the virtual CMM
//! against `tests/foreign/ipp_simple.insp`, reporting the circle NIST's run reported.
//! The reader takes the language's freedoms (blanks, case, `$` continuation, trailing
//! comments, `DATDEF/FA(x),DAT(y)`), names what inspc does not run, and refuses
//! inspc's old `DAT(A)=DATDEF/…`.

use inspc::source::{FileId, FsWorld};
use std::path::Path;

const NIST: &str = "../shared/parts/nist_ipp_simple";

fn read(text: &str) -> Result<inspc::dmis::Program, Vec<String>> {
    inspc::dmis::read(FileId(0), text).map_err(|es| {
        es.iter()
            .map(|e| {
                miette::Diagnostic::code(e)
                    .map(|c| c.to_string())
                    .unwrap_or_default()
            })
            .collect()
    })
}

fn warnings(p: &inspc::dmis::Program) -> Vec<String> {
    p.warnings
        .iter()
        .map(|e| {
            miette::Diagnostic::code(e)
                .map(|c| c.to_string())
                .unwrap_or_default()
        })
        .collect()
}

#[test]
fn nists_program_and_output_file_read_clean() {
    for f in ["simple_in.dms", "output.dms"] {
        let text = std::fs::read_to_string(Path::new(NIST).join(f)).expect("NIST's file");
        let p = read(&text).unwrap_or_else(|e| panic!("{f}: {e:?}"));
        assert!(warnings(&p).is_empty(), "{f}: {:?}", warnings(&p));
    }
    let text = std::fs::read_to_string(Path::new(NIST).join("simple_in.dms")).unwrap();
    let p = read(&text).unwrap();
    assert_eq!(p.commands("PTMEAS").count(), 4);
    // Blanks and case carry no meaning: the statements come out canonical.
    let dat = p.commands("DATSET").next().unwrap();
    assert_eq!(dat, ["MCS"]);
}

#[test]
fn nists_program_runs_unchanged_and_reports_the_circle() {
    let r = inspc::simulate(
        &FsWorld,
        Path::new("tests/foreign/ipp_simple.insp"),
        &Path::new(NIST).join("simple_in.dms"),
        None,
        &inspc::simulate::Options::default(),
    );
    let codes: Vec<String> = r.checked.diagnostics.iter().map(|d| d.code()).collect();
    let rep = r
        .report
        .unwrap_or_else(|| panic!("the run stopped: {codes:?}"));
    assert_eq!(rep.features.len(), 1, "{:?}", rep.features);
    let f = &rep.features[0];
    assert_eq!(
        (f.label.as_str(), f.kind.as_str(), f.inner),
        ("A_CIRCLE", "CIRCLE", true)
    );
    // NIST's output.dms: 50, 50, 40, 0, 0, 1, 50.
    let want = [50.0, 50.0, 40.0, 0.0, 0.0, 1.0, 50.0];
    assert_eq!(f.actual.len(), 7);
    for (a, w) in f.actual.iter().zip(want) {
        assert!((a - w).abs() < 1e-4, "{:?}", f.actual);
    }
    // The results file reads back, in the output file's form.
    let dmo = rep.dmis();
    assert!(
        dmo.starts_with("FILNAM/'IPP SIMPLE DMIS output'\n"),
        "{dmo}"
    );
    assert!(dmo.contains("FA(A_CIRCLE)=FEAT/CIRCLE,INNER,CART,50.0,50.0,40.0,0.0,0.0,1.0,50.0\n"));
    let back = read(&dmo).unwrap_or_else(|e| panic!("{e:?}\n{dmo}"));
    assert!(warnings(&back).is_empty());
    // And as QIF 3 Results, valid against the schemas.
    let program = Path::new(NIST).join("simple_in.dms");
    let text = std::fs::read_to_string(&program).unwrap();
    let meta =
        inspc::simulate::QifMeta::new(Path::new("tests/foreign/ipp_simple.insp"), &program, &text);
    let doc = inspc::simulate::qif_results(&rep, &meta);
    assert!(doc.contains("CircleFeatureMeasurement"), "{doc}");
    super::qif_results::check("ipp_simple", &rep, &doc);
}

#[test]
fn a_probe_not_in_the_rack_names_its_snsdef() {
    let text = std::fs::read_to_string(Path::new(NIST).join("simple_in.dms"))
        .unwrap()
        .replace(
            "0.0, 0.0, 30.0, 0.0, 0.0, -1.0, 4.0",
            "0.0, 0.0, 30.0, 0.0, 0.0, -1.0, 3.0",
        );
    let dir = std::env::temp_dir().join(format!("inspc-foreign-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let prog = dir.join("other_probe.dms");
    std::fs::write(&prog, text).unwrap();
    let r = inspc::simulate(
        &FsWorld,
        Path::new("tests/foreign/ipp_simple.insp"),
        &prog,
        None,
        &inspc::simulate::Options::default(),
    );
    assert!(r.report.is_none());
    let codes: Vec<String> = r.checked.diagnostics.iter().map(|d| d.code()).collect();
    assert!(
        codes.contains(&"insp::simulate::unknown_sensor".to_string()),
        "{codes:?}"
    );
}

#[test]
fn the_language_not_a_dialect() {
    let text = "dmismn/'x', 05.3\n  f(p) = feat/plane, cart, 0, 0, 0, $\n     0, 0, 1 $$ the top\nS(S1)=SNSDEF/PROBE,FIXED,CART,0,0,-50,0,0,1,2\nsnslct/s(s1)\nmeas/plane,f(p),1\nptmeas/cart,0,0,0,0,0,1\nendmes\nDATDEF/FA(P),DAT(A)\nT(T1)=TOL/FLAT,0.1\nT(T2)=TOL/PERP,0.1,RFS,DAT(A)\nOUTPUT/FA(P),TA(T1),TA(T2)\nendfil\n";
    let p = read(text).unwrap_or_else(|e| panic!("{e:?}"));
    assert!(warnings(&p).is_empty(), "{:?}", warnings(&p));
    assert_eq!(p.commands("FEAT").next().unwrap().len(), 8);
    // inspc's old datum form is not DMIS.
    let old = text.replace("DATDEF/FA(P),DAT(A)", "DAT(A)=DATDEF/FA(P)");
    assert!(read(&old)
        .unwrap_err()
        .contains(&"insp::dmis::datdef_form".to_string()));
    // What inspc does not run, or does not know, is a warning on the statement.
    let more = text.replace(
        "endfil",
        "DECL/LOCAL,INTGR,I\nIF/(V(I).EQ.1)\nTEXT/OPER,'one'\nENDIF\nLIGHTOPTION/ON\nFROBNICATE/1\nendfil",
    );
    let p = read(&more).unwrap_or_else(|e| panic!("{e:?}"));
    let w = warnings(&p);
    for code in ["not_run", "vendor_extension", "unknown_statement"] {
        assert!(w.iter().any(|c| c.ends_with(code)), "{code}: {w:?}");
    }
    // A block left open is an error.
    let open = text.replace("endfil", "DO/V(I),1,3\nendfil");
    assert!(read(&open)
        .unwrap_err()
        .contains(&"insp::dmis::structure".to_string()));
}
