//! No input string, however malformed, makes the front end panic.

use inspc::source::MemoryWorld;
use proptest::prelude::*;

fn check(src: &[u8]) {
    let mut w = MemoryWorld::new();
    w.insert("main.insp", src.to_vec());
    w.insert(
        "other.insp",
        b"use \"main.insp\"\nstylus o { tip 1 mm, length 10 mm, stem 0.5 mm }".to_vec(),
    );
    let checked = inspc::check(&w, &["main.insp".into()]);
    // Rendering every diagnostic must not panic either.
    for d in &checked.diagnostics {
        let _ = inspc::diag::render_human(&checked.sources, d, Default::default());
        let _ = inspc::diag::to_json(&checked.sources, d);
    }
}

const TOKENS: &[&str] = &[
    "part",
    "cmm",
    "head",
    "probe",
    "stylus",
    "body",
    "extension",
    "sampling",
    "plan",
    "hierarchy",
    "use",
    "std::heads::PH6",
    "\"other.insp\"",
    "units",
    "mm",
    "deg",
    "in",
    "%",
    "stock",
    "box",
    "sphere",
    "cylinder",
    "mesh",
    "\"x.stl\"",
    "cut",
    "add",
    "hole",
    "slot",
    "pocket",
    "step",
    "boss",
    "face",
    "feature",
    "datum",
    "frame",
    "tolerance",
    "group",
    "segment",
    "select",
    "flatness",
    "position",
    "diameter",
    "angle",
    "distance",
    "perpendicularity",
    "MMC",
    "dia",
    "basic",
    "A",
    "B",
    "top",
    "stock.top",
    "h[3].wall",
    "required",
    "approachability",
    "same_setup",
    "same_probe",
    "same_orient",
    "T",
    "F",
    "*",
    "(",
    ")",
    "{",
    "}",
    "[",
    "]",
    ",",
    ";",
    "\n",
    ":",
    "=",
    "+",
    "-",
    "±",
    "..",
    ".",
    "::",
    "0",
    "1",
    "-3",
    "2.5",
    "1e9",
    "7.5",
    "+z",
    "-x",
    "prefer",
    "forbid",
    "setup",
    "orientation",
    "weight",
    "sample",
    "with",
    "uniform",
    "fan_leu",
    "hammersley",
    "points",
    "inset",
    "at",
    "axis",
    "along",
    "into",
    "width",
    "depth",
    "through",
    "radial",
    "pattern",
    "grid",
    "polar",
    "linear",
    "tip",
    "length",
    "stem",
    "kind",
    "indexable",
    "fixed",
    "a",
    "b",
    "ram",
    "radius",
    "probes",
    "scanner",
    "scanners",
    "std::scanners::LC15Dx",
    "sensors",
    "laser",
    "sensor_ratio",
    "table",
    "z",
    "size",
    "//c\n",
    "/*",
    "*/",
];

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes(src in proptest::collection::vec(any::<u8>(), 0..400)) {
        check(&src);
    }

    #[test]
    fn arbitrary_text(src in "\\PC{0,300}") {
        check(src.as_bytes());
    }

    #[test]
    fn token_soup(tokens in proptest::collection::vec(proptest::sample::select(TOKENS), 0..120)) {
        check(tokens.join(" ").as_bytes());
    }

    #[test]
    fn mutated_examples(which in 0usize..8, edits in proptest::collection::vec((any::<prop::sample::Index>(), proptest::sample::select(TOKENS), 0u8..3), 1..6)) {
        let sources = [
            include_str!("../../examples/f2.insp"), include_str!("../../examples/f4.insp"), include_str!("../../examples/swiss_block.insp"),
            include_str!("../../examples/parts/f3.insp"), include_str!("../../examples/parts/swiss_sphere.insp"),
            include_str!("../../tests/cases/plan_preferences/main.insp"), include_str!("../../tests/cases/patterns_and_bosses/main.insp"),
            include_str!("../../stdlib/hierarchies.insp"),
        ];
        let mut text = sources[which].to_string();
        for (at, token, op) in edits {
            let mut i = at.index(text.len().max(1)).min(text.len());
            while !text.is_char_boundary(i) { i -= 1; }
            match op {
                0 => text.insert_str(i, token),
                1 => { let end = (i + token.len()).min(text.len()); let mut e = end; while !text.is_char_boundary(e) { e -= 1; } text.replace_range(i..e, ""); }
                _ => { let end = (i + 1).min(text.len()); let mut e = end; while !text.is_char_boundary(e) { e += 1; } text.replace_range(i..e.min(text.len()), token); }
            }
        }
        check(text.as_bytes());
    }
}

#[test]
fn pathological_inputs() {
    check("(".repeat(100_000).as_bytes());
    check("[".repeat(70).as_bytes());
    check(format!("part p {{ units mm, stock box({}) }}", "1, ".repeat(10_000)).as_bytes());
    check(format!("stylus s {{ tip {}9 mm }}", "9".repeat(400)).as_bytes());
    check(b"part p { units mm, feature f = g[4294967296].wall }");
    check(b"\xEF\xBB\xBFpart p { units mm }");
    check(b"part p { units mm, stock box(1, 1, 1), cut hole h { at (0,0,0), axis -z, diameter 1, depth 1, pattern grid(1000000, 1000000, 1, 1) }, feature f = h[5].wall }");
}
