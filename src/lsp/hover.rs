//! What hovering a name shows: the item as the model summary prints it, and for the names
//! inside a part what the geometry, the measurement graph and the last plan know of them.

use super::symbols::{contains, decls, target, within, Decl, DeclKind};
use super::Analysis;
use crate::model::{ItemRef, Model};
use crate::resolve::{accepts, Datums};
use crate::source::{FileId, Span};
use crate::syntax::ast;
use serde_json::Value;
use std::fmt::Write;

/// The hover of the name at `offset` of `file`: the span hovered and markdown.
pub fn hover(a: &Analysis, file: FileId, offset: usize) -> Option<(Span, String)> {
    let checked = &a.front;
    let Some((at, decl)) = target(checked, file, offset) else {
        return face_ref(a, file, offset);
    };
    let all = decls(checked);
    // A name bound to no declaration of ours (`stock` in `stock.top`): the reference.
    let Some(mut d) = all.iter().find(|d| d.name.span == decl) else {
        return face_ref(a, file, offset);
    };
    let model = &checked.model;
    let mut o = String::new();
    if d.kind == DeclKind::Label {
        // A rack label stands for the item its entry names.
        let names = &checked.model.index.names;
        let named = names
            .iter()
            .find(|u| u.used != decl && within(u.used, d.full))?;
        let _ = writeln!(o, "`{}` in the rack:\n", d.name.name);
        d = all.iter().find(|x| x.name.span == named.decl)?;
    }
    match d.kind {
        DeclKind::Block(_) | DeclKind::Part | DeclKind::Hierarchy | DeclKind::Plan => {
            let item = item_of(model, d)?;
            let _ = write!(o, "```\n{}", model.describe(item));
            if let ItemRef::Probe(i) = item {
                let p = &model.probes[i];
                o.push_str(&model.describe(ItemRef::Body(p.body.0)));
                for e in &p.extensions {
                    o.push_str(&model.describe(ItemRef::Extension(e.0)));
                }
                o.push_str(&model.describe(ItemRef::Stylus(p.stylus.0)));
            }
            o.push_str("```\n");
        }
        _ => local(a, d, &mut o)?,
    }
    Some((at, o))
}

/// The model item a top-level declaration made.
fn item_of(model: &Model, d: &Decl) -> Option<ItemRef> {
    let name = d.name.name.as_str();
    let file = d.name.span.file;
    macro_rules! find {
        ($v:expr, $make:expr) => {
            $v.iter()
                .position(|x| x.name == name && x.span.file == file)
                .map($make)
        };
    }
    match d.kind {
        DeclKind::Block(k) => match k {
            ast::BlockKind::Cmm => find!(model.cmms, ItemRef::Cmm),
            ast::BlockKind::Head => find!(model.heads, ItemRef::Head),
            ast::BlockKind::Probe => find!(model.probes, ItemRef::Probe),
            ast::BlockKind::Stylus => find!(model.styli, ItemRef::Stylus),
            ast::BlockKind::Body => find!(model.bodies, ItemRef::Body),
            ast::BlockKind::Extension => find!(model.extensions, ItemRef::Extension),
            ast::BlockKind::Sampling => find!(model.samplings, ItemRef::Sampling),
            ast::BlockKind::Fixture => find!(model.fixtures, ItemRef::Fixture),
            ast::BlockKind::Scanner => find!(model.scanners, ItemRef::Scanner),
        },
        DeclKind::Part => find!(model.parts, ItemRef::Part),
        DeclKind::Hierarchy => find!(model.hierarchies, ItemRef::Hierarchy),
        DeclKind::Plan => find!(model.plans, ItemRef::Plan),
        _ => None,
    }
}

/// The hover of a name declared inside a part.
fn local(a: &Analysis, d: &Decl, o: &mut String) -> Option<()> {
    let model = &a.front.model;
    let ast_part = d.part?;
    let k = model
        .parts
        .iter()
        .position(|p| p.name == ast_part.name.name && p.span.file == ast_part.name.span.file)?;
    let part = &model.parts[k];
    let name = d.name.name.as_str();
    match d.kind {
        DeclKind::Face | DeclKind::Feature => {
            let f = part.features.iter().position(|f| f.name == name)?;
            let _ = writeln!(o, "```\n{}\n```", part.features[f].text(part));
            feature_faces(a, k, f, o);
        }
        DeclKind::Datum => {
            let datum = part.datums.iter().find(|x| x.name == name)?;
            let f = datum.feature.0;
            let _ = writeln!(o, "```\ndatum {name} on {}\n```", part.features[f].name);
            feature_faces(a, k, f, o);
        }
        DeclKind::Tolerance => {
            let t = part.tolerances.iter().find(|x| x.name == name)?;
            let _ = writeln!(o, "```\n{}\n```", t.text(part));
            if let Some(rule) = accepts(t.kind) {
                let datums = match rule.datums {
                    Datums::Forbidden => "takes no datums",
                    Datums::Optional => "datums optional",
                    Datums::Required => "datums required",
                };
                let material = if rule.material {
                    "MMC/LMC allowed on the feature"
                } else {
                    "no material modifier"
                };
                let dia = if rule.dia { ", Ø zone allowed" } else { "" };
                let _ = writeln!(o, "\n`{}`: {datums}, {material}{dia}.", rule.keyword);
            }
            tolerance_state(a, &part.name, name, o);
        }
        DeclKind::Frame => {
            let fr = part.frames.iter().find(|x| x.name == name)?;
            let letters: Vec<&str> = fr
                .refs
                .iter()
                .map(|r| part.datums[r.datum.0].name.as_str())
                .collect();
            let _ = writeln!(o, "```\nframe {name} = [{}]\n```", letters.join(", "));
        }
        DeclKind::Op => {
            let op = part.ops.iter().find(|x| x.name == name)?;
            let _ = writeln!(
                o,
                "```\n{} {}: {}\n```",
                op.kind.word(),
                op.name,
                op_faces(a, k, name)
            );
        }
        _ => return None,
    }
    Some(())
}

/// The faces an operation made, by name, once the geometry is built.
fn op_faces(a: &Analysis, part: usize, op: &str) -> String {
    let Some(data) = a.deep.as_ref().and_then(|d| d.parts.get(part)?.as_ref()) else {
        return "faces known once the geometry is built".into();
    };
    let prefix = format!("{op}.");
    let names: Vec<&str> = data
        .geometry
        .faces
        .iter()
        .filter(|f| f.name.starts_with(&prefix) && f.area > 0.0)
        .map(|f| f.name.as_str())
        .collect();
    format!("faces {}", names.join(", "))
}

/// What a hover says while the geometry of the current text is on its way.
const BEING_BUILT: &str = "_The geometry is being built._";

/// A part's geometry in the analysis's geometry stage, found by the part's name (the
/// stage may be of an earlier version of the text, whose parts sit elsewhere).
struct Geo<'a> {
    deep: &'a super::Deep,
    /// The part's index in the geometry stage's model.
    k: usize,
    data: &'a crate::PartData,
}

/// The geometry of part `part` of the current text, or the sentence that says why there
/// is none yet. "See the diagnostics" only where there are some: a stage of an earlier
/// version is still being replaced.
fn geometry_of(a: &Analysis, part: usize) -> Result<Geo<'_>, &'static str> {
    let deep = a.deep.as_ref().ok_or(BEING_BUILT)?;
    let name = &a.front.model.parts[part].name;
    let found = deep
        .checked
        .model
        .parts
        .iter()
        .position(|p| &p.name == name);
    if let Some((k, Some(data))) = found.map(|k| (k, deep.parts.get(k).and_then(Option::as_ref))) {
        return Ok(Geo { deep, k, data });
    }
    if deep.version != a.version {
        Err(BEING_BUILT)
    } else if deep.checked.has_errors() {
        Err("_No geometry while the spec has errors: see the diagnostics._")
    } else {
        Err("_No geometry: the part is not declared in this file and no plan here names it._")
    }
}

/// A feature's faces: surface, area, points sampled, and how the last plan reached them.
fn feature_faces(a: &Analysis, part: usize, feature: usize, o: &mut String) {
    let geo = match geometry_of(a, part) {
        Ok(geo) => geo,
        Err(why) => {
            let _ = writeln!(o, "\n{why}");
            return;
        }
    };
    let name = &a.front.model.parts[part].features[feature].name;
    let model_part = &geo.deep.checked.model.parts[geo.k];
    let Some(feature) = model_part.features.iter().position(|f| &f.name == name) else {
        let _ = writeln!(o, "\n{BEING_BUILT}");
        return;
    };
    let _ = writeln!(o);
    if geo.deep.version != a.version {
        let _ = writeln!(
            o,
            "_As of an earlier version of the text; the geometry of this one is being built._\n"
        );
    }
    // On a machine with a scanner: the sensor chosen and why.
    let sensors = geo
        .deep
        .graphs
        .iter()
        .filter(|g| g.part == geo.k)
        .flat_map(|g| g.graph.sensors.iter().map(move |s| (g, s)))
        .filter(|(_, s)| s.feature.0 == feature);
    for (g, s) in sensors {
        let plan = g.graph.plan.as_deref().unwrap_or("");
        let word = s.sensor.word();
        let _ = writeln!(o, "sensor in plan `{plan}`: **{word}** ({})\n", s.why);
    }
    for id in geo.data.feature_faces.get(feature).into_iter().flatten() {
        face_line(a, &geo, *id, o);
    }
}

/// One face of the geometry: its surface, area and points, and how the last plan
/// reached it.
fn face_line(a: &Analysis, geo: &Geo, id: crate::geometry::FaceId, o: &mut String) {
    let f = &geo.data.geometry.faces[id.0];
    let graph = geo.deep.graphs.iter().find(|g| g.part == geo.k);
    let points = graph.map_or(0, |g| {
        g.graph.fpoints.iter().filter(|p| p.face == id).count()
    });
    let surface = crate::geometry::describe(&f.surface);
    let _ = writeln!(
        o,
        "- **{}**: {} {}, {} mm², {points} points",
        f.name,
        f.surface.kind().keyword(),
        surface,
        crate::model::fmt_num((f.area * 10.0).round() / 10.0)
    );
    let part_name = &geo.deep.checked.model.parts[geo.k].name;
    if let Some(state) = face_state(a, part_name, &f.name) {
        let _ = writeln!(o, "  - {state}");
    }
}

/// The hover of a face reference (`stock.top`, `slot.walls`, `group "face_90"`) at
/// `offset`: the faces of the geometry it names.
fn face_ref(a: &Analysis, file: FileId, offset: usize) -> Option<(Span, String)> {
    let model = &a.front.model;
    let (k, r) = model.parts.iter().enumerate().find_map(|(k, p)| {
        let refs = p.features.iter().flat_map(|f| &f.faces);
        refs.filter(|r| contains(r.span(), file, offset))
            .min_by_key(|r| r.span().end - r.span().start)
            .map(|r| (k, r))
    })?;
    let part = &model.parts[k];
    let mut o = format!("```\n{}\n```\n", r.text(part));
    // The reference's ids (an operation's index) are the current text's: only a
    // geometry stage of this version resolves it.
    let geo = geometry_of(a, k).and_then(|g| match g.deep.version == a.version {
        true => Ok(g),
        false => Err(BEING_BUILT),
    });
    match geo {
        Ok(geo) => {
            let ids = crate::geometry::resolve_faces(
                &geo.data.geometry,
                r,
                &mut crate::diag::Diagnostics::new(),
            );
            if ids.is_empty() {
                let _ = writeln!(o, "\nNames no face of the geometry: see the diagnostics.");
            }
            for id in ids {
                face_line(a, &geo, id, &mut o);
            }
        }
        Err(why) => {
            let _ = writeln!(o, "\n{why}");
        }
    }
    Some((r.span(), o))
}

/// The plans of the last run that plan `part`.
fn plans_of<'a>(a: &'a Analysis, part: &str) -> Vec<&'a Value> {
    a.plan.as_ref().map_or(Vec::new(), |p| {
        p.plans
            .iter()
            .filter(|v| v["part"].as_str() == Some(part))
            .collect()
    })
}

/// How the last plan reached a face: per setup, the probe and orientation.
fn face_state(a: &Analysis, part: &str, face: &str) -> Option<String> {
    let plans = plans_of(a, part);
    if plans.is_empty() {
        return None;
    }
    let mut seen = Vec::new();
    for plan in &plans {
        for (s, setup) in plan["setups"].as_array().into_iter().flatten().enumerate() {
            for probe in setup["probes"].as_array().into_iter().flatten() {
                for orient in probe["orientations"].as_array().into_iter().flatten() {
                    let points: usize = orient["inspect"]
                        .as_array()
                        .into_iter()
                        .flatten()
                        .flat_map(|i| i["faces"].as_array().into_iter().flatten())
                        .filter(|f| f["face"].as_str() == Some(face))
                        .map(|f| f["points"].as_array().map_or(0, Vec::len))
                        .sum();
                    if points > 0 {
                        let at = if plan["indexable"].as_bool() == Some(true) {
                            format!(" at A {} B {}", num(&orient["a"]), num(&orient["b"]))
                        } else {
                            String::new()
                        };
                        seen.push(format!(
                            "setup {} ({}): probe {}{at}, {points} points",
                            s + 1,
                            setup["held_by"].as_str().unwrap_or("?"),
                            probe["probe"].as_str().unwrap_or("?"),
                        ));
                    }
                }
            }
        }
    }
    Some(if seen.is_empty() {
        "not reached in the last plan".into()
    } else {
        format!("last plan: {}", seen.join("; "))
    })
}

/// A tolerance's state in the last plan: the setups that record it.
fn tolerance_state(a: &Analysis, part: &str, name: &str, o: &mut String) {
    let plans = plans_of(a, part);
    if plans.is_empty() {
        let _ = writeln!(o, "\n_Not planned yet: save to plan._");
        return;
    }
    let mut setups = Vec::new();
    for plan in &plans {
        for (s, setup) in plan["setups"].as_array().into_iter().flatten().enumerate() {
            let records = setup["probes"]
                .as_array()
                .into_iter()
                .flatten()
                .flat_map(|p| p["orientations"].as_array().into_iter().flatten())
                .flat_map(|or| or["inspect"].as_array().into_iter().flatten())
                .flat_map(|i| i["record"].as_array().into_iter().flatten())
                .any(|r| r.as_str() == Some(name));
            if records && !setups.contains(&(s + 1)) {
                setups.push(s + 1);
            }
        }
    }
    let _ = if setups.is_empty() {
        writeln!(o, "\nLast plan: **not measured**.")
    } else {
        let list: Vec<String> = setups.iter().map(usize::to_string).collect();
        writeln!(o, "\nLast plan: measured in setup {}.", list.join(", "))
    };
}

fn num(v: &Value) -> String {
    v.as_f64().map_or("?".into(), crate::model::fmt_num)
}
