//! Hostile STEP and QIF files, built here: each class of input that once aborted,
//! overflowed the stack, looped or asked for gigabytes ends in its diagnostic or a
//! correct read. Self-references and circles of references (`step_cycle`,
//! `qif_cycle`), nesting and chains 100,000 deep, counts of 10¹² and `i64::MAX`,
//! aggregates of many arcs, elements with 100,000 attributes. No test asserts a time:
//! each input is large enough that the old quadratic or unbounded work would not end.

use inspc::geometry::qif::QifError;
use inspc::geometry::step::{self, StepError, RESOLUTION};
use inspc::geometry::{qif, MeshError};
use miette::Diagnostic;

/// The code of a read's error, or `ok`.
fn outcome(r: Result<step::CadPart, MeshError>) -> String {
    match r {
        Ok(_) => "ok".into(),
        Err(MeshError::Step(e)) => e.code().map(|c| c.to_string()).unwrap_or_default(),
        Err(MeshError::Qif(e)) => e.code().map(|c| c.to_string()).unwrap_or_default(),
        Err(MeshError::TooLarge(_)) => "insp::geometry::mesh_too_large".into(),
        Err(MeshError::NotClosed(_)) => "insp::geometry::mesh_not_closed".into(),
        Err(MeshError::Extent { .. }) => "insp::geometry::part_too_large".into(),
        Err(e) => format!("{e:?}"),
    }
}

/// A STEP file: a millimetre solid `#1` whose shell is `#2`, with `data` beside.
fn step_file(data: &str) -> Vec<u8> {
    format!(
        "ISO-10303-21;\nHEADER;\nFILE_SCHEMA(('AP242'));\nENDSEC;\nDATA;\n\
         #1=MANIFOLD_SOLID_BREP('',#2);\n\
         #3=ADVANCED_BREP_SHAPE_REPRESENTATION('',(#1),#4);\n\
         #4=(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNIT_ASSIGNED_CONTEXT((#5))REPRESENTATION_CONTEXT('',''));\n\
         #5=(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.));\n{data}ENDSEC;\nEND-ISO-10303-21;\n"
    )
    .into_bytes()
}

/// A plane face `#6` bounded by one edge whose curve is `#20` (defined by `curve`).
fn step_edge_curve(curve: &str) -> Vec<u8> {
    step_file(&format!(
        "#2=CLOSED_SHELL('',(#6));\n#6=ADVANCED_FACE('',(#10),#7,.T.);\n#7=PLANE('',#8);\n\
         #8=AXIS2_PLACEMENT_3D('',#9,$,$);\n#9=CARTESIAN_POINT('',(0.,0.,0.));\n\
         #10=FACE_OUTER_BOUND('',#11,.T.);\n#11=EDGE_LOOP('',(#12));\n\
         #12=ORIENTED_EDGE('',*,*,#13,.T.);\n#13=EDGE_CURVE('',#14,#14,#20,.T.);\n\
         #14=VERTEX_POINT('',#9);\n#15=CARTESIAN_POINT('',(1.,0.,0.));\n\
         #16=CARTESIAN_POINT('',(0.,1.,0.));\n{curve}"
    ))
}

fn step_code(bytes: &[u8]) -> String {
    outcome(step::read(bytes, RESOLUTION))
}

#[test]
fn step_circles_of_references_are_step_cycle() {
    // A shell that is itself, and two that are each other.
    let own = step_file("#2=ORIENTED_CLOSED_SHELL('',*,#2,.T.);\n");
    assert_eq!(step_code(&own), "insp::geometry::step_cycle");
    let pair = step_file(
        "#2=ORIENTED_CLOSED_SHELL('',*,#6,.T.);\n#6=ORIENTED_CLOSED_SHELL('',*,#2,.F.);\n",
    );
    assert_eq!(step_code(&pair), "insp::geometry::step_cycle");
    // A curve trimming itself, and three curves round a circle.
    let own = step_edge_curve("#20=TRIMMED_CURVE('',#20,(),(),.T.,.PARAMETER.);\n");
    assert_eq!(step_code(&own), "insp::geometry::step_cycle");
    let three = step_edge_curve(
        "#20=TRIMMED_CURVE('',#21,(),(),.T.,.PARAMETER.);\n#21=SURFACE_CURVE('',#22,(),.CURVE_3D.);\n\
         #22=SEAM_CURVE('',#20,(),.CURVE_3D.);\n",
    );
    let r = step::read(&three, RESOLUTION);
    let Err(MeshError::Step(StepError::Cycle { ids, .. })) = r else {
        panic!("{r:?}");
    };
    assert_eq!(ids, vec![20, 21, 22]);
}

#[test]
fn a_datum_reference_listing_itself_is_step_cycle() {
    let pmi = "#2=CLOSED_SHELL('',(#6));\n#6=ADVANCED_FACE('',(),#7,.T.);\n#7=PLANE('',#8);\n\
        #8=AXIS2_PLACEMENT_3D('',#9,$,$);\n#9=CARTESIAN_POINT('',(0.,0.,0.));\n\
        #40=LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(0.1),#5);\n\
        #31=PERPENDICULARITY_TOLERANCE('t','',#40,$,(#32));\n\
        #32=DATUM_REFERENCE_COMPARTMENT('','',$,.F.,(#33),$);\n\
        #33=DATUM_REFERENCE_ELEMENT('','',$,.F.,(#32),$);\n";
    assert_eq!(step_code(&step_file(pmi)), "insp::geometry::step_cycle");
}

#[test]
fn deep_chains_and_nesting_are_diagnostics() {
    // 100,000 curves each trimming the next: deeper than any schema nests.
    let mut chain = String::new();
    for k in 20..100_020 {
        chain += &format!("#{k}=TRIMMED_CURVE('',#{},(),(),.T.,.PARAMETER.);\n", k + 1);
    }
    chain += "#100020=LINE('',#9,#9);\n";
    assert_eq!(
        step_code(&step_edge_curve(&chain)),
        "insp::geometry::step_malformed"
    );
    // 100,000 nested parentheses.
    let deep = format!(
        "#9=CARTESIAN_POINT('',{}{});\n",
        "(".repeat(100_000),
        ")".repeat(100_000)
    );
    assert_eq!(step_code(&step_file(&deep)), "insp::geometry::step_syntax");
}

#[test]
fn b_spline_counts_are_checked_before_they_size_anything() {
    let spline = |degree: &str, mults: &str| {
        step_edge_curve(&format!(
            "#20=B_SPLINE_CURVE_WITH_KNOTS('',{degree},(#9,#15,#16),.UNSPECIFIED.,.F.,.F.,({mults}),(0.,1.),.UNSPECIFIED.);\n"
        ))
    };
    for (degree, mults) in [
        ("2", "1000000000000,3"),
        ("2", "9223372036854775807,9223372036854775807"),
        ("2", "300000000,3"),
        ("2", "-3,3"),
        ("1000000000000", "3,3"),
        ("9223372036854775807", "3,3"),
    ] {
        assert_eq!(
            step_code(&spline(degree, mults)),
            "insp::geometry::step_malformed",
            "{degree} {mults}"
        );
    }
    // The same curve with fitting counts reads on, to the face's own error (the curve
    // does not close its loop).
    assert_eq!(step_code(&spline("2", "3,3")), "insp::geometry::step_face");
}

#[test]
fn a_face_named_over_and_over_is_meshed_once() {
    let many = vec!["#6"; 100_000].join(",");
    let file = step_file(&format!(
        "#2=CLOSED_SHELL('',({many}));\n#6=ADVANCED_FACE('',(),#7,.T.);\n#7=PLANE('',#8);\n\
         #8=AXIS2_PLACEMENT_3D('',#9,$,$);\n#9=CARTESIAN_POINT('',(0.,0.,0.));\n"
    ));
    let r = step::read(&file, RESOLUTION);
    let Err(MeshError::Step(StepError::Faces(list))) = r else {
        panic!("{r:?}");
    };
    assert_eq!(list.len(), 1);
}

/// A QIF document: `pmi` at the top level, one plane face with `loops` (ids) and the
/// `topology` and `geometry` sets' further contents.
fn qif_file(pmi: &str, loops: &str, topology: &str, geometry: &str) -> Vec<u8> {
    format!(
        "<?xml version=\"1.0\"?>\n<QIFDocument versionQIF=\"3.0.0\">\n\
         <FileUnits><PrimaryUnits><LinearUnit><SIUnitName>meter</SIUnitName><UnitName>mm</UnitName>\
         <UnitConversion><Factor>0.001</Factor></UnitConversion></LinearUnit></PrimaryUnits></FileUnits>\n\
         {pmi}\n<Product><GeometrySet><SurfaceSet><Plane23 id=\"4\"><Plane23Core><Origin>0 0 0</Origin>\
         <Normal>0 0 1</Normal></Plane23Core></Plane23></SurfaceSet>{geometry}</GeometrySet>\n\
         <TopologySet><FaceSet><Face id=\"3\"><Surface><Id>4</Id></Surface>{loops}</Face></FaceSet>\n\
         {topology}<BodySet><Body id=\"1\" form=\"SOLID\"><FaceIds><Id>3</Id></FaceIds></Body></BodySet>\
         </TopologySet></Product>\n</QIFDocument>\n"
    )
    .into_bytes()
}

fn qif_code(bytes: &[u8]) -> String {
    outcome(qif::read(bytes, RESOLUTION))
}

/// Datum A on feature `first`, and the feature nominals `features`.
fn datum_on(first: u64, features: &str) -> String {
    format!(
        "<DatumDefinitions><DatumDefinition id=\"10\"><DatumLabel>A</DatumLabel><FeatureNominalIds>\
         <Id>{first}</Id></FeatureNominalIds></DatumDefinition></DatumDefinitions>\n\
         <Features><FeatureNominals>{features}</FeatureNominals></Features>"
    )
}

fn feature(id: u64, names: &[u64]) -> String {
    let ids: String = names.iter().map(|n| format!("<Id>{n}</Id>")).collect();
    format!("<PlaneFeatureNominal id=\"{id}\"><FeatureNominalIds>{ids}</FeatureNominalIds></PlaneFeatureNominal>\n")
}

#[test]
fn qif_feature_chains_read_and_circles_are_qif_cycle() {
    // 100,000 features each naming the next, the last the face: read (to the face's
    // own error: it has no loop).
    let mut chain = String::new();
    for k in 100..100_100 {
        chain += &feature(k, &[k + 1]);
    }
    chain += &feature(100_100, &[3]);
    assert_eq!(
        qif_code(&qif_file(&datum_on(100, &chain), "", "", "")),
        "insp::geometry::qif_face"
    );
    // A feature naming itself, and two naming each other.
    let own = datum_on(11, &feature(11, &[11]));
    assert_eq!(
        qif_code(&qif_file(&own, "", "", "")),
        "insp::geometry::qif_cycle"
    );
    let pair = datum_on(11, &(feature(11, &[12]) + &feature(12, &[3, 11])));
    let r = qif::read(&qif_file(&pair, "", "", ""), RESOLUTION);
    let Err(MeshError::Qif(QifError::Cycle { ids, .. })) = r else {
        panic!("{r:?}");
    };
    assert_eq!(ids, vec![11, 12]);
}

/// The face bounded by one edge whose curve is an aggregate of `arcs` arcs, each over
/// `domain`.
fn aggregate_of_arcs(arcs: usize, domain: &str) -> Vec<u8> {
    let arc = format!(
        "<SubCurve><ArcCircular13Core domain=\"{domain}\"><Radius>1</Radius><Center>0 0 0</Center>\
         <Normal>0 0 1</Normal><DirBeg>1 0 0</DirBeg></ArcCircular13Core></SubCurve>"
    );
    let geometry = format!(
        "<PointSet><Point id=\"30\"><XYZ>1 0 0</XYZ></Point></PointSet><CurveSet>\
         <Aggregate13 id=\"40\"><Aggregate13Core><SubCurves>{}</SubCurves></Aggregate13Core></Aggregate13>\
         </CurveSet>",
        arc.repeat(arcs)
    );
    let topology = "<VertexSet><Vertex id=\"31\"><Point><Id>30</Id></Point></Vertex></VertexSet>\
        <EdgeSet><Edge id=\"41\"><Curve><Id>40</Id></Curve><VertexBeg><Id>31</Id></VertexBeg>\
        <VertexEnd><Id>31</Id></VertexEnd></Edge></EdgeSet>\
        <LoopSet><Loop id=\"50\"><CoEdges><CoEdge><EdgeOriented><Id>41</Id></EdgeOriented></CoEdge>\
        </CoEdges></Loop></LoopSet>";
    let loops = "<LoopIds><Id>50</Id></LoopIds>";
    qif_file("", loops, topology, &geometry)
}

#[test]
fn aggregates_of_arcs_cost_in_proportion_to_the_file() {
    // 100 arcs each claiming a million radians: refused, not sampled.
    assert_eq!(
        qif_code(&aggregate_of_arcs(100, "0 1000000")),
        "insp::geometry::qif_malformed"
    );
    // 20,000 full turns need more points than a document's aggregates may take.
    assert_eq!(
        qif_code(&aggregate_of_arcs(20_000, "0 6.283185307179586")),
        "insp::geometry::qif_malformed"
    );
    // A hundred full turns read: a disc, meshed (one face: no closed solid).
    assert_eq!(
        qif_code(&aggregate_of_arcs(100, "0 6.283185307179586")),
        "insp::geometry::mesh_not_closed"
    );
}

#[test]
fn qif_elements_and_counts_are_bounded() {
    let attrs: String = (0..100_000).map(|k| format!(" a{k}=\"1\"")).collect();
    let wide = format!("<QIFDocument versionQIF=\"3.0.0\"{attrs}></QIFDocument>");
    assert_eq!(qif_code(wide.as_bytes()), "insp::geometry::qif_syntax");
    let twice = "<QIFDocument versionQIF=\"3.0.0\" a=\"1\" a=\"2\"></QIFDocument>";
    assert_eq!(qif_code(twice.as_bytes()), "insp::geometry::qif_syntax");
    let nesting = format!("{}{}", "<a>".repeat(100_000), "</a>".repeat(100_000));
    assert_eq!(qif_code(nesting.as_bytes()), "insp::geometry::qif_syntax");
}

/// A part larger than any CMM measures is refused before it is meshed (meshing to an
/// absolute chord costs more the larger the part): the NIST parts with their length
/// unit scaled up by a prefix, and a circle of radius 1 in hectometres. The same files
/// in their own unit read.
#[test]
fn parts_larger_than_a_cmm_are_refused_before_meshing() {
    let hecto = step_edge_curve("#20=CIRCLE('',#8,1.);\n");
    let hecto = String::from_utf8(hecto)
        .unwrap()
        .replace(".MILLI.", ".HECTO.");
    assert_eq!(
        step_code(hecto.as_bytes()),
        "insp::geometry::part_too_large"
    );
    let ctc = std::fs::read_to_string("../shared/parts/nist_ctc_01_asme1_ap242-e1.stp")
        .expect("the NIST parts beside the repository");
    for prefix in [".KILO.", ".HECTO.", ".DECA."] {
        let big = ctc.replace(
            "SI_UNIT(.MILLI.,.METRE.)",
            &format!("SI_UNIT({prefix},.METRE.)"),
        );
        assert_eq!(
            step_code(big.as_bytes()),
            "insp::geometry::part_too_large",
            "{prefix}"
        );
    }
    let qif = std::fs::read_to_string("../shared/parts/nist_ctc_01_asme1_ap242.qif").unwrap();
    let km = qif.replacen(
        "<UnitName>mm</UnitName>\n        <UnitConversion>\n          <Factor>0.001</Factor>",
        "<UnitName>km</UnitName>\n        <UnitConversion>\n          <Factor>1000</Factor>",
        1,
    );
    assert_ne!(km, qif, "the QIF file's linear unit was found");
    assert_eq!(qif_code(km.as_bytes()), "insp::geometry::part_too_large");
}
