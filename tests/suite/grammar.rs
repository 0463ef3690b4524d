//! The grammar accepts and rejects what it should, and builds the right tree.

use inspc::source::FileId;
use inspc::syntax::ast::*;
use inspc::syntax::parse;

fn ok(src: &str) -> File {
    parse(FileId(0), src).unwrap_or_else(|e| panic!("{src:?} should parse: {e}"))
}

fn bad(src: &str) -> String {
    match parse(FileId(0), src) {
        Ok(_) => panic!("{src:?} should not parse"),
        Err(e) => e.to_string(),
    }
}

fn first_prop_value(src: &str) -> ValueKind {
    match &ok(src).items[0] {
        Item::Block(b) => b.props[0].value.kind.clone(),
        other => panic!("not a block: {other:?}"),
    }
}

#[test]
fn separators_comments_and_empty_files() {
    ok("");
    ok("\n\n// only a comment\n/* and a\nblock */\n");
    ok("stylus s { tip 2 mm; length 20 mm\n stem 1 mm, }");
    ok("stylus s {\n  tip 2 mm // the ball\n  length 20 mm /* to the centre */\n  stem 1 mm\n}");
    ok("use std::heads::PH6; use std::probes::*");
}

#[test]
fn use_forms() {
    let f = ok("use std::heads::PH6\nuse std::probes::{A, B,}\nuse std::styli::*\nuse \"lib/lab.insp\"\nuse \"lib/x.insp\"::{c}");
    let kinds: Vec<String> = f
        .items
        .iter()
        .map(|i| match i {
            Item::Use(u) => format!(
                "{}{}",
                match &u.source {
                    UseSource::Module(s) => s
                        .iter()
                        .map(|i| i.name.clone())
                        .collect::<Vec<_>>()
                        .join("::"),
                    UseSource::File(s) => format!("\"{}\"", s.value),
                },
                match &u.select {
                    UseSelect::Implicit => String::new(),
                    UseSelect::Glob(_) => "::*".into(),
                    UseSelect::Names(n) => format!(
                        "::{{{}}}",
                        n.iter()
                            .map(|i| i.name.clone())
                            .collect::<Vec<_>>()
                            .join(",")
                    ),
                }
            ),
            _ => unreachable!(),
        })
        .collect();
    assert_eq!(
        kinds,
        [
            "std::heads::PH6",
            "std::probes::{A,B}",
            "std::styli::*",
            "\"lib/lab.insp\"",
            "\"lib/x.insp\"::{c}"
        ]
    );
}

#[test]
fn quantities_limits_ranges_and_directions() {
    assert!(
        matches!(first_prop_value("stylus s { tip 2.5 mm }"), ValueKind::Quantity(Quantity { value, unit: Some(u), .. }) if value == 2.5 && u.name == "mm")
    );
    assert!(
        matches!(first_prop_value("stylus s { tip .5 }"), ValueKind::Quantity(Quantity { value, unit: None, .. }) if value == 0.5)
    );
    assert!(
        matches!(first_prop_value("stylus s { tip 1e-3 m }"), ValueKind::Quantity(Quantity { value, .. }) if value == 1e-3)
    );
    assert!(
        matches!(first_prop_value("stylus s { tip 20 % }"), ValueKind::Quantity(Quantity { unit: Some(u), .. }) if u.name == "%")
    );
    match first_prop_value("head h { a 0 deg .. 105 deg }") {
        ValueKind::Range(a, b) => assert_eq!((a.value, b.value), (0.0, 105.0)),
        v => panic!("{v:?}"),
    }
    match first_prop_value("head h { a 10 mm ± 0.1 mm }") {
        ValueKind::Limits {
            nominal,
            plus,
            minus,
        } => assert_eq!((nominal.value, plus.value, minus.value), (10.0, 0.1, -0.1)),
        v => panic!("{v:?}"),
    }
    // ASCII spellings of ±: `+-`, and `+/-` as drawings and DMIS programs write it.
    for pm in ["+-", "+/-"] {
        match first_prop_value(&format!("head h {{ a 10 mm {pm} 0.1 mm }}")) {
            ValueKind::Limits { plus, minus, .. } => {
                assert_eq!((plus.value, minus.value), (0.1, -0.1))
            }
            v => panic!("{pm}: {v:?}"),
        }
    }
    match first_prop_value("head h { a 35 mm -0.2 mm +0 mm }") {
        ValueKind::Limits { plus, minus, .. } => assert_eq!((plus.value, minus.value), (0.0, -0.2)),
        v => panic!("{v:?}"),
    }
    assert!(matches!(
        first_prop_value("head h { a -z }"),
        ValueKind::Direction {
            axis: 2,
            negative: true
        }
    ));
    assert!(matches!(
        first_prop_value("head h { a +x }"),
        ValueKind::Direction {
            axis: 0,
            negative: false
        }
    ));
    bad("head h { a +xy }");
}

#[test]
fn lists_tuples_calls_blocks_and_paths() {
    match first_prop_value("cmm c { probes [p1: A, B,\n  p3: std::probes::C] }") {
        ValueKind::List(e) => {
            assert_eq!(e.len(), 3);
            assert_eq!(e[0].label.as_ref().unwrap().name, "p1");
            assert!(e[1].label.is_none());
        }
        v => panic!("{v:?}"),
    }
    match first_prop_value("cmm c { at (1, 2 mm,\n 3) }") {
        ValueKind::Tuple(t) => assert_eq!(t.len(), 3),
        v => panic!("{v:?}"),
    }
    match first_prop_value("cmm c { ram { radius 35 mm, length 600 mm } }") {
        ValueKind::Block(p) => assert_eq!(p.len(), 2),
        v => panic!("{v:?}"),
    }
    match first_prop_value("sampling s { plane uniform(points 9, inset 1 mm) }") {
        ValueKind::Call(c) => {
            assert_eq!(c.callee.text, "uniform");
            assert!(matches!(&c.args[0], Arg::Named(k, _) if k.name == "points"));
        }
        v => panic!("{v:?}"),
    }
    match first_prop_value("cmm c { f grid[3].wall }") {
        ValueKind::Path(p) => {
            assert_eq!(p.segs.len(), 3);
            assert!(matches!(p.segs[1], PathSeg::Index(3, _)));
        }
        v => panic!("{v:?}"),
    }
}

#[test]
fn part_statements() {
    let f = ok(r#"part p {
        units mm
        stock box(120, 60, 40)
        mesh "x.stl" { units in }
        cut slot s { at (30, 0, 40), along +y, width 20, depth 25 }
        add boss b { at (0, 0, 0), diameter 5, height 5 }
        face f1 = s.floor
        feature f2 = stock.top + s.walls
            + group "face_3"
            + segment 4 + select(plane, normal +z)
        feature empty
        datum A = f2
        frame ABC = [A, B(MMC), C]
        tolerance T = position(f2, dia 0.1 mm, MMC, A, B(LMC))
    }"#);
    let Item::Part(p) = &f.items[0] else { panic!() };
    assert_eq!(p.stmts.len(), 11);
    let PartStmt::Named { expr: Some(e), .. } = &p.stmts[6] else {
        panic!("{:?}", p.stmts[6])
    };
    assert_eq!(e.terms.len(), 5);
    assert!(matches!(&e.terms[2], FaceTerm::Group(s) if s.value == "face_3"));
    assert!(matches!(&p.stmts[7], PartStmt::Named { expr: None, .. }));
    let PartStmt::Tolerance { call, .. } = &p.stmts[10] else {
        panic!()
    };
    assert_eq!(call.args.len(), 5);
    assert!(matches!(
        &call.args[4],
        Arg::Positional(Value {
            kind: ValueKind::Call(_),
            ..
        })
    ));
}

#[test]
fn hierarchies_and_plans() {
    let f = ok("hierarchy h {\n required approachability\n same_setup(T, F, *)\n same_orien(*, *)\n}\nplan q {\n part p\n prefer setup (0, 1, 1) weight 0.5\n forbid setup -z\n prefer orientation (30 deg, -90 deg)\n sample f with hammersley(points 5)\n output { dmis \"q.dmi\" }\n}");
    let Item::Hierarchy(h) = &f.items[0] else {
        panic!()
    };
    assert_eq!(h.levels.len(), 3);
    assert!(matches!(&h.levels[1], Level::Same { group, .. } if group.len() == 3));
    let Item::Plan(p) = &f.items[1] else { panic!() };
    assert_eq!(p.stmts.len(), 6);
    assert!(matches!(&p.stmts[1], PlanStmt::Pref { forbid: false, opts, .. } if opts.len() == 1));
    assert!(matches!(&p.stmts[2], PlanStmt::Pref { forbid: true, .. }));
}

#[test]
fn strings_unescape() {
    let f = ok(r#"part p { mesh "a\"b\\c\td.stl" }"#);
    let Item::Part(p) = &f.items[0] else { panic!() };
    let PartStmt::Mesh { path, .. } = &p.stmts[0] else {
        panic!()
    };
    assert_eq!(path.value, "a\"b\\c\td.stl");
}

#[test]
fn rejections() {
    bad("part { units mm }");
    bad("part p { units }");
    bad("stylus s { tip 2 mm length 20 mm }");
    bad("stylus s tip 2 mm");
    bad("part p { feature f = }");
    bad("hierarchy h { same_setup T }");
    bad("use std::heads::{}");
    bad("stylus s { tip \"unterminated }");
    bad("stylus s { tip 2 mm } }");
    bad("part p { tolerance T = 5 }");
    let msg = bad("cmm c { probes [p1: A p2: B] }");
    assert!(msg.starts_with("expected "), "{msg}");
}
