//! The deviations file: how the virtual part and its placement differ from nominal.
//!
//! One change per line, `#` to the end of a line is a comment; lengths in mm, angles in
//! degrees (a trailing `mm` or `deg` may say so):
//!
//! ```text
//! feature bore_1 move (0.3, 0, 0)        # the feature's faces translate (part frame)
//! feature top tilt 0.2 about (0, 1, 0)   # turn about an axis through its centroid
//! feature bore_1 grow 0.05               # its size grows: a diameter, a slot's width
//! face stock.top bow 0.1                 # a plane's centre stands out (flatness); a
//!                                        # face by its geometry name or a feature's name
//! face stock.top shift 0.1               # a plane moves along its outward normal
//! face stock.top bump 0.04 at (50, 20, 30) across 25
//!                                        # a plane stands out 0.04 at the point,
//!                                        # nothing 12.5 mm from it (a local dent
//!                                        # where negative: flatness per unit area)
//! part move (5, 0)                       # the part lies off on the table (machine x, y)
//! part turn 3                            # … and turned about the vertical (degrees)
//! setup 2 move (1, 0)                    # the same, in one setup only
//! ```
//!
//! Changes to one face compose in file order. A feature's changes apply to each of its
//! faces about the feature's centroid, so a moved bore stays one cylinder.

use super::errors::SimError;
use super::number::number;
use crate::geometry::{FaceId, PartGeometry, Surface, P3, V3};
use crate::model::Part;
use crate::source::{FileId, Span};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion};

/// How one face differs from its nominal.
#[derive(Debug, Clone)]
pub struct FaceChange {
    /// A rigid motion in the part frame.
    pub motion: Isometry3<f64>,
    /// Growth of the face's size (mm): a cylinder's, sphere's or cone's diameter.
    pub grow: f64,
    /// A plane's bow (mm): its centre stands this far out along its normal, falling
    /// off with the square of the distance to nothing at its farthest corner.
    pub bow: f64,
    /// Local bumps on a plane (nominal part frame): each a bow of its own `reach`
    /// about its `centre`, nothing beyond.
    pub(crate) bumps: Vec<Bow>,
}

/// A planar face bowed: a paraboloid over the plane, in the nominal part frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bow {
    /// Height at the centre (mm).
    pub height: f64,
    /// The face's centroid.
    pub centre: P3,
    /// The distance from it, across the normal, where the bow ends.
    pub reach: f64,
}

impl Bow {
    /// How far the bowed plane stands out at (the projection of) `x`.
    pub fn at(&self, normal: &V3, x: &P3) -> f64 {
        let d = x - self.centre;
        let across = (d - normal * d.dot(normal)).norm();
        self.height * (1.0 - (across / self.reach).powi(2))
    }

    /// The same, as a bump: nothing beyond its reach.
    fn bump_at(&self, normal: &V3, x: &P3) -> f64 {
        let d = x - self.centre;
        let across = (d - normal * d.dot(normal)).norm();
        if across >= self.reach {
            0.0
        } else {
            self.at(normal, x)
        }
    }
}

/// How far a plane stands out of its moved nominal: its bow and its bumps.
#[derive(Debug, Clone)]
pub(crate) struct Lift {
    bow: Option<Bow>,
    bumps: Vec<Bow>,
}

impl Lift {
    /// How far the plane of normal `normal` stands out at (the projection of) `x`.
    pub fn at(&self, normal: &V3, x: &P3) -> f64 {
        self.bow.map_or(0.0, |b| b.at(normal, x))
            + self.bumps.iter().map(|b| b.bump_at(normal, x)).sum::<f64>()
    }
}

impl Default for FaceChange {
    fn default() -> Self {
        FaceChange {
            motion: Isometry3::identity(),
            grow: 0.0,
            bow: 0.0,
            bumps: Vec::new(),
        }
    }
}

/// Where the part lies on the table against where the program expects it.
#[derive(Debug, Clone, Copy, Default)]
pub struct Placement {
    /// Machine x and y (mm).
    pub shift: [f64; 2],
    /// About the vertical through the part's centre (degrees).
    pub turn: f64,
}

/// A placement of one setup only, on top of every setup's.
#[derive(Debug, Clone, Copy)]
pub struct SetupPlacement {
    /// The setup, from 1.
    pub setup: usize,
    /// How it lies off.
    pub placement: Placement,
    /// The setup's number in the deviations file.
    pub span: Span,
}

/// Everything a deviations file says.
#[derive(Debug, Clone, Default)]
pub struct Deviations {
    /// Per face (by index), its change; faces not named are nominal.
    pub faces: Vec<FaceChange>,
    /// For every setup.
    pub placement: Placement,
    /// Per setup, on top of [`Deviations::placement`].
    pub setups: Vec<SetupPlacement>,
}

impl Deviations {
    /// The nominal part, placed where the program expects it.
    pub fn nominal(faces: usize) -> Deviations {
        Deviations {
            faces: vec![FaceChange::default(); faces],
            ..Default::default()
        }
    }

    /// The placement of setup `k` (from 1).
    pub(crate) fn placement_of(&self, k: usize) -> Placement {
        let mut p = self.placement;
        for s in self.setups.iter().filter(|s| s.setup == k) {
            p.shift[0] += s.placement.shift[0];
            p.shift[1] += s.placement.shift[1];
            p.turn += s.placement.turn;
        }
        p
    }

    /// An error for each placement of a setup the program does not have (it ran
    /// `setups` of them): a deviation that applies to nothing is a mistake in the file,
    /// and the run it was meant for never happened.
    pub(crate) fn missing_setups(&self, setups: usize) -> Vec<SimError> {
        self.setups
            .iter()
            .filter(|s| s.setup > setups)
            .map(|s| SimError::BadDeviation {
                span: s.span,
                what: format!(
                    "the program has {setups} setup{}: there is no setup {}",
                    if setups == 1 { "" } else { "s" },
                    s.setup
                ),
                label: "no such setup".into(),
                help: format!(
                    "number the setups from 1 to {setups}, as the program's `PAUSE`s place the part; `part move|turn` places it in every setup"
                ),
            })
            .collect()
    }

    /// A planar face's bow and bumps, moved with it; `None` when it has neither.
    pub(crate) fn lift_of(&self, g: &PartGeometry, f: FaceId) -> Option<Lift> {
        let c = self.faces.get(f.0)?;
        let bumps: Vec<Bow> = c
            .bumps
            .iter()
            .map(|b| Bow {
                centre: c.motion * b.centre,
                ..*b
            })
            .collect();
        let bow = self.bow_of(g, f);
        (bow.is_some() || !bumps.is_empty()).then_some(Lift { bow, bumps })
    }

    /// A planar face's bow, moved with it; `None` when it has none.
    fn bow_of(&self, g: &PartGeometry, f: FaceId) -> Option<Bow> {
        let c = self.faces.get(f.0)?;
        if c.bow == 0.0 {
            return None;
        }
        let face = &g.faces[f.0];
        let Surface::Plane { normal, .. } = face.surface else {
            return None;
        };
        let reach = face
            .triangles
            .iter()
            .flat_map(|t| g.triangles[*t as usize])
            .map(|v| {
                let d = g.vertices[v as usize] - face.centroid;
                (d - normal * d.dot(&normal)).norm()
            })
            .fold(0.0f64, f64::max);
        Some(Bow {
            height: c.bow,
            centre: c.motion * face.centroid,
            reach: reach.max(1e-6),
        })
    }

    /// The face's actual surface: the nominal moved and grown.
    pub fn surface(&self, g: &PartGeometry, f: FaceId) -> Surface {
        let nominal = &g.faces[f.0].surface;
        let Some(c) = self.faces.get(f.0) else {
            return nominal.clone();
        };
        let half = c.grow / 2.0;
        // Grown in place, then moved.
        let grown = match nominal.clone() {
            Surface::Cylinder {
                origin,
                axis,
                radius,
                convex,
            } => Surface::Cylinder {
                origin,
                axis,
                radius: radius + half,
                convex,
            },
            // Every diameter grows by `grow`: the apex moves back along the axis.
            Surface::Cone {
                apex,
                axis,
                half_angle,
                convex,
            } => Surface::Cone {
                apex: apex - axis * (half / half_angle.tan().max(1e-9)),
                axis,
                half_angle,
                convex,
            },
            Surface::Sphere {
                center,
                radius,
                convex,
            } => Surface::Sphere {
                center,
                radius: radius + half,
                convex,
            },
            other => other,
        };
        grown.moved(&c.motion)
    }
}

/// A token of the file with its byte range.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Word(String),
    Num(f64),
    Open,
    Close,
    Comma,
}

/// Why a stretch of a line is no token: its byte range, and what to say.
struct NoToken {
    start: usize,
    end: usize,
    what: String,
    label: &'static str,
    help: String,
}

/// Tokens with their byte ranges, or what is none.
type Tokens = Result<Vec<(Tok, usize, usize)>, NoToken>;

fn tokens(line: &str, base: usize) -> Tokens {
    let b = line.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i] as char;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let start = i;
        let tok = match c {
            '(' => {
                i += 1;
                Tok::Open
            }
            ')' => {
                i += 1;
                Tok::Close
            }
            ',' => {
                i += 1;
                Tok::Comma
            }
            '-' | '+' | '.' | '0'..='9' => {
                while i < b.len() && matches!(b[i] as char, '-' | '+' | '.' | 'e' | 'E' | '0'..='9')
                {
                    i += 1;
                }
                let text = &line[start..i];
                let (what, help) = match number(text) {
                    Ok(Some(x)) => {
                        out.push((Tok::Num(x), base + start, base + i));
                        continue;
                    }
                    Ok(None) => (format!("`{text}` is not a number"), USAGE.to_string()),
                    Err(why) => (format!("a deviation with {}", why.what(text)), why.help()),
                };
                return Err(NoToken {
                    start: base + start,
                    end: base + i,
                    what,
                    label: "not a usable number",
                    help,
                });
            }
            _ if c.is_ascii_alphabetic() || c == '_' => {
                while i < b.len()
                    && ((b[i] as char).is_ascii_alphanumeric()
                        || matches!(b[i], b'_' | b'.' | b'[' | b']'))
                {
                    i += 1;
                }
                Tok::Word(line[start..i].to_string())
            }
            _ => {
                // The whole character, though the loop reads bytes.
                let c = line[start..].chars().next().unwrap_or(' ');
                return Err(NoToken {
                    start: base + start,
                    end: base + start + c.len_utf8(),
                    what: "a deviation line holds a character it cannot read".into(),
                    label: "not a word, number, parenthesis or comma",
                    help: "write one change per line: `feature NAME move (x, y, z)`".into(),
                });
            }
        };
        out.push((tok, base + start, base + i));
    }
    Ok(out)
}

/// Reads a deviations file against a part: every problem is a diagnostic with its span.
pub fn parse(
    file: FileId,
    text: &str,
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
) -> Result<Deviations, Vec<SimError>> {
    let mut dev = Deviations::nominal(g.faces.len());
    let mut errors = Vec::new();
    let mut offset = 0;
    for raw in text.split_inclusive('\n') {
        let base = offset;
        offset += raw.len();
        let line = raw.split('#').next().unwrap_or("");
        let line = line.trim_end_matches(['\n', '\r']);
        if line.trim().is_empty() {
            continue;
        }
        let bad =
            |s: usize, e: usize, what: &str, label: &str, help: &str| SimError::BadDeviation {
                span: Span::new(file, s, e.max(s + 1).min(base + line.len().max(1))),
                what: what.into(),
                label: label.into(),
                help: help.into(),
            };
        let toks = match tokens(line, base) {
            Ok(t) => t,
            Err(no) => {
                errors.push(bad(no.start, no.end, &no.what, no.label, &no.help));
                continue;
            }
        };
        let mut c = Cur {
            toks: &toks,
            k: 0,
            file,
        };
        if let Err(e) = one_line(&mut c, &mut dev, part, g, feature_faces, &bad) {
            errors.push(e);
        }
    }
    if errors.is_empty() {
        Ok(dev)
    } else {
        Err(errors)
    }
}

type Bad<'a> = dyn Fn(usize, usize, &str, &str, &str) -> SimError + 'a;

const USAGE: &str = "lines read `feature NAME move (x, y, z)`, `… tilt DEG about (x, y, z)`, `… grow MM`, `face NAME shift MM`, `face NAME bow MM`, `part move (x, y)`, `part turn DEG` or `setup N move|turn …`";

/// A cursor over one line's tokens.
struct Cur<'t> {
    toks: &'t [(Tok, usize, usize)],
    k: usize,
    /// The deviations file, for spans the parse keeps.
    file: FileId,
}

impl Cur<'_> {
    fn end(&self) -> (usize, usize) {
        self.toks.last().map(|t| (t.2, t.2 + 1)).unwrap_or((0, 1))
    }

    fn span(&self) -> (usize, usize) {
        self.toks
            .get(self.k)
            .map(|t| (t.1, t.2))
            .unwrap_or_else(|| self.end())
    }

    fn word(&mut self) -> Option<String> {
        match self.toks.get(self.k) {
            Some((Tok::Word(w), ..)) => {
                self.k += 1;
                Some(w.clone())
            }
            _ => None,
        }
    }

    fn num(&mut self) -> Option<f64> {
        match self.toks.get(self.k) {
            Some((Tok::Num(x), ..)) => {
                self.k += 1;
                Some(*x)
            }
            _ => None,
        }
    }

    fn is(&mut self, t: &Tok) -> bool {
        if self.toks.get(self.k).map(|x| &x.0) == Some(t) {
            self.k += 1;
            true
        } else {
            false
        }
    }

    /// An optional unit word among `units`.
    fn unit(&mut self, units: &[&str]) {
        if let Some((Tok::Word(w), ..)) = self.toks.get(self.k) {
            if units.contains(&w.as_str()) {
                self.k += 1;
            }
        }
    }

    /// `(a, b[, c])` with `n` numbers.
    fn tuple(&mut self, n: usize) -> Option<Vec<f64>> {
        if !self.is(&Tok::Open) {
            return None;
        }
        let mut v = Vec::new();
        for i in 0..n {
            if i > 0 && !self.is(&Tok::Comma) {
                return None;
            }
            v.push(self.num()?);
        }
        self.is(&Tok::Close).then_some(v)
    }
}

/// One line of the file: what it changes (`part`, `setup`, `feature`, `face`), read
/// into `dev`.
fn one_line(
    c: &mut Cur,
    dev: &mut Deviations,
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
    bad: &Bad,
) -> Result<(), SimError> {
    let (s0, e0) = c.span();
    let Some(kind) = c.word() else {
        return Err(bad(
            s0,
            e0,
            "a deviation line starts with what it changes",
            "expected `feature`, `face`, `part` or `setup`",
            USAGE,
        ));
    };
    match kind.as_str() {
        "part" | "setup" => placement_line(c, &kind, dev, bad)?,
        "feature" | "face" => face_line(c, &kind, dev, part, g, feature_faces, bad)?,
        _ => {
            return Err(bad(
                s0,
                e0,
                &format!("`{kind}` is not something a deviation changes"),
                "expected `feature`, `face`, `part` or `setup`",
                USAGE,
            ))
        }
    }
    if c.k < c.toks.len() {
        let (s, e) = c.span();
        return Err(bad(
            s,
            e,
            "a deviation line goes on past its change",
            "unexpected",
            USAGE,
        ));
    }
    Ok(())
}

/// `part move|turn …` or `setup N move|turn …`: the part's placement on the table, for
/// every setup or for one.
fn placement_line(
    c: &mut Cur,
    kind: &str,
    dev: &mut Deviations,
    bad: &Bad,
) -> Result<(), SimError> {
    let setup = if kind == "setup" {
        let (s, e) = c.span();
        Some((setup_number(c, bad)?, Span::new(c.file, s, e)))
    } else {
        None
    };
    let p = placement(c, bad)?;
    match setup {
        Some((setup, span)) => dev.setups.push(SetupPlacement {
            setup,
            placement: p,
            span,
        }),
        None => {
            dev.placement.shift[0] += p.shift[0];
            dev.placement.shift[1] += p.shift[1];
            dev.placement.turn += p.turn;
        }
    }
    Ok(())
}

/// The setup's number after `setup`, from 1.
fn setup_number(c: &mut Cur, bad: &Bad) -> Result<usize, SimError> {
    let (s, e) = c.span();
    match c.num() {
        Some(n) if n >= 1.0 && n.fract() == 0.0 => Ok(n as usize),
        _ => Err(bad(
            s,
            e,
            "`setup` takes the setup's number, from 1",
            "expected a whole number",
            USAGE,
        )),
    }
}

/// `move (x, y)` or `turn DEG`: how the part lies off on the table.
fn placement(c: &mut Cur, bad: &Bad) -> Result<Placement, SimError> {
    let (s, e) = c.span();
    let mut p = Placement::default();
    match c.word().as_deref() {
        Some("move") => {
            let Some(v) = c.tuple(2) else {
                let (s, e) = c.span();
                return Err(bad(
                    s,
                    e,
                    "`move` of the part takes its shift on the table",
                    "expected `(x, y)`",
                    "the part moves in the table's plane: `part move (5, 0) mm`",
                ));
            };
            c.unit(&["mm"]);
            p.shift = [v[0], v[1]];
        }
        Some("turn") => {
            let Some(a) = c.num() else {
                let (s, e) = c.span();
                return Err(bad(
                    s,
                    e,
                    "`turn` takes an angle in degrees",
                    "expected a number",
                    "`part turn 3 deg`",
                ));
            };
            c.unit(&["deg"]);
            p.turn = a;
        }
        _ => {
            return Err(bad(
                s,
                e,
                "the part on the table can `move` or `turn`",
                "expected `move` or `turn`",
                "the part rests on the table: it moves in its plane and turns about the vertical",
            ))
        }
    }
    Ok(p)
}

/// `feature NAME …` or `face NAME …`: a change to the faces it names, composed with
/// their changes so far.
fn face_line(
    c: &mut Cur,
    kind: &str,
    dev: &mut Deviations,
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
    bad: &Bad,
) -> Result<(), SimError> {
    let (ns, ne) = c.span();
    let Some(name) = c.word() else {
        return Err(bad(
            ns,
            ne,
            &format!("`{kind}` takes a name"),
            "expected a name",
            USAGE,
        ));
    };
    let faces = if kind == "feature" {
        feature_faces_named(&name, (ns, ne), part, feature_faces, bad)?
    } else {
        face_named(&name, (ns, ne), part, g, feature_faces, bad)?
    };
    if faces.is_empty() {
        return Err(bad(
            ns,
            ne,
            &format!("feature `{name}` has no faces to change"),
            "no faces",
            USAGE,
        ));
    }
    for (f, ch) in face_change(c, &name, &faces, g, bad)? {
        let cur = &mut dev.faces[f.0];
        cur.motion = ch.motion * cur.motion;
        cur.grow += ch.grow;
        cur.bow += ch.bow;
        cur.bumps.extend(ch.bumps);
    }
    Ok(())
}

/// The faces of the part's feature `name`, written at `ns..ne`.
fn feature_faces_named(
    name: &str,
    (ns, ne): (usize, usize),
    part: &Part,
    feature_faces: &[Vec<FaceId>],
    bad: &Bad,
) -> Result<Vec<FaceId>, SimError> {
    match part.features.iter().position(|f| f.name == name) {
        Some(k) => Ok(feature_faces.get(k).cloned().unwrap_or_default()),
        None => {
            let names: Vec<&str> = part.features.iter().map(|f| f.name.as_str()).collect();
            let help = match crate::diag::suggest::did_you_mean(name, names.iter().copied()) {
                Some(s) => format!("did you mean `{s}`?"),
                None => {
                    format!("part `{}` has features {}", part.name, names.join(", "))
                }
            };
            Err(bad(
                ns,
                ne,
                &format!("part `{}` has no feature `{name}`", part.name),
                "unknown feature",
                &help,
            ))
        }
    }
}

/// The part's face `name`, written at `ns..ne`: a face of the geometry by its name
/// (`stock.top`, `face_12`, as `inspc faces` lists them), else the faces of the feature
/// the spec names so (`face top bow 0.1` where the spec says `feature top = …`).
fn face_named(
    name: &str,
    (ns, ne): (usize, usize),
    part: &Part,
    g: &PartGeometry,
    feature_faces: &[Vec<FaceId>],
    bad: &Bad,
) -> Result<Vec<FaceId>, SimError> {
    if let Some(k) = g.faces.iter().position(|f| f.name == name) {
        return Ok(vec![FaceId(k)]);
    }
    match part.features.iter().position(|f| f.name == name) {
        Some(k) => Ok(feature_faces.get(k).cloned().unwrap_or_default()),
        None => {
            let faces = g.faces.iter().map(|f| f.name.as_str());
            let features = part.features.iter().map(|f| f.name.as_str());
            let help = match crate::diag::suggest::did_you_mean(name, faces.chain(features)) {
                Some(s) => format!("did you mean `{s}`?"),
                None => "`inspc faces SPEC` lists the part's faces".into(),
            };
            Err(bad(
                ns,
                ne,
                &format!("part `{}` has no face `{name}`", part.name),
                "unknown face",
                &help,
            ))
        }
    }
}

/// The change the verb after a feature's or face's name says (`move`, `tilt`,
/// `shift`, `bow`, `grow`), per face of `faces`.
fn face_change(
    c: &mut Cur,
    name: &str,
    faces: &[FaceId],
    g: &PartGeometry,
    bad: &Bad,
) -> Result<Vec<(FaceId, FaceChange)>, SimError> {
    let verb_at = c.span();
    let (vs, ve) = verb_at;
    match c.word().as_deref() {
        Some("move") => move_change(c, faces, bad),
        Some("tilt") => tilt_change(c, faces, area_centroid(g, faces), bad),
        Some("shift") => shift_change(c, faces, g, verb_at, bad),
        Some("bow") => bow_change(c, faces, g, verb_at, bad),
        Some("bump") => bump_change(c, faces, g, verb_at, bad),
        Some("grow") => {
            let Some(d) = c.num() else {
                let (s, e) = c.span();
                return Err(bad(
                    s,
                    e,
                    "`grow` takes a size change",
                    "expected a number",
                    "`feature bore grow 0.05 mm` grows a diameter or a slot's width",
                ));
            };
            c.unit(&["mm"]);
            grow(g, faces, d).ok_or_else(|| bad(vs, ve, &format!("`{name}` has no size to grow"), "no size", "`grow` changes a cylinder's, cone's or sphere's diameter, or the width between two opposed planes"))
        }
        _ => Err(bad(
            vs,
            ve,
            "a feature or face can `move`, `tilt`, `shift` or `grow`",
            "expected a change",
            USAGE,
        )),
    }
}

/// The faces' centroid, weighted by their areas.
fn area_centroid(g: &PartGeometry, faces: &[FaceId]) -> P3 {
    let (mut s, mut w) = (V3::zeros(), 0.0);
    for f in faces {
        let face = &g.faces[f.0];
        s += face.centroid.coords * face.area;
        w += face.area;
    }
    P3::from(s / w.max(1e-12))
}

/// `move (x, y, z)`: every face translated (part frame).
fn move_change(
    c: &mut Cur,
    faces: &[FaceId],
    bad: &Bad,
) -> Result<Vec<(FaceId, FaceChange)>, SimError> {
    let Some(v) = c.tuple(3) else {
        let (s, e) = c.span();
        return Err(bad(
            s,
            e,
            "`move` takes a translation",
            "expected `(x, y, z)`",
            "`feature bore move (0.3, 0, 0) mm`, in the part frame",
        ));
    };
    c.unit(&["mm"]);
    let m = Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::identity(),
    );
    Ok(rigid(faces, m))
}

/// `tilt DEG about (x, y, z)`: every face turned about the axis through `centroid`.
fn tilt_change(
    c: &mut Cur,
    faces: &[FaceId],
    centroid: P3,
    bad: &Bad,
) -> Result<Vec<(FaceId, FaceChange)>, SimError> {
    let Some(a) = c.num() else {
        let (s, e) = c.span();
        return Err(bad(
            s,
            e,
            "`tilt` takes an angle in degrees",
            "expected a number",
            "`feature top tilt 0.2 deg about (0, 1, 0)`",
        ));
    };
    c.unit(&["deg"]);
    let (s, e) = c.span();
    let axis = if c.word().as_deref() == Some("about") {
        c.tuple(3)
    } else {
        None
    };
    // Scaled by its largest component before it is normalised: the length of
    // (1e300, 1e300, 0) overflows, which would leave no direction at all.
    let direction = |v: Vec<f64>| {
        let v = V3::new(v[0], v[1], v[2]);
        let m = v.amax();
        (m > 0.0).then(|| Unit::try_new(v / m, 1e-12)).flatten()
    };
    let Some(axis) = axis.and_then(direction) else {
        return Err(bad(
            s,
            e,
            "`tilt` needs the axis it turns about",
            "expected `about (x, y, z)`",
            "the axis passes through the feature's centroid: `tilt 0.2 deg about (0, 1, 0)`",
        ));
    };
    let r = UnitQuaternion::from_axis_angle(&axis, a.to_radians());
    // About the centroid: x ↦ c + R (x − c).
    let m = Isometry3::from_parts(Translation3::from(centroid.coords - r * centroid.coords), r);
    Ok(rigid(faces, m))
}

/// `shift MM`: every face, a plane, moved along its outward normal; the verb, at
/// `vs..ve`, is blamed for a face that is not one.
fn shift_change(
    c: &mut Cur,
    faces: &[FaceId],
    g: &PartGeometry,
    (vs, ve): (usize, usize),
    bad: &Bad,
) -> Result<Vec<(FaceId, FaceChange)>, SimError> {
    let Some(d) = c.num() else {
        let (s, e) = c.span();
        return Err(bad(
            s,
            e,
            "`shift` takes a distance",
            "expected a number",
            "`face stock.top shift 0.1 mm` moves a plane along its outward normal",
        ));
    };
    c.unit(&["mm"]);
    let mut out = Vec::new();
    for f in faces {
        let Surface::Plane { normal, .. } = g.faces[f.0].surface else {
            return Err(bad(
                vs,
                ve,
                &format!(
                    "`shift` moves planes along their normal; `{}` is not a plane",
                    g.faces[f.0].name
                ),
                "not a plane",
                "move other faces with `move (x, y, z)`, or change their size with `grow`",
            ));
        };
        let t = normal * d;
        out.push((
            *f,
            FaceChange {
                motion: Isometry3::from_parts(Translation3::from(t), UnitQuaternion::identity()),
                ..FaceChange::default()
            },
        ));
    }
    Ok(out)
}

/// `bow MM`: every face, a plane, bent so its centre stands out; the verb, at
/// `vs..ve`, is blamed for a face that is not one.
fn bow_change(
    c: &mut Cur,
    faces: &[FaceId],
    g: &PartGeometry,
    (vs, ve): (usize, usize),
    bad: &Bad,
) -> Result<Vec<(FaceId, FaceChange)>, SimError> {
    let Some(d) = c.num() else {
        let (s, e) = c.span();
        return Err(bad(
            s,
            e,
            "`bow` takes a height",
            "expected a number",
            "`face stock.top bow 0.1 mm`: the plane's centre stands out by that much",
        ));
    };
    c.unit(&["mm"]);
    let mut out = Vec::new();
    for f in faces {
        if !matches!(g.faces[f.0].surface, Surface::Plane { .. }) {
            return Err(bad(
                vs,
                ve,
                &format!("`bow` bends planes; `{}` is not a plane", g.faces[f.0].name),
                "not a plane",
                "change other faces with `move`, `tilt` or `grow`",
            ));
        }
        out.push((
            *f,
            FaceChange {
                bow: d,
                ..FaceChange::default()
            },
        ));
    }
    Ok(out)
}

/// `bump MM at (x, y, z) across MM`: every face, a plane, standing out by the height at
/// the point (part frame, projected onto each plane), nothing half the width from it.
fn bump_change(
    c: &mut Cur,
    faces: &[FaceId],
    g: &PartGeometry,
    (vs, ve): (usize, usize),
    bad: &Bad,
) -> Result<Vec<(FaceId, FaceChange)>, SimError> {
    const HELP: &str = "`face stock.top bump 0.04 mm at (50, 20, 30) across 25 mm`: the plane stands out 0.04 mm at the point, nothing 12.5 mm from it";
    let height = c.num();
    c.unit(&["mm"]);
    let at = (c.word().as_deref() == Some("at"))
        .then(|| c.tuple(3))
        .flatten();
    c.unit(&["mm"]);
    let across = (c.word().as_deref() == Some("across"))
        .then(|| c.num())
        .flatten()
        .filter(|w| *w > 0.0);
    c.unit(&["mm"]);
    let (Some(height), Some(at), Some(across)) = (height, at, across) else {
        let (s, e) = c.span();
        return Err(bad(
            s,
            e,
            "`bump` takes a height, a point and a width",
            "expected `bump H at (x, y, z) across W`",
            HELP,
        ));
    };
    let mut out = Vec::new();
    for f in faces {
        let Surface::Plane { origin, normal } = g.faces[f.0].surface else {
            return Err(bad(
                vs,
                ve,
                &format!(
                    "`bump` raises planes; `{}` is not a plane",
                    g.faces[f.0].name
                ),
                "not a plane",
                HELP,
            ));
        };
        let p = P3::new(at[0], at[1], at[2]);
        let centre = p - normal * (p - origin).dot(&normal);
        out.push((
            *f,
            FaceChange {
                bumps: vec![Bow {
                    height,
                    centre,
                    reach: across / 2.0,
                }],
                ..FaceChange::default()
            },
        ));
    }
    Ok(out)
}

/// Every face moved by `m`.
fn rigid(faces: &[FaceId], m: Isometry3<f64>) -> Vec<(FaceId, FaceChange)> {
    let change = FaceChange {
        motion: m,
        ..FaceChange::default()
    };
    faces.iter().map(|f| (*f, change.clone())).collect()
}

/// A size change: curved faces grow in diameter; two opposed planes move apart (a
/// slot's walls into the material, a tab's out of it).
fn grow(g: &PartGeometry, faces: &[FaceId], d: f64) -> Option<Vec<(FaceId, FaceChange)>> {
    let planes: Vec<(FaceId, P3, V3)> = faces
        .iter()
        .filter_map(|f| match g.faces[f.0].surface {
            Surface::Plane { origin, normal } => Some((*f, origin, normal)),
            _ => None,
        })
        .collect();
    let mut out = Vec::new();
    for f in faces {
        match g.faces[f.0].surface {
            Surface::Cylinder { .. } | Surface::Cone { .. } | Surface::Sphere { .. } => out.push((
                *f,
                FaceChange {
                    motion: Isometry3::identity(),
                    grow: d,
                    ..FaceChange::default()
                },
            )),
            Surface::Plane { origin, normal } => {
                // Its opposite wall: a plane of the feature facing the other way.
                let (_, o2, _) = planes.iter().find(|(_, _, n2)| n2.dot(&normal) < -0.999)?;
                let inner = (o2 - origin).dot(&normal) > 0.0;
                let s = if inner { -d / 2.0 } else { d / 2.0 };
                out.push((
                    *f,
                    FaceChange {
                        motion: Isometry3::from_parts(
                            Translation3::from(normal * s),
                            UnitQuaternion::identity(),
                        ),
                        ..FaceChange::default()
                    },
                ));
            }
            Surface::Freeform => return None,
        }
    }
    (!out.is_empty()).then_some(out)
}
