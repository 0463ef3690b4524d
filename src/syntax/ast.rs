//! The syntax tree of one `.insp` file: what was written, with spans, nothing resolved.

use crate::source::Span;

/// A name as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Ident {
    /// The text.
    pub name: String,
    /// Where it was written.
    pub span: Span,
}

/// A string literal, unescaped.
#[derive(Debug, Clone, PartialEq)]
pub struct Str {
    /// The value with escapes resolved.
    pub value: String,
    /// Where it was written, quotes included.
    pub span: Span,
}

/// One parsed file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct File {
    /// Top-level items in source order.
    pub items: Vec<Item>,
}

/// A top-level item.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// `use …`
    Use(Use),
    /// `part name { … }`
    Part(Part),
    /// `cmm`, `head`, `probe`, `stylus`, `body`, `extension` or `sampling` with properties.
    Block(BlockItem),
    /// `hierarchy name { … }`
    Hierarchy(Hierarchy),
    /// `plan name { … }`
    Plan(Plan),
}

/// What a `use` imports from.
#[derive(Debug, Clone, PartialEq)]
pub enum UseSource {
    /// A module path such as `std::heads::PH6` (segments as written).
    Module(Vec<Ident>),
    /// A file path relative to the importing file.
    File(Str),
}

/// Which items a `use` selects.
#[derive(Debug, Clone, PartialEq)]
pub enum UseSelect {
    /// No selector: for a file, every item; for a module path, its last segment.
    Implicit,
    /// `::*`
    Glob(Span),
    /// `::{a, b}`
    Names(Vec<Ident>),
}

/// `use std::probes::{A, B}` or `use "shared/lab.insp"`.
#[derive(Debug, Clone, PartialEq)]
pub struct Use {
    /// Where to import from.
    pub source: UseSource,
    /// What to import.
    pub select: UseSelect,
    /// The whole statement.
    pub span: Span,
}

/// The kind of a generic property item.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum BlockKind {
    /// A coordinate measuring machine.
    Cmm,
    /// A probe head.
    Head,
    /// A probe assembly (body, extensions, stylus).
    Probe,
    /// A stylus.
    Stylus,
    /// A probe body.
    Body,
    /// A stylus extension.
    Extension,
    /// A sampling strategy set.
    Sampling,
    /// A fixture that holds a part on the table.
    Fixture,
    /// A laser line scanner.
    Scanner,
}

impl BlockKind {
    /// The keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            BlockKind::Cmm => "cmm",
            BlockKind::Head => "head",
            BlockKind::Probe => "probe",
            BlockKind::Stylus => "stylus",
            BlockKind::Body => "body",
            BlockKind::Extension => "extension",
            BlockKind::Sampling => "sampling",
            BlockKind::Fixture => "fixture",
            BlockKind::Scanner => "scanner",
        }
    }
}

/// `cmm lab { … }` and the other property items.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockItem {
    /// Which item.
    pub kind: BlockKind,
    /// Its name.
    pub name: Ident,
    /// Its properties in source order.
    pub props: Vec<Prop>,
    /// The whole item.
    pub span: Span,
}

/// `key value`
#[derive(Debug, Clone, PartialEq)]
pub struct Prop {
    /// The key.
    pub key: Ident,
    /// The value.
    pub value: Value,
    /// Key and value.
    pub span: Span,
}

/// A number with an optional unit, as written.
#[derive(Debug, Clone, PartialEq)]
pub struct Quantity {
    /// The number.
    pub value: f64,
    /// The unit, if one was written.
    pub unit: Option<Ident>,
    /// Number and unit.
    pub span: Span,
}

/// A segment of a path: `a`, `.b`, `[3]`.
#[derive(Debug, Clone, PartialEq)]
pub enum PathSeg {
    /// A name.
    Name(Ident),
    /// An index into a pattern.
    Index(u32, Span),
}

/// `stock.top`, `grid[3].wall`, `std::hierarchies::efficiency`.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// The segments; the first is always a name.
    pub segs: Vec<PathSeg>,
    /// The path as written.
    pub text: String,
    /// The whole path.
    pub span: Span,
}

impl Path {
    /// The first name.
    pub fn head(&self) -> &Ident {
        match &self.segs[0] {
            PathSeg::Name(i) => i,
            PathSeg::Index(..) => unreachable!("the grammar starts every path with a name"),
        }
    }

    /// The single name, if the path is one.
    pub fn as_ident(&self) -> Option<&Ident> {
        match self.segs.as_slice() {
            [PathSeg::Name(i)] => Some(i),
            _ => None,
        }
    }
}

/// One argument of a call.
#[derive(Debug, Clone, PartialEq)]
pub enum Arg {
    /// `value`
    Positional(Value),
    /// `name value`
    Named(Ident, Value),
}

/// `name(args)`
#[derive(Debug, Clone, PartialEq)]
pub struct Call {
    /// What is called.
    pub callee: Path,
    /// Its arguments.
    pub args: Vec<Arg>,
    /// The whole call.
    pub span: Span,
}

/// An entry of a list, optionally labelled: `p1: TP20_D2_L20`.
#[derive(Debug, Clone, PartialEq)]
pub struct ListEntry {
    /// The label.
    pub label: Option<Ident>,
    /// The value.
    pub value: Value,
}

/// A value with its span.
#[derive(Debug, Clone, PartialEq)]
pub struct Value {
    /// What kind of value.
    pub kind: ValueKind,
    /// Where.
    pub span: Span,
}

/// The value forms.
#[derive(Debug, Clone, PartialEq)]
pub enum ValueKind {
    /// `12.5 mm`, `3`
    Quantity(Quantity),
    /// `10 mm ± 0.1 mm`, `10 mm +0.2 mm -0.1 mm` (plus and minus as written, signed)
    Limits {
        /// The nominal value.
        nominal: Quantity,
        /// The upper deviation (signed as written).
        plus: Quantity,
        /// The lower deviation (signed as written; for `±` the negated plus).
        minus: Quantity,
    },
    /// `0 deg .. 105 deg`
    Range(Quantity, Quantity),
    /// `+z`: axis index 0..3 and sign.
    Direction {
        /// 0 for x, 1 for y, 2 for z.
        axis: u8,
        /// `true` for `-`.
        negative: bool,
    },
    /// `"text"`
    Str(Str),
    /// `(a, b, c)`
    Tuple(Vec<Value>),
    /// `[a, b: c]`
    List(Vec<ListEntry>),
    /// `{ key value, … }`
    Block(Vec<Prop>),
    /// `f(args)`
    Call(Call),
    /// `name`, `a.b`, `a[1].b`
    Path(Path),
}

/// `part name { … }`
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The part's name.
    pub name: Ident,
    /// Its statements.
    pub stmts: Vec<PartStmt>,
    /// The whole item.
    pub span: Span,
}

/// A statement inside a part.
#[derive(Debug, Clone, PartialEq)]
pub enum PartStmt {
    /// `units mm`
    Units(Ident),
    /// `stock box(120, 60, 40)`
    Stock(Call),
    /// `mesh "file.obj" { units in }`
    Mesh {
        /// The file, relative to this spec.
        path: Str,
        /// Options.
        props: Vec<Prop>,
        /// The statement.
        span: Span,
    },
    /// `cut hole h1 { … }` or `add boss b1 { … }`
    Cut {
        /// `true` for `add` (material added), `false` for `cut`.
        add: bool,
        /// The machining feature kind: hole, slot, pocket, step, boss.
        kind: Ident,
        /// Its name.
        name: Ident,
        /// Its parameters.
        props: Vec<Prop>,
        /// The statement.
        span: Span,
    },
    /// `face name = …`, `feature name = …`, `datum A = …`
    Named {
        /// Which of the three.
        what: NamedKind,
        /// The declared name.
        name: Ident,
        /// The faces; `None` when nothing follows the name.
        expr: Option<FaceExpr>,
        /// The statement.
        span: Span,
    },
    /// `frame DRF = [A, B, C]`
    Frame {
        /// The declared name.
        name: Ident,
        /// The datum references.
        refs: Vec<ListEntry>,
        /// The statement.
        span: Span,
    },
    /// `tolerance T1 = flatness(top, 0.05 mm)`
    Tolerance {
        /// The declared name.
        name: Ident,
        /// The call.
        call: Call,
        /// The statement.
        span: Span,
    },
}

/// Which named face statement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NamedKind {
    /// `face`
    Face,
    /// `feature`
    Feature,
    /// `datum`
    Datum,
}

/// `a + b + group "face_3"`
#[derive(Debug, Clone, PartialEq)]
pub struct FaceExpr {
    /// The terms, unioned.
    pub terms: Vec<FaceTerm>,
    /// The whole expression.
    pub span: Span,
}

/// One term of a face expression.
#[derive(Debug, Clone, PartialEq)]
pub enum FaceTerm {
    /// A name or path: `top`, `stock.top`, `grid[2].wall`.
    Path(Path),
    /// `group "face_12"`: a group of a mesh file.
    Group(Str),
    /// `segment 3`: a face found by segmenting an unlabelled mesh.
    Segment(u32, Span),
    /// `step_face 1234` or `qif_face 56`: a CAD file's face by the file's own id.
    FileFace(CadKind, u32, Span),
    /// `select(plane, normal +z, highest z)`
    Select(Vec<Arg>, Span),
}

/// `hierarchy name { … }`
#[derive(Debug, Clone, PartialEq)]
pub struct Hierarchy {
    /// Its name.
    pub name: Ident,
    /// Its levels in order of importance.
    pub levels: Vec<Level>,
    /// The whole item.
    pub span: Span,
}

/// One level of a hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub enum Level {
    /// `required approachability`
    Required(Ident, Span),
    /// `same_setup(T, *)`
    Same {
        /// `same_setup`, `same_probe` or `same_orient`.
        constraint: Ident,
        /// The group, e.g. `T`, `*`.
        group: Vec<Ident>,
        /// The whole level.
        span: Span,
    },
}

/// `plan name { … }`
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Its name.
    pub name: Ident,
    /// Its statements.
    pub stmts: Vec<PlanStmt>,
    /// The whole item.
    pub span: Span,
}

/// A statement of a plan.
#[derive(Debug, Clone, PartialEq)]
pub enum PlanStmt {
    /// `part f2`, `cmm lab`, `hierarchy …`, `sampling …`, `output { … }`
    Prop(Prop),
    /// `prefer setup +z weight 1` or `forbid setup -z`
    Pref {
        /// `true` for `forbid`.
        forbid: bool,
        /// `setup`, `orientation` or `probe`.
        kind: Ident,
        /// The setup direction, (A, B) pair or probe.
        value: Value,
        /// `weight 1.0`, `cost 2`
        opts: Vec<Prop>,
        /// The statement.
        span: Span,
    },
    /// `sample large_slot with hammersley(points 20)`
    Sample {
        /// The feature.
        feature: Path,
        /// The strategy.
        strategy: Value,
        /// The statement.
        span: Span,
    },
}

/// The kind of CAD file whose ids `step_face` and `qif_face` name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CadKind {
    /// STEP: the face's instance number (`#1234`).
    Step,
    /// QIF: the face's `id`.
    Qif,
}

impl CadKind {
    /// The kind of CAD file a path names, by its extension (`.stp`, `.step`, `.qif`);
    /// `None` for a mesh or anything else.
    pub fn of_path(path: &std::path::Path) -> Option<CadKind> {
        let ext = path.extension()?.to_string_lossy().to_ascii_lowercase();
        match ext.as_str() {
            "stp" | "step" => Some(CadKind::Step),
            "qif" => Some(CadKind::Qif),
            _ => None,
        }
    }

    /// The keyword that names a face of this kind of file.
    pub fn keyword(self) -> &'static str {
        match self {
            CadKind::Step => "step_face",
            CadKind::Qif => "qif_face",
        }
    }

    /// The file kind, in words.
    pub fn file(self) -> &'static str {
        match self {
            CadKind::Step => "STEP",
            CadKind::Qif => "QIF",
        }
    }
}
