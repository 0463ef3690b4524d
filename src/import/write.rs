//! The spec `inspc import` writes: features named once per set of faces, datums (common
//! datums made on demand), tolerances and sizes checked against what the language
//! accepts, each left out with a comment saying why, and the text around them.

use super::errors::LeftOut;
use super::text::{source, DatumLetters, Place};
use super::values::{written, Sign};
use super::{ImportOptions, Imported};
use crate::geometry::step::{pmi, CadPart};
use crate::geometry::Surface;
use crate::model::{fmt_num, Material, TolKind};
use crate::resolve::{accepts, Accepts, Datums};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

/// A feature of the spec: a set of faces, named once.
struct Features {
    by_faces: BTreeMap<Vec<usize>, String>,
    order: Vec<Vec<usize>>,
    used_names: BTreeSet<String>,
}

impl Features {
    fn name(&mut self, faces: &[usize], preferred: Option<String>) -> String {
        if let Some(n) = self.by_faces.get(faces) {
            return n.clone();
        }
        let base = preferred.unwrap_or_else(|| match faces {
            [one] => format!("f{}", one + 1),
            [first, .., last] => format!("f{}_{}", first + 1, last + 1),
            [] => "f".to_string(),
        });
        let name = unique(&mut self.used_names, &source(&base, Place::Identifier));
        self.by_faces.insert(faces.to_vec(), name.clone());
        self.order.push(faces.to_vec());
        name
    }
}

fn unique(used: &mut BTreeSet<String>, base: &str) -> String {
    let mut name = base.to_string();
    let mut k = 2;
    while used.contains(&name) {
        name = format!("{base}_{k}");
        k += 1;
    }
    used.insert(name.clone());
    name
}

/// The letters a frame may name: datums with faces, and common datums (A-B) made on
/// demand as a two-letter datum on the union of their features.
struct Frames {
    datum_feature: BTreeMap<String, Vec<usize>>,
    common: BTreeMap<String, (Vec<String>, Vec<usize>)>,
}

impl Frames {
    fn letter(&mut self, letters: &[String], feats: &mut Features) -> Result<String, String> {
        for l in letters {
            if !self.datum_feature.contains_key(l) {
                return Err(format!("datum {l} has no faces"));
            }
        }
        if letters.len() == 1 {
            return Ok(letters[0].clone());
        }
        // E-F is written EF (two letters hold it); E-F-G as E_F_G, a common datum's
        // name in the language.
        let joined: String = if letters.len() == 2 && letters.iter().all(|l| l.len() == 1) {
            letters.concat()
        } else {
            letters.join("_")
        };
        if self.datum_feature.contains_key(&joined) {
            return Err(format!(
                "common datum {} clashes with datum {joined}",
                letters.join("-")
            ));
        }
        let mut faces: Vec<usize> = letters
            .iter()
            .flat_map(|l| self.datum_feature[l].clone())
            .collect();
        faces.sort_unstable();
        faces.dedup();
        if !self.common.contains_key(&joined) {
            feats.name(&faces, Some(format!("datum_{}", joined.to_lowercase())));
            self.common
                .insert(joined.clone(), (letters.to_vec(), faces));
        }
        Ok(joined)
    }
}

/// Short keyword prefixes for tolerance names.
fn prefix(kind: TolKind) -> &'static str {
    match kind {
        TolKind::Flatness => "flat",
        TolKind::Straightness => "straight",
        TolKind::Circularity => "round",
        TolKind::Cylindricity => "cyl",
        TolKind::ProfileLine => "lprof",
        TolKind::ProfileSurface => "prof",
        TolKind::Perpendicularity => "perp",
        TolKind::Parallelism => "par",
        TolKind::Angularity => "ang",
        TolKind::Position => "pos",
        TolKind::Concentricity => "conc",
        TolKind::Coaxiality => "coax",
        TolKind::Symmetry => "sym",
        TolKind::CircularRunout => "runout",
        TolKind::TotalRunout => "trunout",
        _ => "tol",
    }
}

fn mm(x: f64) -> String {
    format!("{} mm", fmt_num(x))
}

fn faces_text(faces: &[usize]) -> String {
    let v: Vec<String> = faces.iter().map(|f| (f + 1).to_string()).collect();
    format!(
        "face{} {}",
        if faces.len() == 1 { "" } else { "s" },
        v.join(", ")
    )
}

/// One line of a spec that could not be written, as a comment.
fn left_out(out: &mut Vec<String>, what: String, why: &str) {
    out.push(comment(&format!("not written: {what}: {why}")));
}

/// A comment line of the part's body, its text from the file.
fn comment(text: &str) -> String {
    format!("    // {}", source(text, Place::Comment))
}

/// Limits as the language writes them: `± 0.15 mm`, `+0 mm -0.2 mm`.
fn limits(nominal: f64, upper: f64, lower: f64, unit: &str) -> String {
    let q = |x: f64| format!("{} {unit}", fmt_num(x));
    if (upper + lower).abs() < 1e-12 && upper > 0.0 {
        return format!("{} ± {}", q(nominal), q(upper));
    }
    // A zero deviation takes the sign of its side: `+0` above, `-0` below.
    let signed = |x: f64, minus: bool| {
        if minus {
            format!("-{}", q(-x))
        } else {
            format!("+{}", q(x))
        }
    };
    format!(
        "{} {} {}",
        q(nominal),
        signed(upper, upper < 0.0),
        signed(lower, lower <= 0.0)
    )
}

/// The PMI without the faces of sheet bodies: an open surface the file carries beside
/// its solid (construction geometry) is no material a probe can touch, and the part's
/// mesh leaves it out. What loses faces says so in the notes.
fn solid_pmi(part: &CadPart) -> pmi::Pmi {
    let mut p = part.pmi.clone();
    let solid = part.solid_faces();
    let mut notes = Vec::new();
    let mut keep = |faces: &mut Vec<usize>, what: String| {
        let before = faces.len();
        faces.retain(|f| *f < solid);
        if faces.len() < before {
            notes.push(format!(
                "{what}: its sheet (construction) face{} left out",
                if before - faces.len() == 1 {
                    " is"
                } else {
                    "s are"
                }
            ));
        }
    };
    for d in &mut p.datums {
        keep(&mut d.faces, format!("datum {}", d.letter));
    }
    for t in &mut p.tolerances {
        keep(&mut t.faces, format!("`{}`", t.name));
    }
    for d in &mut p.dimensions {
        keep(&mut d.faces, format!("dimension #{}", d.id));
        keep(&mut d.to_faces, format!("dimension #{}", d.id));
    }
    p.notes.extend(notes);
    p
}

/// The PMI without the faces no ball of the rack can touch ([`super::touch`]) among
/// those its tolerances and sizes apply to (a general tolerance, on every face, and the
/// datums keep theirs), each loss a note; and, per tolerance or dimension left with no
/// face, why it is not written.
fn touchable_pmi(part: &CadPart, mut p: pmi::Pmi) -> (pmi::Pmi, BTreeMap<u64, String>) {
    let solid = part.solid_faces();
    let asked: BTreeSet<usize> = p
        .tolerances
        .iter()
        .filter(|t| !general(t, solid))
        .flat_map(|t| t.faces.iter().copied())
        .chain(
            p.dimensions
                .iter()
                .flat_map(|d| d.faces.iter().chain(&d.to_faces).copied()),
        )
        .collect();
    let r = super::touch::SMALLEST_BALL;
    let bad = super::touch::untouchable(&part.mesh, &asked, r);
    let why = |faces: &[usize]| {
        format!(
            "{} curve{} tighter than the rack's smallest ball (Ø{} mm), which touches the faces beside, not {}: not a CMM's to measure (a radius gauge or an optical comparator is)",
            faces_text(faces),
            if faces.len() == 1 { "s" } else { "" },
            fmt_num(2.0 * r),
            if faces.len() == 1 { "it" } else { "them" }
        )
    };
    let mut gone = BTreeMap::new();
    let mut notes = Vec::new();
    let mut drop = |faces: &mut Vec<usize>, id: u64, what: String| {
        let lost: Vec<usize> = faces.iter().copied().filter(|f| bad.contains(f)).collect();
        if lost.is_empty() {
            return;
        }
        faces.retain(|f| !bad.contains(f));
        if faces.is_empty() {
            gone.insert(id, why(&lost));
        } else {
            notes.push(format!("{what}: left out {}", why(&lost)));
        }
    };
    for t in p.tolerances.iter_mut().filter(|t| !general(t, solid)) {
        drop(&mut t.faces, t.id, format!("`{}`", t.name));
    }
    let mut sizes_gone = Vec::new();
    for d in &mut p.dimensions {
        let before = d.faces.clone();
        drop(&mut d.faces, d.id, format!("dimension #{}", d.id));
        drop(&mut d.to_faces, d.id, format!("dimension #{}", d.id));
        // A size left on free-form faces alone has nothing to read it on.
        let freeform = |f: &usize| matches!(part.mesh.exact.get(*f), Some(Surface::Freeform));
        if matches!(d.kind, pmi::DimKind::Size(_))
            && d.faces.len() < before.len()
            && !d.faces.is_empty()
            && d.faces.iter().all(freeform)
        {
            let lost: Vec<usize> = before.iter().copied().filter(|f| bad.contains(f)).collect();
            sizes_gone.push((
                d.id,
                format!("{}; the rest are free-form, which have no size", why(&lost)),
            ));
        }
    }
    gone.extend(sizes_gone);
    p.notes.extend(notes);
    (p, gone)
}

/// The PMI with every datum letter as the spec writes it ([`DatumLetters`]): the
/// datums' and those of every frame, a note for each one renamed.
fn with_datum_letters(mut p: pmi::Pmi) -> pmi::Pmi {
    let file_letters: Vec<String> = p
        .datums
        .iter()
        .map(|d| d.letter.clone())
        .chain(
            p.tolerances
                .iter()
                .flat_map(|t| t.datums.iter().flat_map(|d| d.letters.clone())),
        )
        .collect();
    let letters = DatumLetters::new(file_letters.iter().map(String::as_str));
    for d in &mut p.datums {
        d.letter = letters.of(&d.letter);
    }
    for t in &mut p.tolerances {
        for d in &mut t.datums {
            for l in &mut d.letters {
                *l = letters.of(l);
            }
        }
    }
    let renamed: Vec<String> = letters
        .renamed()
        .map(|(file, spec)| {
            format!("datum `{file}` is written as datum {spec}: datum letters are capitals other than I, O and Q (ASME Y14.5)")
        })
        .collect();
    p.notes.extend(renamed);
    p
}

pub(super) fn write_spec(part: &CadPart, opts: &ImportOptions) -> Imported {
    let (solid, gone) = touchable_pmi(part, with_datum_letters(solid_pmi(part)));
    let p = &solid;
    let mut warnings = Vec::new();
    let mut feats = Features {
        by_faces: BTreeMap::new(),
        order: Vec::new(),
        used_names: BTreeSet::new(),
    };
    let datums = datum_lines(p, &mut feats);
    let mut frames = Frames {
        datum_feature: datums.features,
        common: BTreeMap::new(),
    };
    let mut used_tol_names = BTreeSet::new();
    let (tol_lines, written_tols) = tolerance_lines(
        p,
        (&part.mesh.exact, part.solid_faces()),
        &gone,
        &mut feats,
        &mut frames,
        &mut used_tol_names,
        &mut warnings,
    );
    let (mut dim_lines, written_dims) = dimension_lines(
        p,
        &part.mesh.exact,
        &gone,
        &mut feats,
        &mut used_tol_names,
        &mut warnings,
    );
    let mut datum_lines = datums.lines;
    common_datum_lines(&frames, &mut feats, &mut datum_lines);
    let mut notes = p.notes.clone();
    let no_pmi = p.datums.is_empty() && p.tolerances.is_empty() && p.dimensions.is_empty();
    let mut defaults = 0;
    let mut header = PMI_HEADER;
    if no_pmi {
        if let Some(d) = super::recognise::default_inspection(part) {
            header = DEFAULT_HEADER;
            let (datums, tols) = default_lines(&d, &mut feats, &mut used_tol_names);
            defaults = tols.len();
            datum_lines = datums;
            dim_lines = tols;
            notes.extend(d.notes);
        }
    }

    let text = render(
        part,
        (header, &notes),
        opts,
        &feats,
        &datum_lines,
        &datums.notes,
        &tol_lines,
        &dim_lines,
    );
    Imported {
        // In the layout `inspc fmt` gives, so a formatted repository stays formatted.
        text: crate::fmt::format(&text),
        faces: part.solid_faces(),
        datums: (datums.letters, frames.datum_feature.len()),
        tolerances: (p.tolerances.len(), written_tols),
        dimensions: (p.dimensions.len(), written_dims),
        warnings,
        defaults,
    }
}

/// The first line of the spec's account of its tolerances, by where they come from.
const PMI_HEADER: &str = "The datums, tolerances and sizes are the file's semantic PMI; what the language cannot say is a comment.";
const DEFAULT_HEADER: &str = "The file has no PMI: the datums and tolerances below are a DEFAULT INSPECTION of the features inspc recognised, with general tolerances (sizes and distances ISO 2768-1 m, flatness ISO 2768-2 K, positions Ø2t) in place of the drawing's. Replace them with the drawing's before the results count.";

/// The default inspection as spec lines: its datums, and its tolerances.
fn default_lines(
    d: &super::recognise::DefaultInspection,
    feats: &mut Features,
    used: &mut BTreeSet<String>,
) -> (Vec<String>, Vec<String>) {
    let names: Vec<String> = d
        .features
        .iter()
        .map(|(faces, name)| feats.name(faces, Some(name.clone())))
        .collect();
    let datums = d
        .datums
        .iter()
        .map(|(letter, f)| format!("    datum {letter} = {}", names[*f]))
        .collect();
    let tols = d
        .tolerances
        .iter()
        .map(|t| {
            let targets: Vec<&str> = t.features.iter().map(|f| names[*f].as_str()).collect();
            let prefix = match t.keyword {
                "flatness" => "flat",
                "position" => "pos",
                "distance" => "dist",
                _ => "size",
            };
            let name = unique(used, &format!("{prefix}_{}", targets[0]));
            let mut args: Vec<String> = targets.iter().map(|s| s.to_string()).collect();
            args.push(t.value.clone());
            args.extend(t.datums.iter().map(char::to_string));
            format!("    tolerance {name} = {}({})", t.keyword, args.join(", "))
        })
        .collect();
    (datums, tols)
}

/// The datums of the PMI as the spec writes them.
struct DatumLines {
    /// `datum A = datum_a`, with a comment before a datum set up by targets.
    lines: Vec<String>,
    /// Comments for the datums left out.
    notes: Vec<String>,
    /// The faces of each datum written, by letter.
    features: BTreeMap<String, Vec<usize>>,
    /// The distinct letters the PMI has.
    letters: usize,
}

/// Datums: a letter per datum with faces, each named as a feature `datum_<letter>`.
fn datum_lines(p: &pmi::Pmi, feats: &mut Features) -> DatumLines {
    let mut lines = Vec::new();
    let mut notes = Vec::new();
    let mut features: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let mut seen_letters = BTreeSet::new();
    for d in &p.datums {
        if !seen_letters.insert(d.letter.clone()) {
            continue;
        }
        if d.faces.is_empty() {
            left_out(
                &mut notes,
                format!("datum {}", d.letter),
                "the file links it to no face",
            );
            continue;
        }
        let name = feats.name(&d.faces, Some(format!("datum_{}", d.letter.to_lowercase())));
        features.insert(d.letter.clone(), d.faces.clone());
        if d.located {
            let targets: Vec<String> = d
                .targets
                .iter()
                .map(|t| format!("{} {}", t.kind, t.label))
                .collect();
            lines.push(comment(&format!(
                "Datum {} is set up by targets ({}) that the file places on no face; they lie on {}. inspc has no datum targets: the datum is those whole faces. Check it against the drawing.",
                d.letter,
                targets.join(", "),
                faces_text(&d.faces)
            )));
        }
        lines.push(format!("    datum {} = {name}", d.letter));
    }
    DatumLines {
        lines,
        notes,
        features,
        letters: seen_letters.len(),
    }
}

/// Common datums (A-B) the frames made: their feature and letter, after the plain ones.
fn common_datum_lines(frames: &Frames, feats: &mut Features, lines: &mut Vec<String>) {
    for (letter, (parts, faces)) in &frames.common {
        lines.push(format!(
            "    // Common datum {}: one datum on both features.",
            parts.join("-")
        ));
        let f = feats.name(faces, None);
        lines.push(format!("    datum {letter} = {f}"));
    }
}

/// The geometric tolerances, each written or left out with why, and how many were
/// written; `solid` is how many faces the part has.
///
/// **Decision: a general tolerance stays a comment.** A tolerance the file places on
/// the whole part (STEP's `product_definition_shape`, every face) is the drawing's
/// "unless otherwise specified" note: a profile all over (ASME Y14.5-2018 § 11.3.1.4)
/// or a general geometrical specification (ISO 22081), applying to every feature not
/// toleranced on its own. Workshops do not inspect general tolerances feature by
/// feature (ISO 2768-1:1989, annex A: spot checks suffice), and a CMM cannot: NIST FTC 07's
/// 0.06 in profile on its 304 faces, R0.43 blends among them, planned (with every face
/// a ball misses left out) into 28 setups and 7,316 touches. It is a comment naming its
/// value and frame, and a warning (`insp::import::general_tolerance`); a `profile_surface`
/// on the faces to check writes it back.
fn tolerance_lines(
    p: &pmi::Pmi,
    (exact, solid): (&[crate::geometry::Surface], usize),
    gone: &BTreeMap<u64, String>,
    feats: &mut Features,
    frames: &mut Frames,
    used_names: &mut BTreeSet<String>,
    warnings: &mut Vec<LeftOut>,
) -> (Vec<String>, usize) {
    let mut lines = Vec::new();
    let mut count = 0;
    for t in &p.tolerances {
        let label = format!("`{}` (#{})", t.name, t.id);
        if general(t, solid) {
            let what = general_words(t);
            warnings.push(LeftOut {
                item: source(&format!("tolerance {label}"), Place::Comment),
                value: what.clone(),
                general: true,
            });
            left_out(
                &mut lines,
                label,
                &format!("a general tolerance, {what}: the drawing's note for every feature not toleranced on its own, checked by sampling, not on every face"),
            );
            continue;
        }
        if let Some(why) = gone.get(&t.id) {
            left_out(&mut lines, label, why);
            continue;
        }
        // A zone per unit length or area is not the same zone over the whole feature
        // (that would reject parts the drawing accepts): written as `per_unit`, or
        // said where the language has no such zone.
        if let Some(per) = &t.per_unit {
            if let Err(why) = per_unit_arg(t, per) {
                left_out(
                    &mut lines,
                    label,
                    &format!("its zone applies {}, {why}; a zone over the whole feature would reject parts the drawing accepts", per.text),
                );
                continue;
            }
        }
        // A zone of 0 is legal at MMC or LMC (ASME Y14.5 zero tolerance at MMC).
        let zero_at_material = t.value_mm == 0.0
            && t.kind == Some(TolKind::Position)
            && matches!(t.material, Some(Material::Mmc | Material::Lmc));
        let sign = if zero_at_material {
            Sign::Any
        } else {
            Sign::Positive
        };
        if let Err(why) = written(t.value_mm, sign, "a zone", "mm") {
            warnings.push(LeftOut {
                item: source(&format!("tolerance {label}"), Place::Comment),
                value: why.clone(),
                general: false,
            });
            left_out(&mut lines, label, &why);
            continue;
        }
        let basic =
            (t.kind == Some(TolKind::Angularity)).then(|| super::angles::basic_angle(t, p, exact));
        match tolerance_line(t, basic, feats, frames, used_names) {
            Ok(line) => {
                lines.push(line);
                count += 1;
            }
            Err(why) => left_out(&mut lines, label, &why),
        }
    }
    (lines, count)
}

/// Whether a tolerance is a general one: on every one of the part's `solid` faces.
fn general(t: &pmi::GeoTolerance, solid: usize) -> bool {
    solid > 1 && t.faces.len() >= solid
}

/// A general tolerance in words: `a profile of 1.524 mm to A|B|C on all 304 faces`.
fn general_words(t: &pmi::GeoTolerance) -> String {
    let kind = t.kind.map_or("tolerance", |k| k.keyword());
    let frame: Vec<String> = t.datums.iter().map(|d| d.letters.join("-")).collect();
    let frame = if frame.is_empty() {
        String::new()
    } else {
        format!(" to {}", frame.join("|"))
    };
    format!(
        "{kind} {} mm{frame} on all {} faces",
        fmt_num(t.value_mm),
        t.faces.len()
    )
}

/// A zone per unit as the language writes it: `per_unit(0.02 mm, 25 mm)`, a square's or
/// rectangle's sides, a circle's `dia`; Err with why not (the language has per-unit
/// zones for straightness along a length and flatness over an area, ASME Y14.5-2018
/// § 5.4.1.4 and § 5.4.2.2).
fn per_unit_arg(t: &pmi::GeoTolerance, p: &pmi::PerUnitZone) -> Result<String, String> {
    use crate::model::UnitOf;
    if p.zone_mm.is_some_and(|z| z >= t.value_mm) {
        return Err("not tighter than the whole feature's zone, which it must be".into());
    }
    let zone = p.zone_mm.unwrap_or(t.value_mm);
    let zone = written(zone, Sign::Positive, "the zone per unit", "mm")?.0;
    let size = |x: f64| written(x, Sign::Positive, "the unit", "mm").map(|w| w.0);
    let unit = match (t.kind, p.unit) {
        (_, None) => return Err("whose size cannot be read".into()),
        (Some(TolKind::Straightness), Some(UnitOf::Length(l))) => size(l)?,
        (Some(TolKind::Flatness), Some(UnitOf::Rectangle(a, b))) if a == b => size(a)?,
        (Some(TolKind::Flatness), Some(UnitOf::Rectangle(a, b))) => {
            format!("{} mm, {}", size(a)?, size(b)?)
        }
        (Some(TolKind::Flatness), Some(UnitOf::Circle(d))) => format!("dia {}", size(d)?),
        _ => {
            return Err(
                "which the language has only for straightness per length and flatness per area"
                    .into(),
            )
        }
    };
    Ok(format!("per_unit({zone} mm, {unit} mm)"))
}

/// One tolerance as `tolerance name = kind(feature, value, datums)`, with a comment on
/// what it loses; Err with why the language cannot say it. Its frame's common datums
/// are made even when it is left out.
fn tolerance_line(
    t: &pmi::GeoTolerance,
    basic: Option<Result<f64, String>>,
    feats: &mut Features,
    frames: &mut Frames,
    used_names: &mut BTreeSet<String>,
) -> Result<String, String> {
    let kind = t.kind.ok_or("the file states no tolerance type")?;
    let rule = accepts(kind).ok_or("inspc has no such tolerance type")?;
    if t.faces.is_empty() {
        return Err("the file links it to no face".into());
    }
    let mut datums = Vec::new();
    let mut why_not = None;
    for d in &t.datums {
        match frames.letter(&d.letters, feats) {
            Ok(l) => {
                let letter = match d.material {
                    Some(Material::Mmc) => format!("{l}(MMC)"),
                    Some(Material::Lmc) => format!("{l}(LMC)"),
                    _ => l.clone(),
                };
                datums.push((l, letter));
            }
            Err(e) => why_not = Some(e),
        }
    }
    if let Some(Err(why)) = &basic {
        why_not = Some(why.clone());
    }
    if let Some(why) = why_not_written(t, rule, &datums, frames, why_not) {
        return Err(why);
    }
    let feature = feats.name(&t.faces, None);
    let (mut args, lost) = tolerance_args(t, rule, &feature, &datums);
    if let Some(Ok(angle)) = basic {
        // The basic angle the model gives (`angles.rs`).
        args.push(format!("basic {} deg", fmt_num(angle)));
    }
    let name = unique(used_names, &format!("{}_{feature}", prefix(kind)));
    let comment = if lost.is_empty() {
        String::new()
    } else {
        format!("  // {}", source(&lost.join("; "), Place::Comment))
    };
    Ok(format!(
        "    tolerance {name} = {}({}){comment}",
        rule.keyword,
        args.join(", ")
    ))
}

/// Why a tolerance with these datums (letter, as written) cannot be written, if it
/// cannot; `why_not` is what its frame said, and a later reason replaces an earlier one.
fn why_not_written(
    t: &pmi::GeoTolerance,
    rule: Accepts,
    datums: &[(String, String)],
    frames: &Frames,
    mut why_not: Option<String>,
) -> Option<String> {
    let letters: Vec<&String> = datums.iter().map(|(l, _)| l).collect();
    if letters.iter().collect::<BTreeSet<_>>().len() < letters.len() {
        why_not = Some("its frame names a datum twice".to_string());
    }
    match rule.datums {
        Datums::Forbidden if !datums.is_empty() => {
            why_not = Some(format!("{} takes no datums", rule.keyword))
        }
        Datums::Required if datums.is_empty() && why_not.is_none() => {
            why_not = Some(format!(
                "{} needs a datum and the frame has none",
                rule.keyword
            ))
        }
        _ => {}
    }
    // A datum feature is not toleranced relative to its own datum.
    for (l, _) in datums {
        let own = frames
            .datum_feature
            .get(l)
            .or_else(|| frames.common.get(l).map(|(_, f)| f));
        if own == Some(&t.faces) {
            why_not = Some(format!(
                "it refers to datum {l}, whose feature it tolerances"
            ));
        }
    }
    why_not
}

/// A tolerance's arguments (feature, zone, modifier, datums) and what the language
/// cannot carry of it.
fn tolerance_args(
    t: &pmi::GeoTolerance,
    rule: Accepts,
    feature: &str,
    datums: &[(String, String)],
) -> (Vec<String>, Vec<String>) {
    let mut args = vec![feature.to_string()];
    let mut lost = Vec::new();
    match t.per_unit.as_ref().map(|p| (p, per_unit_arg(t, p))) {
        Some((p, Ok(unit))) => {
            // The file's whole-feature value, where it gives one besides the unit's.
            if p.zone_mm.is_some() {
                args.push(mm(t.value_mm));
            }
            args.push(unit);
        }
        _ if t.diameter && rule.dia => args.push(format!("dia {}", mm(t.value_mm))),
        _ => {
            if t.diameter {
                lost.push("Ø zone".to_string());
            }
            args.push(mm(t.value_mm));
        }
    }
    match (t.material, rule.material) {
        (Some(Material::Mmc), true) => args.push("MMC".into()),
        (Some(Material::Lmc), true) => args.push("LMC".into()),
        (Some(m), false) => lost.push(format!("{m:?}").to_uppercase()),
        _ => {}
    }
    args.extend(datums.iter().map(|(_, s)| s.clone()));
    lost.extend(t.other.iter().cloned());
    for d in &t.datums {
        lost.extend(
            d.other
                .iter()
                .map(|o| format!("{o} on datum {}", d.letters.join("-"))),
        );
    }
    if let Some(u) = t.unequal_mm {
        let u = match written(u, Sign::Any, "U", "mm") {
            Ok((text, _)) => format!("U {text} mm"),
            Err(why) => why,
        };
        lost.push(format!(
            "unequally disposed ({u}): checked as equal bilateral"
        ));
    }
    if t.composite_of.is_some() {
        lost.push("lower segment of a composite frame: checked as its own tolerance".into());
    }
    (args, lost)
}

/// The dimensions, each written as a size or location tolerance or left out with why,
/// and how many were written.
fn dimension_lines(
    p: &pmi::Pmi,
    exact: &[Surface],
    gone: &BTreeMap<u64, String>,
    feats: &mut Features,
    used_names: &mut BTreeSet<String>,
    warnings: &mut Vec<LeftOut>,
) -> (Vec<String>, usize) {
    let mut lines = Vec::new();
    let mut count = 0;
    for d in &p.dimensions {
        let label = match &d.kind {
            pmi::DimKind::Size(n) => format!("size `{n}` (#{})", d.id),
            pmi::DimKind::Location(n) => format!("location `{n}` (#{})", d.id),
        };
        if let Some(why) = gone.get(&d.id) {
            left_out(&mut lines, label, why);
            continue;
        }
        if let Err(why) = dimension_values(d) {
            warnings.push(LeftOut {
                item: source(&label, Place::Comment),
                value: why.clone(),
                general: false,
            });
            left_out(&mut lines, label, &why);
            continue;
        }
        match dimension_line(d, exact, feats, used_names) {
            Ok(line) => {
                lines.push(line);
                count += 1;
            }
            Err(why) => left_out(&mut lines, label, &why),
        }
    }
    (lines, count)
}

/// Whether a dimension's values can be written as the limits `resolve` takes: each
/// finite and in range, a length's nominal above 0, the lower limit below the upper as
/// written. A value the file does not give is `dimension_line`'s to explain.
fn dimension_values(d: &pmi::Dimension) -> Result<(), String> {
    let (unit, nominal_sign) = if d.angular {
        ("deg", Sign::Any)
    } else {
        ("mm", Sign::Positive)
    };
    if let Some(n) = d.nominal {
        written(n, nominal_sign, "a nominal", unit)?;
    }
    let upper = d
        .upper
        .map(|u| written(u, Sign::Any, "an upper deviation", unit));
    let lower = d
        .lower
        .map(|l| written(l, Sign::Any, "a lower deviation", unit));
    if let (Some(upper), Some(lower)) = (upper.transpose()?, lower.transpose()?) {
        if lower.1 >= upper.1 {
            return Err(format!(
                "limits of `{} {unit}` to `{} {unit}`, the lower not below the upper",
                lower.0, upper.0
            ));
        }
    }
    Ok(())
}

/// One dimension as `tolerance name = diameter|radius|width|distance|angle(…, limits)`;
/// Err with why the language cannot say it. A width between planes that all face one
/// way, at two levels, is the distance between the levels ([`super::levels`]).
fn dimension_line(
    d: &pmi::Dimension,
    exact: &[Surface],
    feats: &mut Features,
    used_names: &mut BTreeSet<String>,
) -> Result<String, String> {
    let unit = if d.angular { "deg" } else { "mm" };
    // A fit (`Ø25 G6`) is its ISO 286 limits.
    let (mut upper, mut lower, mut note) = (d.upper, d.lower, String::new());
    if let (Some(fit), Some(nominal), None) = (&d.fit, d.nominal, d.upper) {
        let (u, l) = super::fits::deviations(fit, nominal)
            .map_err(|why| format!("its limits are the fit {fit}, but {why}"))?;
        (upper, lower) = (Some(u), Some(l));
        note = format!(" // fit {fit}: ISO 286 limits");
    }
    let (Some(nominal), Some(upper), Some(lower)) = (d.nominal, upper, lower) else {
        return Err(if d.nominal.is_none() {
            "the file gives it no value".to_string()
        } else {
            format!(
                "{} has no limits (a basic or reference dimension)",
                fmt_num(d.nominal.unwrap_or(0.0))
            )
        });
    };
    if d.faces.is_empty() {
        return Err("the file links it to no face".into());
    }
    let (keyword, targets) = match &d.kind {
        pmi::DimKind::Size(what) => {
            let keyword = match what.as_str() {
                "diameter" | "spherical diameter" => "diameter",
                "radius" | "spherical radius" => "radius",
                "thickness" | "width" | "length" => "width",
                _ => return Err("inspc has no such size".into()),
            };
            match super::levels::step_levels(exact, &d.faces).filter(|_| keyword == "width") {
                Some((upper, lower)) => {
                    note = format!(
                        "{note} // a {what} between faces that all face one way: the distance between their levels"
                    );
                    (
                        "distance",
                        vec![feats.name(&upper, None), feats.name(&lower, None)],
                    )
                }
                None => (keyword, vec![feats.name(&d.faces, None)]),
            }
        }
        pmi::DimKind::Location(_) => {
            if d.to_faces.is_empty() {
                return Err("the file links its second feature to no face".into());
            }
            let a = feats.name(&d.faces, None);
            let b = feats.name(&d.to_faces, None);
            (if d.angular { "angle" } else { "distance" }, vec![a, b])
        }
    };
    let name = unique(
        used_names,
        &format!(
            "{}_{}",
            match keyword {
                "diameter" | "radius" | "width" => "size",
                k => k,
            },
            targets[0]
        ),
    );
    Ok(format!(
        "    tolerance {name} = {keyword}({}, {}){note}",
        targets.join(", "),
        limits(nominal, upper, lower, unit)
    ))
}

/// The probe rack for a part, as (label, stdlib probe): a general Ø2 tip, a Ø1 tip
/// for narrow slots and small holes on the shortest stylus that reaches the deepest
/// of them with the body clear ([`super::reach`]: 10 mm, 20 mm, or 20 mm on a 30 mm
/// extension; 20 mm without small holes), a long Ø3 stylus for reach, and an extension
/// when the part is taller than that stylus reaches.
fn rack(part: &CadPart, size: [f64; 3]) -> Vec<(&'static str, &'static str)> {
    let extent = size.into_iter().fold(0.0, f64::max);
    let small = match super::reach::small_hole_reach(&part.mesh) {
        0.0 => "TP20_D1_L20",
        r if r <= THIN_REACH[0] => "TP20_D1_L10",
        r if r <= THIN_REACH[1] => "TP20_D1_L20",
        _ => "TP20_D1_L20_X30",
    };
    let mut rack = vec![("p1", "TP20_D2_L20"), ("p2", small), ("p3", "TP20_D3_L50")];
    if extent > 150.0 {
        rack.push(("p4", "TP20_D2_L20_X30"));
    }
    if deepest_floor(part) > DEEP_FLOOR {
        rack.push((if rack.len() == 3 { "p4" } else { "p5" }, "TP20_D3_L50_X50"));
    }
    rack
}

/// How deep (mm, hole bottom to where the body fits) the Ø1 mm styli of 10 and 20 mm
/// reach: their length less the 1 mm the planner keeps the body from the part.
const THIN_REACH: [f64; 2] = [9.0, 19.0];

/// A recess floor deeper than this (mm) is past the 50 mm stylus's reach with its head
/// kept 5 mm above the opening: the rack gets the stylus on a 50 mm extension, as
/// Renishaw's stylus guidance asks for a stylus "long enough to reach all features".
const DEEP_FLOOR: f64 = 45.0;

/// The depth (mm) of the part's deepest recess floor (`geometry::recess_depth`): the
/// floor of a pocket or blind hole walled on every side.
fn deepest_floor(part: &CadPart) -> f64 {
    let m = &part.mesh;
    let own = m.triangles_of_groups();
    m.exact
        .iter()
        .zip(&own)
        .filter_map(|(s, tris)| match s {
            Surface::Plane { normal, .. } if !tris.is_empty() => {
                crate::geometry::recess_depth(&m.vertices, &m.triangles, tris, normal)
            }
            _ => None,
        })
        .fold(0.0, f64::max)
}

/// The fixture that tilts the part: the 6 × 12 in sine plate, or the large tilting table
/// for a part the plate takes in no pose (more than half as large again as its top even
/// lying on its smallest side).
fn tilting_fixture(extent: [f64; 3]) -> &'static str {
    let mut e = extent;
    e.sort_by(f64::total_cmp);
    if e[0] > 1.5 * 150.0 || e[1] > 1.5 * 300.0 {
        "TILT_TABLE_60"
    } else {
        "SINE_PLATE_60"
    }
}

/// The part's extent along x, y and z (mm).
fn size(part: &CadPart) -> [f64; 3] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for v in &part.mesh.vertices {
        for i in 0..3 {
            lo[i] = lo[i].min(v[i]);
            hi[i] = hi[i].max(v[i]);
        }
    }
    [0, 1, 2].map(|i| hi[i] - lo[i])
}

/// The names the spec declares or imports beside the part's.
const SPEC_NAMES: &[&str] = &[
    "lab",
    "efficient_accuracy",
    "PH10MQ",
    "ANGLE_PLATE",
    "SINE_PLATE_60",
    "TP20_D2_L20",
    "TP20_D1_L10",
    "TP20_D1_L20",
    "TP20_D3_L50",
    "TP20_D2_L20_X30",
    "TP20_D1_L20_X30",
    "TP20_D3_L50_X50",
];

/// The part's name as an identifier that no other item of the spec has.
fn part_name(asked: &str) -> String {
    let name = source(asked, Place::Identifier);
    if SPEC_NAMES.contains(&name.as_str()) {
        format!("{name}_part")
    } else {
        name
    }
}

#[allow(clippy::too_many_arguments)]
fn render(
    part: &CadPart,
    (header, notes): (&str, &[String]),
    opts: &ImportOptions,
    feats: &Features,
    datum_lines: &[String],
    datum_notes: &[String],
    tol_lines: &[String],
    dim_lines: &[String],
) -> String {
    let mut s = String::new();
    let extent = size(part);
    let size = extent.map(|x| {
        written(x.round(), Sign::Any, "a size", "mm").map_or_else(|_| "?".to_string(), |w| w.0)
    });
    let _ = writeln!(
        s,
        "// Written by `inspc import` from {}.",
        source(&opts.cad_path, Place::Comment)
    );
    let _ = writeln!(
        s,
        "// {} faces (`face_<n>` in the file's shell order), {} × {} × {} mm; the file's unit is {}{}.",
        part.solid_faces(),
        size[0],
        size[1],
        size[2],
        source(&part.unit.0, Place::Comment),
        match opts.scale == 1.0 {
            true => String::new(),
            false => format!(", scaled × {}", fmt_num(opts.scale)),
        }
    );
    if part.sheet_faces > 0 {
        let _ = writeln!(
            s,
            "// The file's {} sheet (construction) face{} beside the solid {} no material and left out.",
            part.sheet_faces,
            if part.sheet_faces == 1 { "" } else { "s" },
            if part.sheet_faces == 1 { "is" } else { "are" },
        );
    }
    let _ = writeln!(s, "// {header}");
    if !notes.is_empty() {
        let title = match header == DEFAULT_HEADER {
            true => "Left out of the default inspection:",
            false => "The PMI as read:",
        };
        let _ = writeln!(s, "//\n// {title}");
        for n in notes {
            let _ = writeln!(s, "//   - {}", source(n, Place::Comment));
        }
    }
    let rack = rack(part, extent);
    let _ = writeln!(s, "\nuse std::heads::PH10MQ");
    let probes: Vec<&str> = rack.iter().map(|(_, p)| *p).collect();
    let _ = writeln!(s, "use std::probes::{{{}}}", probes.join(", "));
    let _ = writeln!(s, "use std::hierarchies::efficient_accuracy");
    let tilter = tilting_fixture(extent);
    let _ = writeln!(s, "use std::fixtures::{{ANGLE_PLATE, RISERS_25, {tilter}}}");

    let name = part_name(&opts.part_name);
    let _ = writeln!(s, "\npart {name} {{");
    let _ = writeln!(
        s,
        "    // Quantities below are in mm; the file's own unit applies to its geometry."
    );
    let _ = writeln!(s, "    units mm");
    let scale = match opts.scale == 1.0 {
        true => String::new(),
        false => format!(" {{ scale {} }}", fmt_num(opts.scale)),
    };
    let _ = writeln!(
        s,
        "    mesh \"{}\"{scale}",
        source(&opts.cad_path, Place::Literal)
    );
    if !feats.order.is_empty() {
        s.push('\n');
    }
    for faces in &feats.order {
        let name = &feats.by_faces[faces];
        let terms: Vec<String> = faces
            .iter()
            .map(|f| format!("group \"face_{}\"", f + 1))
            .collect();
        let head = format!("    feature {name} = ");
        let mut line = head.clone();
        let indent = " ".repeat(head.len() - 2);
        for (i, t) in terms.iter().enumerate() {
            if i > 0 {
                if i % 4 == 0 {
                    let _ = writeln!(s, "{line}");
                    line = format!("{indent}+ {t}");
                    continue;
                }
                line.push_str(" + ");
            }
            line.push_str(t);
        }
        let _ = writeln!(s, "{line}");
    }
    for block in [datum_notes, datum_lines, tol_lines, dim_lines] {
        if !block.is_empty() {
            s.push('\n');
            for l in block {
                let _ = writeln!(s, "{l}");
            }
        }
    }
    let _ = writeln!(s, "}}");

    // A part too large to write gets the smallest table; its size says `?` above.
    let table = |i: usize, min: f64| {
        let want = (extent[i] * 2.5 / 100.0).ceil() * 100.0;
        written(want, Sign::Positive, "a table", "mm")
            .map_or(fmt_num(min), |w| fmt_num(min.max(w.1)))
    };
    let _ = writeln!(
        s,
        "\n// A bridge CMM whose table holds the part in any pose, an indexable head and a rack\n// sized to the part's smallest holes and its height."
    );
    let _ = writeln!(s, "cmm lab {{");
    let _ = writeln!(
        s,
        "    table {{ z 0 mm, size ({} mm, {} mm) }}",
        table(0, 2000.0),
        table(1, 1200.0)
    );
    let _ = writeln!(s, "    ram {{ radius 40 mm, length 800 mm }}");
    let _ = writeln!(s, "    head PH10MQ");
    let rack_text: Vec<String> = rack.iter().map(|(l, p)| format!("{l}: {p}")).collect();
    let _ = writeln!(s, "    probes [{}]", rack_text.join(", "));
    let _ = writeln!(
        s,
        "    fixtures [risers: RISERS_25, angle: ANGLE_PLATE, sine: {tilter}]"
    );
    let _ = writeln!(s, "}}");
    let _ = writeln!(s, "\nplan {name}_plan {{");
    let _ = writeln!(s, "    part {name}");
    let _ = writeln!(s, "    cmm lab");
    let _ = writeln!(s, "    hierarchy efficient_accuracy");
    let _ = writeln!(s, "    prefer setup +z weight 1.0");
    let _ = writeln!(
        s,
        "    // Risers where the table hides a face, plates for faces no pose on it presents."
    );
    let _ = writeln!(s, "    fixtures [risers, angle, sine]");
    let _ = writeln!(s, "    output {{ dmis \"{name}.dmi\" }}");
    let _ = writeln!(s, "}}");
    s
}
