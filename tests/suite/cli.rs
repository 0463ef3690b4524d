//! The `inspc` binary: exit codes and the JSON diagnostics contract.

use crate::common;

use std::process::Command;

fn inspc(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_inspc"))
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("inspc runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

fn temp_spec(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("inspc-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_string_lossy().into_owned()
}

#[test]
fn check_clean_example_exits_zero() {
    let (code, stdout, stderr) = inspc(&["check", "examples/f2.insp"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.is_empty());
    assert!(stderr.contains("1 file checked, no errors"), "{stderr}");
}

#[test]
fn a_report_quotes_a_window_of_a_long_line() {
    // A 2 MB line used to be echoed whole, once per diagnostic.
    let filler = "x".repeat(1_000_000);
    let text = format!(
        "part p {{\n    units mm // {filler}\n    stock box(1, 1, 1), bogus 3 // {filler}\n}}\n"
    );
    let spec = temp_spec("long_line.insp", &text);
    let (code, _, stderr) = inspc(&["check", &spec]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("insp::syntax::unexpected"),
        "{}",
        &stderr[..stderr.len().min(2000)]
    );
    assert!(stderr.len() < 4_000, "{} bytes of report", stderr.len());
    // The label still points at the property, on the file's own line number.
    assert!(
        stderr.contains("bogus") && stderr.contains("long_line.insp:3:"),
        "{stderr}"
    );
    assert!(stderr.contains('…'), "{stderr}");
}

/// Whether the rendered diagnostics hold one of `code` at `severity`: the line after the
/// code starts with miette's `⚠` for a warning, `×` for an error.
fn filed(stderr: &str, code: &str, severity: &str) -> bool {
    let mark = if severity == "warning" { "⚠" } else { "×" };
    let lines: Vec<&str> = stderr.lines().collect();
    lines.iter().enumerate().any(|(i, l)| {
        l.trim() == code
            && lines[i + 1..]
                .iter()
                .find(|n| !n.trim().is_empty())
                .is_some_and(|n| n.trim_start().starts_with(mark))
    })
}

#[test]
fn an_unmeasured_tolerance_fails_the_build_unless_allowed() {
    let spec = temp_spec(
        "unmeasured.insp",
        "use std::heads::PH6\nuse std::probes::TP20_D2_L20\npart p {\n    units mm\n    stock box(100, 100, 20)\n    cut hole bore { at (50, 50, 20), axis -z, diameter 40, depth through }\n    feature top = stock.top\n    feature side = stock.left\n    tolerance flat = flatness(top, 0.05 mm)\n    tolerance flat_side = flatness(side, 0.05 mm)\n}\ncmm lab { table { z 0 mm }, ram { radius 35 mm, length 600 mm }, head PH6, probes [p1: TP20_D2_L20] }\nplan q { part p, cmm lab, sample top with uniform(points 4, inset 45 %) }\n",
    );
    let out = spec.replace(".insp", ".dmi");
    let _ = std::fs::remove_file(&out);
    let (code, _, stderr) = inspc(&["build", &spec, "-o", &out]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        filed(&stderr, "insp::plan::unmeasured", "error") && stderr.contains("`flat`"),
        "{stderr}"
    );
    assert!(!std::path::Path::new(&out).exists());
    let (code, stdout, stderr) = inspc(&["build", &spec, "-o", &out, "--allow-unmeasured"]);
    assert_eq!(code, 0, "{stderr}");
    // The same code, now a warning.
    assert!(
        filed(&stderr, "insp::plan::unmeasured", "warning"),
        "{stderr}"
    );
    assert!(stdout.contains("tolerances measured 1 of 2"), "{stdout}");
    let program = std::fs::read_to_string(&out).unwrap();
    assert!(
        program.contains("TA(FLAT_SIDE)") && !program.contains("TA(FLAT)"),
        "{program}"
    );
}

#[test]
fn a_face_no_probe_inspects_is_left_out_when_allowed() {
    // The slot is narrower than the tip: the build fails, or, allowed, measures the rest.
    let spec = temp_spec(
        "narrow.insp",
        "use std::heads::PH6\nuse std::probes::TP20_D2_L20\npart p {\n    units mm\n    stock box(60, 40, 20)\n    cut slot narrow { at (30, 0, 20), along +y, width 1.5, depth 10 }\n    feature top = stock.top\n    feature gap = narrow.walls\n    tolerance flat = flatness(top, 0.05 mm)\n    tolerance w = width(gap, 1.5 mm ± 0.05 mm)\n}\ncmm lab { table { z 0 mm }, ram { radius 35 mm, length 600 mm }, head PH6, probes [p1: TP20_D2_L20] }\nplan q { part p, cmm lab }\n",
    );
    let out = spec.replace(".insp", ".dmi");
    let _ = std::fs::remove_file(&out);
    let (code, _, stderr) = inspc(&["build", &spec, "-o", &out]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        filed(&stderr, "insp::plan::uninspectable_face", "error"),
        "{stderr}"
    );
    assert!(!std::path::Path::new(&out).exists());
    let (code, stdout, stderr) = inspc(&["build", &spec, "-o", &out, "--allow-unmeasured"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        filed(&stderr, "insp::plan::uninspectable_face", "warning")
            && filed(&stderr, "insp::plan::unmeasured", "warning")
            && stderr.contains("`w`"),
        "{stderr}"
    );
    assert!(stdout.contains("tolerances measured 1 of 2"), "{stdout}");
    let program = std::fs::read_to_string(&out).unwrap();
    assert!(
        program.contains("TA(FLAT)") && !program.contains("TA(W)"),
        "{program}"
    );
}

#[test]
fn check_reports_errors_and_exits_one() {
    let bad = temp_spec(
        "bad.insp",
        "stylus s { tip 0 mm, length 20 deg, stem 1 mmm }\n",
    );
    let (code, _, stderr) = inspc(&["check", &bad]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("insp::resolve::non_positive") && stderr.contains("help:"),
        "{stderr}"
    );
    assert!(stderr.contains("3 errors"), "{stderr}");
}

#[test]
fn json_diagnostics_are_one_object_per_line() {
    let bad = temp_spec(
        "json.insp",
        "// é\nstylus s { tip 0 mm, length 20 deg, stem 1 mmm }\n",
    );
    let (code, stdout, stderr) = inspc(&["check", "--message-format", "json", &bad]);
    assert_eq!(code, 1);
    assert!(stderr.is_empty(), "json mode keeps stderr quiet: {stderr}");
    let lines: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert_eq!(lines.len(), 3);
    for v in &lines {
        for key in [
            "severity",
            "code",
            "message",
            "file",
            "line",
            "column",
            "end_line",
            "end_column",
            "labels",
            "help",
        ] {
            assert!(v.get(key).is_some(), "missing `{key}` in {v}");
        }
        assert_eq!(v["severity"], "error");
        assert!(v["code"].as_str().unwrap().starts_with("insp::"));
        assert!(!v["labels"].as_array().unwrap().is_empty());
    }
    // `tip 0 mm`: line 2, column of `0` (1-based, in characters).
    assert_eq!(lines[0]["line"], 2);
    assert_eq!(lines[0]["column"], 16);
    assert_eq!(lines[0]["end_column"], 20);
    assert_eq!(lines[2]["code"], "insp::resolve::unknown_unit");
    assert_eq!(lines[2]["help"], "did you mean `mm`?");
}

#[test]
fn every_command_prints_json_diagnostics_and_keeps_stdout_for_them() {
    // F3 with a fixed head plans with a warning (a datum measured in another setup): the
    // plan's diagnostics reach JSON like the front end's; the summary moves to stderr.
    let out = std::env::temp_dir().join(format!("inspc-json-{}.dmi", std::process::id()));
    let out = out.to_string_lossy().into_owned();
    let args = [
        "build",
        "--message-format",
        "json",
        "examples/f3_fixed.insp",
        "-o",
        &out,
    ];
    let (code, stdout, stderr) = inspc(&args);
    let _ = std::fs::remove_file(&out);
    assert_eq!(code, 0, "{stderr}");
    let lines: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|_| panic!("not JSON: {l}")))
        .collect();
    assert!(
        lines
            .iter()
            .any(|v| v["code"] == "insp::plan::datum_in_other_setup" && v["severity"] == "warning"),
        "{stdout}"
    );
    assert!(stderr.contains("wrote "), "{stderr}");
    // The flag also stands before the command.
    let (code, stdout, _) = inspc(&["--message-format", "json", "dmis", "no/such/program.dmi"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().next().unwrap()).unwrap();
    assert_eq!(v["code"], "insp::io::unreadable");
}

#[test]
fn missing_file_is_a_diagnostic() {
    let (code, stdout, _) = inspc(&["check", "--message-format", "json", "no/such/spec.insp"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().next().unwrap()).unwrap();
    assert_eq!(v["code"], "insp::load::unreadable");
}

#[test]
fn emit_model_prints_the_resolved_spec() {
    let (code, stdout, _) = inspc(&["check", "--emit", "model", "examples/f2.insp"]);
    assert_eq!(code, 0);
    assert!(stdout.contains("part f2: box (120, 60, 40)"), "{stdout}");
    assert!(
        stdout.contains("tolerance T2: perpendicularity(small_slot) 0.02 | A"),
        "{stdout}"
    );
}

#[test]
fn usage_errors_exit_two() {
    let (code, _, stderr) = inspc(&["check"]);
    assert_eq!(code, 2, "{stderr}");
}

fn type_counts(stdout: &str) -> std::collections::BTreeMap<String, usize> {
    let v: serde_json::Value = serde_json::from_str(stdout).expect("faces --format json is JSON");
    let mut counts = std::collections::BTreeMap::new();
    for f in v[0]["faces"].as_array().unwrap() {
        *counts
            .entry(f["type"].as_str().unwrap().to_string())
            .or_default() += 1;
    }
    counts
}

#[test]
fn faces_of_the_nist_obj_groups_match_the_pmi_surface_types() {
    // The PMI lists CTC 01 as 56 planes, 57 cylinders and 4 cones; FTC 08 as 82 planes,
    // 134 cylinders, 20 spheres and 12 tori (free-form for inspc).
    common::require_shared_parts();
    let (code, stdout, stderr) = inspc(&[
        "faces",
        "--format",
        "json",
        "../shared/parts/nist_ctc_01_asme1_ap242-e1.obj",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let c = type_counts(&stdout);
    assert_eq!((c["plane"], c["cylinder"], c["cone"]), (56, 57, 4), "{c:?}");
    let (_, stdout, _) = inspc(&[
        "faces",
        "--format",
        "json",
        "../shared/parts/nist_ftc_08_asme1_ap242-e1.obj",
    ]);
    let c = type_counts(&stdout);
    assert_eq!(
        (c["plane"], c["cylinder"], c["sphere"], c["freeform"]),
        (82, 134, 20, 12),
        "{c:?}"
    );
}

#[test]
fn faces_segments_the_nist_stl_files_into_sensible_types() {
    common::require_shared_parts();
    for (mesh, min_faces) in [
        ("nist_ctc_01_asme1_ap242-e1.stl", 90),
        ("nist_ftc_08_asme1_ap242-e1.stl", 200),
    ] {
        let (code, stdout, stderr) = inspc(&[
            "faces",
            "--format",
            "json",
            &format!("../shared/parts/{mesh}"),
        ]);
        assert_eq!(code, 0, "{stderr}");
        let c = type_counts(&stdout);
        let total: usize = c.values().sum();
        assert!(total >= min_faces, "{mesh}: {c:?}");
        // Planes and cylinders dominate; almost nothing is left free-form.
        assert!(c["plane"] + c["cylinder"] > total * 2 / 3, "{mesh}: {c:?}");
        assert!(
            c.get("freeform").copied().unwrap_or(0) * 20 < total,
            "{mesh}: {c:?}"
        );
    }
    let (_, text, _) = inspc(&["faces", "../shared/parts/nist_ctc_01_asme1_ap242-e1.stl"]);
    assert!(
        text.contains("segment_1 ") && text.contains("cylinder") && text.contains("(hole)"),
        "{text}"
    );
}

#[test]
fn faces_of_a_spec_name_the_constructive_faces() {
    let (code, stdout, stderr) = inspc(&["faces", "examples/f2.insp"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.starts_with("f2: 12 faces"), "{stdout}");
    assert!(
        stdout.contains("large.left_wall") && stdout.contains("small.floor"),
        "{stdout}"
    );
    let (code, stdout, _) = inspc(&["faces", "examples/swiss_block.insp"]);
    assert_eq!(code, 0);
    assert!(stdout.starts_with("swiss_block: 206 faces"), "{stdout}");
}

#[test]
fn faces_of_a_missing_mesh_is_a_diagnostic() {
    let (code, _, stderr) = inspc(&["faces", "no/such/part.stl"]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("insp::geometry::mesh_unreadable"),
        "{stderr}"
    );
}

#[test]
fn graph_prints_dot_mermaid_and_json() {
    let (code, dot, stderr) = inspc(&["graph", "examples/f2.insp"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        dot.starts_with("digraph \"f2\" {") && dot.trim_end().ends_with('}'),
        "{dot}"
    );
    assert!(
        dot.contains("stock.top\\nplane · 4 points\\ncan rest on the table"),
        "{dot}"
    );
    assert!(dot.contains("[style=dashed, label=\"datum\"]"), "{dot}");

    let (code, with_points, _) = inspc(&["graph", "examples/f2.insp", "--points"]);
    assert_eq!(code, 0);
    assert_eq!(
        with_points.matches("shape=point").count(),
        20,
        "{with_points}"
    );

    let (code, mermaid, _) = inspc(&["graph", "examples/f2.insp", "--format", "mermaid"]);
    assert_eq!(code, 0);
    assert!(
        mermaid.starts_with("flowchart TD\n") && mermaid.contains("-. datum .->"),
        "{mermaid}"
    );

    let (code, json, _) = inspc(&["graph", "examples/swiss_block.insp", "--format", "json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&json).expect("graph --format json is JSON");
    let g = &v[0];
    assert_eq!(g["plan"], "swiss_block_plan");
    assert_eq!(g["counts"]["faces"], 101);
    let points: usize = g["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["points"].as_array().unwrap().len())
        .sum();
    assert_eq!(g["counts"]["fpoints"], points);
    assert_eq!(g["faces"][0]["points"][0]["n"].as_array().unwrap().len(), 3);
}

#[test]
fn graph_of_both_nist_parts() {
    common::require_shared_parts();
    for (spec, tolerances) in [
        ("tests/real/nist_ctc_01.insp", 14),
        ("tests/real/nist_ftc_08.insp", 42),
    ] {
        let (code, json, stderr) = inspc(&["graph", spec, "--format", "json"]);
        assert_eq!(code, 0, "{spec}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v[0]["counts"]["tolerances"], tolerances, "{spec}");
        assert!(
            v[0]["faces"]
                .as_array()
                .unwrap()
                .iter()
                .all(|f| !f["points"].as_array().unwrap().is_empty()),
            "{spec}: a face without points"
        );
    }
}

#[test]
fn graph_of_a_bad_spec_exits_one() {
    let spec = temp_spec(
        "bad_graph.insp",
        "part p { units mm, stock box(10, 10, 10), feature f = stock.tpo }\n",
    );
    let (code, out, stderr) = inspc(&["graph", &spec]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        out.is_empty() && stderr.contains("insp::resolve::"),
        "{stderr}"
    );
}

#[test]
fn cones_prints_a_summary_and_draws_the_cone() {
    let dir = std::env::temp_dir().join(format!("inspc-cones-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("cone.pgm");
    let (code, stdout, stderr) = inspc(&[
        "cones",
        "examples/f4.insp",
        "--face",
        "large.wall",
        "--point",
        "2",
        "--probe",
        "large",
        "-n",
        "32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    for needle in [
        "face large.wall (cylinder)",
        "probe large",
        "stylus",
        "body",
        "D2 (setup directions)",
        "wrote",
    ] {
        assert!(stdout.contains(needle), "no `{needle}` in:\n{stdout}");
    }
    let bytes = std::fs::read(&out).unwrap();
    assert!(bytes.starts_with(b"P5\n128 96\n255\n"));
    assert_eq!(bytes.len(), "P5\n128 96\n255\n".len() + 128 * 96);
    // Inside the large bore few directions are free, but the way out along its axis is.
    assert!(stdout.contains("axes in the cone: -y"), "{stdout}");
    let (code, stdout, stderr) = inspc(&[
        "cones",
        "examples/f4.insp",
        "--face",
        "stock.top",
        "-n",
        "32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let axes = stdout
        .lines()
        .find(|l| l.contains("axes in the cone"))
        .unwrap();
    assert!(axes.ends_with("+z") && !axes.contains("-z"), "{stdout}");
    let bytes = std::fs::read(&out).unwrap();
    // On the top, the upper half of the sphere is largely free.
    let px = &bytes["P5\n128 96\n255\n".len()..];
    let white = px.iter().filter(|&&b| b == 255).count();
    let black = px.iter().filter(|&&b| b == 0).count();
    assert!(white > 0 && black > white, "{white} free, {black} blocked");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn cones_of_unknown_names_are_diagnostics() {
    for (args, code) in [
        (&["--face", "nope"][..], "insp::access::unknown_face"),
        (&["--probe", "zz"][..], "insp::access::unknown_probe"),
        (
            &["--face", "small.wall", "--point", "99"][..],
            "insp::access::no_point",
        ),
    ] {
        let mut all = vec!["cones", "examples/f4.insp"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", "/nonexistent-dir/never.pgm"]);
        let (status, _, stderr) = inspc(&all);
        assert_eq!(status, 1);
        assert!(stderr.contains(code), "{args:?}: {stderr}");
    }
    let spec = temp_spec(
        "cones_no_machine.insp",
        "part p {\n    units mm\n    stock box(10, 10, 10)\n    feature top = stock.top\n}\n",
    );
    let (status, _, stderr) = inspc(&[
        "cones",
        &spec,
        "--probe",
        "p1",
        "-o",
        "/nonexistent-dir/x.pgm",
    ]);
    assert_eq!(status, 1);
    assert!(stderr.contains("insp::access::no_machine"), "{stderr}");
}

#[test]
fn build_writes_the_program_and_the_plan() {
    let dir = std::env::temp_dir().join(format!("inspc-build-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dmi = dir.join("f2.dmi");
    let json = dir.join("f2.json");
    let (code, stdout, stderr) = inspc(&[
        "build",
        "examples/f2.insp",
        "-o",
        dmi.to_str().unwrap(),
        "--plan-json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("1 setup, 2 probes"), "{stdout}");
    assert!(
        stdout.contains(&format!("wrote {}", dmi.display())),
        "{stdout}"
    );
    assert!(stdout.contains("time: front end"), "{stdout}");
    let program = std::fs::read_to_string(&dmi).unwrap();
    assert!(program.contains("DMISMN/'F2_PLAN',05.3") && program.ends_with("ENDFIL\n"));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert!(v["paths"].as_array().is_some_and(|p| !p.is_empty()), "{v}");
    // The program reads back clean.
    let (code, stdout, stderr) = inspc(&["dmis", dmi.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("touches"), "{stdout}");
    // No temporary file is left beside it.
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("inspc-tmp"))
        .collect();
    assert!(left.is_empty());
}

#[test]
fn a_failed_build_writes_nothing() {
    let dir = std::env::temp_dir().join(format!("inspc-fail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dmi = dir.join("slot.dmi");
    let (code, _, stderr) = inspc(&[
        "build",
        "tests/cases/uninspectable_slot/main.insp",
        "-o",
        dmi.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(
        stderr.contains("insp::plan::uninspectable_face"),
        "{stderr}"
    );
    assert!(stderr.contains("nothing written"), "{stderr}");
    assert!(!dmi.exists());
    assert_eq!(
        std::fs::read_dir(&dir).unwrap().count(),
        0,
        "no partial file"
    );
}

#[test]
fn the_dmis_reader_reports_what_a_controller_rejects() {
    let bad = temp_spec(
        "bad.dmi",
        "DMISMN/'X',05.3\nF(B-AD)=FEAT/POINT,CART,0,0,0,0,0,1\nMEAS/POINT,F(NONE),2\nPTMEAS/CART,1,2,3,0,0,1\nENDMES\nOUTPUT/FA(NONE),TA(T1)\n",
    );
    let (code, _, stderr) = inspc(&["dmis", &bad]);
    assert_eq!(code, 1);
    for c in [
        "insp::dmis::bad_label",
        "insp::dmis::undefined",
        "insp::dmis::structure",
    ] {
        assert!(stderr.contains(c), "{c}: {stderr}");
    }
    assert!(stderr.contains("help:"), "{stderr}");
}

/// A diagnostic about a machine declared in the stdlib is filed under the stdlib's file
/// and shows its source, not a failed read of the user's file.
#[test]
fn cones_with_a_stdlib_machine_point_into_the_stdlib() {
    let spec = temp_spec(
        "cones_std_machine.insp",
        "use std::cmms::bridge_fixed\n\npart p {\n    units mm\n    stock box(10, 10, 10)\n    feature top = stock.top\n}\n\nplan q { part p, cmm bridge_fixed }\n",
    );
    let (status, _, stderr) = inspc(&[
        "cones",
        &spec,
        "--probe",
        "zz",
        "-o",
        "/nonexistent-dir/x.pgm",
    ]);
    assert_eq!(status, 1, "{stderr}");
    assert!(stderr.contains("insp::access::unknown_probe"), "{stderr}");
    assert!(stderr.contains("cmm bridge_fixed"), "{stderr}");
    assert!(!stderr.contains("Failed to read"), "{stderr}");
}

/// `output { graph }` writes the plan's measurement graph beside the program, in the
/// format its extension asks for.
#[test]
fn build_writes_the_graph_the_plan_asks_for() {
    let dir = std::env::temp_dir().join(format!("inspc-graph-out-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f2 = std::fs::read_to_string("examples/f2.insp").unwrap();
    let spec = dir.join("f2.insp");
    std::fs::write(
        &spec,
        f2.replace(
            "    sampling fan_leu\n}",
            "    sampling fan_leu\n    output { dmis \"f2.dmi\", graph \"f2.mmd\" }\n}",
        ),
    )
    .unwrap();
    let (code, stdout, stderr) = inspc(&["build", spec.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    let graph = std::fs::read_to_string(dir.join("f2.mmd")).unwrap();
    assert!(
        graph.starts_with("flowchart") || graph.contains("graph"),
        "{graph}"
    );
    assert!(graph.contains("small_slot"), "{graph}");
    assert!(stdout.contains("f2.mmd"), "{stdout}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A scratch folder holding a copy of F2's spec, for the file-rule tests.
fn f2_in(tag: &str) -> (std::path::PathBuf, String) {
    let dir = std::env::temp_dir().join(format!("inspc-files-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("f2.insp");
    std::fs::copy("examples/f2.insp", &spec).unwrap();
    let s = spec.to_string_lossy().into_owned();
    (dir, s)
}

/// An existing target that is not a regular file is refused, not replaced; nothing is
/// written.
#[test]
fn outputs_never_replace_a_folder_or_a_device() {
    let (dir, spec) = f2_in("notafile");
    let folder = dir.join("out.dmi");
    std::fs::create_dir_all(&folder).unwrap();
    let (code, _, stderr) = inspc(&["build", &spec, "-o", folder.to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("insp::io::not_a_file"), "{stderr}");
    assert!(folder.is_dir());
    if std::path::Path::new("/dev/full").exists() {
        let (code, _, stderr) = inspc(&["build", &spec, "-o", "/dev/full"]);
        assert_eq!(code, 1, "{stderr}");
        assert!(stderr.contains("insp::io::not_a_file"), "{stderr}");
        let meta = std::fs::metadata("/dev/full").unwrap();
        assert!(!meta.is_file(), "/dev/full was replaced by a regular file");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// An output never replaces an input, and two outputs never share a file.
#[test]
fn outputs_never_replace_an_input_or_each_other() {
    let (dir, spec) = f2_in("inputs");
    let before = std::fs::read(&spec).unwrap();
    let (code, _, stderr) = inspc(&["build", &spec, "-o", &spec]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("insp::io::overwrites_input"), "{stderr}");
    assert_eq!(
        std::fs::read(&spec).unwrap(),
        before,
        "the spec was overwritten"
    );
    let out = dir.join("x.dmi");
    let out = out.to_str().unwrap();
    let (code, _, stderr) = inspc(&["build", &spec, "-o", out, "--plan-json", out]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("insp::io::same_output"), "{stderr}");
    assert!(!std::path::Path::new(out).exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// When one output cannot be written, none is: the program is not left behind by a
/// plan JSON that failed.
#[test]
fn outputs_are_written_all_or_none() {
    let (dir, spec) = f2_in("allornone");
    let dmi = dir.join("f2.dmi");
    let json = dir.join("missing-folder").join("plan.json");
    let (code, _, stderr) = inspc(&[
        "build",
        &spec,
        "-o",
        dmi.to_str().unwrap(),
        "--plan-json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("insp::io::unwritable"), "{stderr}");
    assert!(
        !dmi.exists(),
        "the program was written although the plan JSON failed"
    );
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("inspc-tmp"))
        .collect();
    assert!(left.is_empty(), "temporaries left: {left:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Links planted where inspc writes are never followed: not at the temporary names
/// (they are new and exclusive), and not at the target (the rename replaces the link).
#[cfg(unix)]
#[test]
fn planted_links_are_not_followed() {
    let (dir, spec) = f2_in("links");
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "keep me").unwrap();
    for name in [".f2.dmi.inspc-tmp", ".f2.dmi.tmp"] {
        std::os::unix::fs::symlink(&victim, dir.join(name)).unwrap();
    }
    let target = dir.join("f2.dmi");
    std::os::unix::fs::symlink(&victim, &target).unwrap();
    let (code, _, stderr) = inspc(&["build", &spec]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "keep me");
    let meta = std::fs::symlink_metadata(&target).unwrap();
    assert!(
        meta.is_file(),
        "the program replaced the link, as a file of its own"
    );
    assert!(std::fs::read_to_string(&target)
        .unwrap()
        .starts_with("$$ inspc"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Reading stops at what is not a regular file, and `use` reads only specs, quoting
/// nothing of anything else.
#[test]
fn only_regular_files_and_only_specs_are_read() {
    if std::path::Path::new("/dev/zero").exists() {
        let (code, _, stderr) = inspc(&["dmis", "/dev/zero"]);
        assert_eq!(code, 1, "{stderr}");
        assert!(stderr.contains("insp::io::unreadable"), "{stderr}");
        assert!(stderr.contains("not a regular file"), "{stderr}");
        let spec = temp_spec("use_zero.insp", "use \"/dev/zero\"\n");
        let (code, _, stderr) = inspc(&["check", &spec]);
        assert_eq!(code, 1, "{stderr}");
        assert!(stderr.contains("insp::load::not_a_spec"), "{stderr}");
    }
    let dir = std::env::temp_dir().join(format!("inspc-secret-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("secret.txt"), "root:x:0:0:TOP-SECRET\n").unwrap();
    let spec = dir.join("main.insp");
    std::fs::write(&spec, "use \"secret.txt\"\n").unwrap();
    let (code, _, stderr) = inspc(&["check", spec.to_str().unwrap()]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("insp::load::not_a_spec"), "{stderr}");
    assert!(!stderr.contains("TOP-SECRET"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Escape sequences and bidirectional overrides in a spec never reach the terminal raw.
#[test]
fn control_characters_are_not_printed_raw() {
    let spec = temp_spec(
        "escapes.insp",
        "part p {\n    units mm\n    stock box(10, 10, 10)\n    feature f = stock.t\u{1b}[31mop\u{202e}x\n}\n",
    );
    let (code, _, stderr) = inspc(&["check", &spec]);
    assert_eq!(code, 1, "{stderr}");
    assert!(!stderr.contains('\u{1b}'), "{stderr:?}");
    assert!(!stderr.contains('\u{202e}'), "{stderr:?}");
}

#[test]
fn import_writes_a_spec_that_checks_and_reports_a_broken_file() {
    crate::common::require_shared_parts();
    let dir = std::env::temp_dir().join(format!("inspc_import_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("ctc_01.insp");
    let step = std::fs::canonicalize("../shared/parts/nist_ctc_01_asme1_ap242-e1.stp").unwrap();
    let (code, out, err) = inspc(&[
        "import",
        step.to_str().unwrap(),
        "-o",
        spec.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.is_empty());
    assert!(err.contains("datums 3 of 3, tolerances 6 of 6"), "{err}");
    let text = std::fs::read_to_string(&spec).unwrap();
    assert!(text.contains("datum B = datum_b"), "{text}");
    let (code, _, err) = inspc(&["check", spec.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    // A truncated file: a diagnostic with its code, and nothing written.
    let bytes = std::fs::read(&step).unwrap();
    let broken = dir.join("broken.stp");
    std::fs::write(&broken, &bytes[..bytes.len() / 3]).unwrap();
    let out_spec = dir.join("broken.insp");
    let (code, _, err) = inspc(&[
        "import",
        broken.to_str().unwrap(),
        "-o",
        out_spec.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(err.contains("insp::geometry::step_"), "{err}");
    assert!(!out_spec.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A bore sampled densely puts every stand-off near its axis; their lifted copies were
/// one another's nearest roadmap neighbours and formed an island the path stage could
/// not leave (swiss_block at 10 points per hole failed with `insp::path::no_path`).
/// `Roadmap::bridge` joins such islands; the program runs in tolerance at nominal.
#[test]
fn densely_sampled_bores_get_a_path() {
    let text = std::fs::read_to_string("examples/swiss_block.insp")
        .unwrap()
        .replace("hammersley(points 6)", "hammersley(points 10)");
    assert!(text.contains("points 10"));
    let spec = temp_spec("swiss_block_dense.insp", &text);
    let program = spec.replace(".insp", ".dmi");
    let (code, stdout, stderr) = inspc(&["build", &spec, "-o", &program]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains("tolerances measured 1 of 1, 1 setup, 1 probe, 1 orientation"),
        "{stdout}"
    );
    let (code, stdout, stderr) = inspc(&["simulate", &program, &spec]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("100 in, 0 out"), "{stdout}");
}

/// `inspc view --png DIR`: a file where the folder should be is `insp::io::unwritable`,
/// and nothing is written; a run that writes nothing makes no folder.
#[test]
fn view_images_into_a_path_that_cannot_be_a_folder() {
    let dir = std::env::temp_dir().join(format!("inspc-view-png-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let page = dir.join("f2.html");
    let blocker = dir.join("images");
    std::fs::write(&blocker, "a file, not a folder").unwrap();
    let (code, _, stderr) = inspc(&[
        "view",
        "examples/f2.insp",
        "-o",
        page.to_str().unwrap(),
        "--png",
        blocker.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("insp::io::unwritable"), "{stderr}");
    assert!(!page.exists(), "nothing is written");
    // A spec that fails writes nothing and makes no folder.
    let bad = dir.join("bad.insp");
    std::fs::write(&bad, "part p {\n").unwrap();
    let images = dir.join("never");
    let (code, _, _) = inspc(&[
        "view",
        bad.to_str().unwrap(),
        "--png",
        images.to_str().unwrap(),
    ]);
    assert_eq!(code, 1);
    assert!(!images.exists(), "no folder for a run that writes nothing");
}

/// Issue 45: an MFCAD block (a 10 mm model of a 100 mm part, no PMI) imported with
/// `--scale 10` gets a default inspection that builds with every tolerance measured; a
/// scale out of range is refused before anything is read.
#[test]
fn a_part_without_pmi_is_imported_scaled_with_a_default_inspection_and_builds() {
    common::require_shared_parts();
    let dir = std::env::temp_dir().join(format!("inspc-mfcad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("block.insp");
    let spec = spec.to_string_lossy();
    let step = "../shared/parts/mfcad/0-0-0-2-5-23.step";
    let (code, _, stderr) = inspc(&["import", step, "--scale", "10", "-o", &spec]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("no PMI: a default inspection of"),
        "{stderr}"
    );
    let text = std::fs::read_to_string(&*spec).unwrap();
    assert!(text.contains("100 × 100 × 100 mm"), "{text}");
    assert!(text.contains("{ scale 10 }"), "{text}");
    assert!(text.contains("DEFAULT INSPECTION"), "{text}");
    let dmi = dir.join("block.dmi");
    let (code, stdout, stderr) = inspc(&["build", &spec, "-o", &dmi.to_string_lossy()]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.contains("tolerances measured 23 of 23"),
        "{stdout}{stderr}"
    );
    let (code, _, stderr) = inspc(&["import", step, "--scale", "0"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("a scale runs from 0.001 to 1000"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// An MFCAD part (`../shared/parts/mfcad/<name>.step`) imported as a 100 mm block,
/// built and planned.
struct Imported {
    /// The spec's text.
    text: String,
    /// `inspc build`'s summary.
    built: String,
    /// The program.
    program: String,
    /// `inspc plan`'s listing.
    plan: String,
}

impl Imported {
    /// Asserts the build measured all `n` tolerances of the spec.
    fn measures_all(&self, n: usize) {
        let all = format!("tolerances measured {n} of {n}");
        assert!(self.built.contains(&all), "{}", self.built);
    }
}

fn import_and_build(name: &str) -> Imported {
    common::require_shared_parts();
    let dir = std::env::temp_dir().join(format!("inspc-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let spec = dir.join("part.insp");
    let spec = spec.to_string_lossy();
    let step = format!("../shared/parts/mfcad/{name}.step");
    let (code, _, stderr) = inspc(&["import", &step, "--scale", "10", "-o", &spec]);
    assert_eq!(code, 0, "{stderr}");
    let text = std::fs::read_to_string(&*spec).unwrap();
    let dmi = dir.join("part.dmi");
    let (code, built, stderr) = inspc(&["build", &spec, "-o", &dmi.to_string_lossy()]);
    assert_eq!(code, 0, "{built}{stderr}");
    let program = std::fs::read_to_string(&dmi).unwrap();
    let (code, plan, stderr) = inspc(&["plan", &spec]);
    assert_eq!(code, 0, "{plan}{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
    Imported {
        text,
        built,
        program,
        plan,
    }
}

/// Issue 45: the floor of a hexagonal pocket 57 mm deep and 17.3 mm across flats (MFCAD
/// 8-8-11-12-12-23 as a 100 mm block) is past the 50 mm stylus: the import's rack adds
/// the stylus on a 50 mm extension, the floor's points keep the extension clear of the
/// pocket's walls, and the plan measures every default tolerance, the floor's distance
/// from the back with the long probe.
#[test]
fn a_pocket_floor_deeper_than_the_longest_stylus_is_measured_on_an_extension() {
    let part = import_and_build("8-8-11-12-12-23");
    assert!(part.text.contains("p4: TP20_D3_L50_X50"), "{}", part.text);
    part.measures_all(28);
    assert!(
        part.program.contains("SNSLCT/S(P4_"),
        "the floor is touched with p4"
    );
}

/// Issue 45: a block whose spec offers an angle and a sine plate (MFCAD 4-9-19). The
/// face a plate clamps cannot be touched there, whatever the probe's orientation: the
/// planner knows it before the first round, instead of learning it one plate angle a
/// round and stopping at its limit with the top face unmeasured.
#[test]
fn a_face_clamped_on_a_plate_is_not_planned_there() {
    let part = import_and_build("4-9-19");
    part.measures_all(12);
}

/// Issue 45: a triangular passage runs through the block (MFCAD 1-1-4-10-12-23); no
/// point of its walls has a way straight up or up the probe's axis, and the probe
/// leaves the part sideways before it rises. The path stage re-plans this part, and
/// `inspc plan` lists the plan the program was built from.
#[test]
fn a_passage_wall_is_left_sideways() {
    let part = import_and_build("1-1-4-10-12-23");
    part.measures_all(23);
    assert!(
        part.program.contains("MEAS/POINT,F(PLANE_13_P1)"),
        "the passage's wall `face_6` is touched"
    );
    let setups = part.plan.matches("change-setup").count();
    assert!(
        part.built.contains(&format!(", {setups} setups,")),
        "{}{}",
        part.plan,
        part.built
    );
}
