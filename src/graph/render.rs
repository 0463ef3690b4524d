//! `inspc graph` output: Graphviz DOT, Mermaid and JSON.

use super::{Edge, MeasurementGraph, Node};
use crate::geometry::PartGeometry;
use crate::model::{fmt_num, Part};
use petgraph::graph::NodeIndex;
use std::fmt::Write;

/// A number rounded to the micrometre fraction inspc reports (1e-6 mm), without `-0`.
fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6 + 0.0
}

fn tolerance_text(part: &Part, k: usize) -> (String, String) {
    let t = &part.tolerances[k];
    let value = t.value.text();
    let kind = t.kind.keyword();
    let datums: Vec<&str> = t
        .datums
        .iter()
        .map(|r| part.datums[r.datum.0].name.as_str())
        .collect();
    let frame = if datums.is_empty() {
        String::new()
    } else {
        format!(" | {}", datums.join(" | "))
    };
    (t.name.clone(), format!("{kind} {value}{frame}"))
}

/// Each node's label lines.
fn label(part: &Part, g: &PartGeometry, mg: &MeasurementGraph, n: NodeIndex) -> Vec<String> {
    match &mg.graph[n] {
        Node::Part => vec![
            format!("part {}", part.name),
            format!("{} fpoints", mg.fpoints.len()),
        ],
        Node::Tolerance(k) => {
            let (name, text) = tolerance_text(part, *k);
            vec![name, text]
        }
        Node::Feature { feature, datums } => {
            let mut l = vec![part.features[feature.0].name.clone()];
            if !datums.is_empty() {
                l.push(format!("datum {}", datums.join(", ")));
            }
            if let Some(s) = mg.sensors.iter().find(|s| s.feature == *feature) {
                l.push(s.sensor.word().into());
            }
            l
        }
        Node::Face { face, on_table } => {
            let f = &g.faces[face.0];
            let points = mg.children(n).len();
            let mut l = vec![
                f.name.clone(),
                format!("{} · {points} points", f.surface.kind().keyword()),
            ];
            if *on_table {
                l.push("can rest on the table".into());
            }
            l
        }
        Node::Point(i) => {
            let p = &mg.fpoints[*i];
            vec![
                format!("p{i}"),
                format!(
                    "({}, {}, {})",
                    fmt_num(round6(p.position.x)),
                    fmt_num(round6(p.position.y)),
                    fmt_num(round6(p.position.z))
                ),
            ]
        }
    }
}

fn shown(mg: &MeasurementGraph, n: NodeIndex, points: bool) -> bool {
    points || !matches!(mg.graph[n], Node::Point(_))
}

/// The graph in Graphviz DOT; fpoints as nodes only when `points`, otherwise counted on
/// their faces.
pub fn dot(part: &Part, g: &PartGeometry, mg: &MeasurementGraph, points: bool) -> String {
    let esc = |s: &str| s.replace('\\', "\\\\").replace('"', "\\\"");
    let mut o = String::new();
    let _ = writeln!(o, "digraph \"{}\" {{", esc(&part.name));
    let _ = writeln!(
        o,
        "  rankdir=TB;\n  node [shape=box, fontname=\"Helvetica\"];"
    );
    for (n, node) in mg.nodes().filter(|(n, _)| shown(mg, *n, points)) {
        let text: Vec<String> = label(part, g, mg, n).iter().map(|l| esc(l)).collect();
        let style = match node {
            Node::Part => ", shape=doubleoctagon",
            Node::Tolerance(_) => ", shape=note",
            Node::Feature { datums, .. } if !datums.is_empty() => ", style=bold",
            Node::Face { on_table: true, .. } => ", style=filled, fillcolor=\"#dddddd\"",
            Node::Point(_) => ", shape=point",
            _ => "",
        };
        let _ = writeln!(
            o,
            "  n{} [label=\"{}\"{style}];",
            n.index(),
            text.join("\\n")
        );
    }
    for e in mg.graph.edge_indices() {
        let (a, b) = mg.graph.edge_endpoints(e).expect("edge");
        if !shown(mg, b, points) {
            continue;
        }
        let style = if mg.graph[e] == Edge::Datum {
            " [style=dashed, label=\"datum\"]"
        } else {
            ""
        };
        let _ = writeln!(o, "  n{} -> n{}{style};", a.index(), b.index());
    }
    o.push_str("}\n");
    o
}

/// The graph as a Mermaid flowchart; fpoints as with [`dot`].
pub fn mermaid(part: &Part, g: &PartGeometry, mg: &MeasurementGraph, points: bool) -> String {
    let esc = |s: &str| {
        s.replace('"', "#quot;")
            .replace('<', "#lt;")
            .replace('>', "#gt;")
    };
    let mut o = String::from("flowchart TD\n");
    for (n, node) in mg.nodes().filter(|(n, _)| shown(mg, *n, points)) {
        let text: Vec<String> = label(part, g, mg, n).iter().map(|l| esc(l)).collect();
        let text = text.join("<br/>");
        let _ = match node {
            Node::Part => writeln!(o, "  n{}{{{{\"{text}\"}}}}", n.index()),
            Node::Tolerance(_) => writeln!(o, "  n{}[/\"{text}\"/]", n.index()),
            Node::Point(_) => writeln!(o, "  n{}((\"{text}\"))", n.index()),
            _ => writeln!(o, "  n{}[\"{text}\"]", n.index()),
        };
    }
    for e in mg.graph.edge_indices() {
        let (a, b) = mg.graph.edge_endpoints(e).expect("edge");
        if !shown(mg, b, points) {
            continue;
        }
        let arrow = if mg.graph[e] == Edge::Datum {
            "-. datum .->"
        } else {
            "-->"
        };
        let _ = writeln!(o, "  n{} {arrow} n{}", a.index(), b.index());
    }
    o
}

/// The graph as JSON: tolerances, features and faces with their children by name, every
/// fpoint with its position and normal (rounded to 1e-6), and the counts.
pub fn json(part: &Part, g: &PartGeometry, mg: &MeasurementGraph) -> serde_json::Value {
    use serde_json::json;
    let name_of = |n: NodeIndex| match &mg.graph[n] {
        Node::Tolerance(k) => part.tolerances[*k].name.clone(),
        Node::Feature { feature, .. } => part.features[feature.0].name.clone(),
        Node::Face { face, .. } => g.faces[face.0].name.clone(),
        _ => String::new(),
    };
    let v3 = |v: &nalgebra::Vector3<f64>| json!([round6(v.x), round6(v.y), round6(v.z)]);
    let (mut tolerances, mut features, mut faces) = (vec![], vec![], vec![]);
    for (n, node) in mg.nodes() {
        let kids = mg.children(n);
        let named = |edge: Edge| {
            kids.iter()
                .filter(|(_, e)| *e == edge)
                .map(|(c, _)| name_of(*c))
                .collect::<Vec<_>>()
        };
        match node {
            Node::Tolerance(k) => {
                let (name, text) = tolerance_text(part, *k);
                tolerances.push(json!({ "name": name, "tolerance": text, "features": named(Edge::Target), "datum_features": named(Edge::Datum) }));
            }
            Node::Feature { feature, datums } => {
                let toleranced = mg
                    .graph
                    .neighbors_directed(n, petgraph::Direction::Incoming)
                    .any(|p| p != mg.root);
                let mut f = json!({ "name": part.features[feature.0].name, "datums": datums, "toleranced": toleranced, "faces": named(Edge::Face) });
                if let Some(s) = mg.sensors.iter().find(|s| s.feature == *feature) {
                    f["sensor"] = json!(s.sensor.word());
                    f["sensor_why"] = json!(s.why);
                }
                features.push(f);
            }
            Node::Face { face, on_table } => {
                let f = &g.faces[face.0];
                let points: Vec<serde_json::Value> = kids
                    .iter()
                    .filter_map(|(c, _)| match mg.graph[*c] {
                        Node::Point(i) => Some(json!({ "p": v3(&mg.fpoints[i].position.coords), "n": v3(&mg.fpoints[i].normal) })),
                        _ => None,
                    })
                    .collect();
                faces.push(json!({ "id": face.0, "name": f.name, "type": f.surface.kind().keyword(), "on_table": on_table, "points": points }));
            }
            _ => {}
        }
    }
    let [t, fe, fa, p] = mg.counts();
    json!({
        "part": part.name,
        "plan": mg.plan,
        "sampling": mg.sampling,
        "margin": round6(mg.margin),
        "counts": { "tolerances": t, "features": fe, "faces": fa, "fpoints": p },
        "tolerances": tolerances,
        "features": features,
        "faces": faces,
    })
}
