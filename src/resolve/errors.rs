//! The resolver's diagnostics.

use crate::source::Span;

/// A name, unit, value or structure problem in a spec.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[allow(missing_docs)]
pub(crate) enum ResolveError {
    #[error("this zone per unit cannot be read: {problem}")]
    #[diagnostic(code(insp::resolve::per_unit))]
    PerUnit {
        #[label("here")]
        span: Span,
        problem: String,
        #[help]
        help: String,
    },
    #[error("unknown {what} `{name}`")]
    #[diagnostic(code(insp::resolve::unknown_name))]
    UnknownName {
        #[label("not found")]
        span: Span,
        what: String,
        name: String,
        #[help]
        help: String,
    },
    #[error("expected {expected}, found {found} `{name}`")]
    #[diagnostic(code(insp::resolve::wrong_kind))]
    WrongKind {
        #[label("this is {found}")]
        span: Span,
        name: String,
        expected: String,
        found: String,
        #[help]
        help: String,
    },
    #[error("`{name}` is declared twice")]
    #[diagnostic(code(insp::resolve::duplicate_name))]
    DuplicateName {
        #[label("declared again here")]
        span: Span,
        #[label("first declared here")]
        first: Option<Span>,
        name: String,
        #[help]
        help: String,
    },
    #[error("unknown property `{key}` for {item}")]
    #[diagnostic(code(insp::resolve::unknown_property))]
    UnknownProperty {
        #[label("not a property of {item}")]
        span: Span,
        key: String,
        item: String,
        #[help]
        help: String,
    },
    #[error("{item} needs `{key}`")]
    #[diagnostic(code(insp::resolve::missing_property))]
    MissingProperty {
        #[label("`{key}` is missing")]
        span: Span,
        key: String,
        item: String,
        #[help]
        help: String,
    },
    #[error("`{key}` is given twice")]
    #[diagnostic(code(insp::resolve::duplicate_property), help("remove one of them"))]
    DuplicateProperty {
        #[label("given again here")]
        span: Span,
        #[label("first given here")]
        first: Span,
        key: String,
    },
    #[error("expected {expected}, found {found}")]
    #[diagnostic(code(insp::resolve::type_mismatch))]
    TypeMismatch {
        #[label("expected {expected}")]
        span: Span,
        expected: String,
        found: String,
        #[help]
        help: String,
    },
    #[error("unknown unit `{unit}`")]
    #[diagnostic(code(insp::resolve::unknown_unit))]
    UnknownUnit {
        #[label("not a unit")]
        span: Span,
        unit: String,
        #[help]
        help: String,
    },
    #[error("expected {expected}, found {found} (`{unit}`)")]
    #[diagnostic(code(insp::resolve::unit_mismatch))]
    UnitMismatch {
        #[label("this is {found}")]
        span: Span,
        expected: String,
        found: String,
        unit: String,
        #[help]
        help: String,
    },
    #[error("`{value}` needs a unit")]
    #[diagnostic(code(insp::resolve::missing_unit))]
    MissingUnit {
        #[label("{expected} without a unit")]
        span: Span,
        value: String,
        expected: String,
        #[help]
        help: String,
    },
    #[error("{what} must be greater than zero, found {value}")]
    #[diagnostic(code(insp::resolve::non_positive))]
    NonPositive {
        #[label("not greater than zero")]
        span: Span,
        what: String,
        value: String,
        #[help]
        help: String,
    },
    #[error("feature `{feature}` asks for a laser scanner, and cmm `{cmm}` has none")]
    #[diagnostic(
        code(insp::resolve::no_scanner),
        help("add one to the machine's rack, `scanners [l1: std::scanners::LC15Dx]`, or measure `{feature}` by `touch`")
    )]
    NoScanner {
        #[label("no scanner on the machine")]
        span: Span,
        feature: String,
        cmm: String,
    },
    #[error("{what} {value} is out of range: {range}")]
    #[diagnostic(code(insp::resolve::out_of_range))]
    OutOfRange {
        #[label("out of range")]
        span: Span,
        what: String,
        value: String,
        range: String,
        #[help]
        help: String,
    },
    #[error("step {step} does not divide the {axis} range {range}")]
    #[diagnostic(code(insp::resolve::step_not_dividing))]
    StepNotDividing {
        #[label("does not divide {range}")]
        span: Span,
        step: String,
        axis: String,
        range: String,
        #[help]
        help: String,
    },
    #[error("angle {axis} = {value}° is outside head `{head}`'s range {range}")]
    #[diagnostic(code(insp::resolve::angle_out_of_range))]
    AngleOutOfRange {
        #[label("outside {range}")]
        span: Span,
        axis: String,
        value: String,
        head: String,
        range: String,
        #[help]
        help: String,
    },
    #[error("angle {axis} = {value}° is not on head `{head}`'s {step}° grid")]
    #[diagnostic(code(insp::resolve::off_grid))]
    OffGrid {
        #[label("between grid positions")]
        span: Span,
        axis: String,
        value: String,
        head: String,
        step: String,
        #[help]
        help: String,
    },
    #[error("head `{head}` is fixed: it has no orientations to prefer")]
    #[diagnostic(code(insp::resolve::fixed_head), help("orientation preferences need an indexable head such as `PH10MQ`; remove this line or change the head"))]
    FixedHead {
        #[label("needs an indexable head")]
        span: Span,
        head: String,
    },
    #[error("{kind} needs a datum reference")]
    #[diagnostic(code(insp::resolve::datums_required))]
    DatumsRequired {
        #[label("no datum given")]
        span: Span,
        kind: String,
        #[help]
        help: String,
    },
    #[error("{kind} takes no datum reference")]
    #[diagnostic(code(insp::resolve::datums_forbidden))]
    DatumsForbidden {
        #[label("remove this datum")]
        span: Span,
        kind: String,
        #[help]
        help: String,
    },
    #[error("tolerance on `{feature}` refers to datum `{datum}`, which is that same feature")]
    #[diagnostic(
        code(insp::resolve::datum_self_reference),
        help("a feature cannot be controlled relative to itself: refer to another datum")
    )]
    DatumSelfReference {
        #[label("`{datum}` is `{feature}`")]
        span: Span,
        datum: String,
        feature: String,
    },
    #[error("datum `{datum}` appears twice in the reference frame")]
    #[diagnostic(
        code(insp::resolve::duplicate_datum),
        help("each datum appears once: primary, secondary, tertiary")
    )]
    DuplicateDatum {
        #[label("again")]
        span: Span,
        datum: String,
    },
    #[error("{kind} takes {expected}, found {found}")]
    #[diagnostic(code(insp::resolve::arity))]
    Arity {
        #[label("{found}")]
        span: Span,
        kind: String,
        expected: String,
        found: String,
        #[help]
        help: String,
    },
    #[error("{kind} does not allow the `{modifier}` modifier")]
    #[diagnostic(code(insp::resolve::modifier_not_allowed))]
    ModifierNotAllowed {
        #[label("not allowed here")]
        span: Span,
        kind: String,
        modifier: String,
        #[help]
        help: String,
    },
    #[error("{kind} has no diameter (Ø) zone")]
    #[diagnostic(
        code(insp::resolve::diameter_zone),
        help("write the zone width without `dia`")
    )]
    DiameterZone {
        #[label("`dia` not allowed here")]
        span: Span,
        kind: String,
    },
    #[error("{kind} needs {what}")]
    #[diagnostic(code(insp::resolve::missing_argument))]
    MissingArgument {
        #[label("{what} missing")]
        span: Span,
        kind: String,
        what: String,
        #[help]
        help: String,
    },
    #[error("limits are inverted or empty: lower {lower} is not below upper {upper}")]
    #[diagnostic(code(insp::resolve::invalid_limits), help("write the deviations as `+upper -lower`, e.g. `10 mm +0.1 mm -0.05 mm`, with upper above lower"))]
    InvalidLimits {
        #[label("no size satisfies these limits")]
        span: Span,
        lower: String,
        upper: String,
    },
    #[error("feature `{name}` has no faces")]
    #[diagnostic(
        code(insp::resolve::empty_feature),
        help("list its faces: `feature {name} = stock.top + slot.walls`")
    )]
    EmptyFeature {
        #[label("no faces")]
        span: Span,
        name: String,
    },
    #[error("{owner} has no face `{role}`")]
    #[diagnostic(code(insp::resolve::unknown_face))]
    UnknownFace {
        #[label("no such face")]
        span: Span,
        owner: String,
        role: String,
        #[help]
        help: String,
    },
    #[error("{what} needs a mesh part")]
    #[diagnostic(code(insp::resolve::needs_mesh))]
    NeedsMesh {
        #[label("this part is built from stock")]
        span: Span,
        what: String,
        #[help]
        help: String,
    },
    #[error("{what} needs stock to work on")]
    #[diagnostic(code(insp::resolve::needs_stock), help("machining operations shape a `stock`; a mesh part's faces are named with `group`, `segment` or `select`"))]
    NeedsStock {
        #[label("this part is a mesh")]
        span: Span,
        what: String,
    },
    #[error("part `{part}` has no geometry")]
    #[diagnostic(
        code(insp::resolve::no_geometry),
        help("add `stock box(…)` (or `cylinder`, `sphere`) or `mesh \"file.stl\"`")
    )]
    NoGeometry {
        #[label("no `stock` or `mesh`")]
        span: Span,
        part: String,
    },
    #[error("part `{part}` has two geometry sources")]
    #[diagnostic(
        code(insp::resolve::duplicate_geometry),
        help("a part is either one stock with operations or one mesh")
    )]
    DuplicateGeometry {
        #[label("second source")]
        span: Span,
        #[label("first source")]
        first: Span,
        part: String,
    },
    #[error("output `{path}` would be written outside the spec's folder")]
    #[diagnostic(
        code(insp::resolve::output_outside),
        help("outputs a spec names stay in its folder or below: give a relative path without `..`; `inspc build -o` may write anywhere")
    )]
    OutputOutside {
        #[label("outside the spec's folder")]
        span: Span,
        path: String,
    },
    #[error("mesh file `{path}` not found")]
    #[diagnostic(
        code(insp::resolve::file_not_found),
        help("paths are relative to the folder of the spec that names them")
    )]
    FileNotFound {
        #[label("no such file")]
        span: Span,
        path: String,
    },
    #[error("unsupported mesh format `{ext}`")]
    #[diagnostic(
        code(insp::resolve::mesh_format),
        help("inspc reads STL (binary or ASCII), OBJ, STEP (.stp, .step) and QIF 3 (.qif) files")
    )]
    MeshFormat {
        #[label("not .stl, .obj, .stp or .qif")]
        span: Span,
        ext: String,
    },
    #[error("{kind} {op} with `{verb}`")]
    #[diagnostic(code(insp::resolve::wrong_operation))]
    WrongOperation {
        #[label("use `{fix}`")]
        span: Span,
        kind: String,
        op: String,
        verb: String,
        fix: String,
        #[help]
        help: String,
    },
    #[error("hierarchy `{name}` does not start with `required approachability`")]
    #[diagnostic(code(insp::resolve::hierarchy_required), help("every plan must reach every measurement: begin the hierarchy with `required approachability`"))]
    HierarchyRequired {
        #[label("missing required level")]
        span: Span,
        name: String,
    },
    #[error("`{level}` is ranked above `{above}`, which the solver cannot honour")]
    #[diagnostic(code(insp::resolve::hierarchy_order))]
    HierarchyOrder {
        #[label("ranked too high")]
        span: Span,
        level: String,
        above: String,
        #[help]
        help: String,
    },
    #[error("level `{level}` appears twice")]
    #[diagnostic(
        code(insp::resolve::duplicate_level),
        help("a level counts its violations once; remove the repeat")
    )]
    DuplicateLevel {
        #[label("repeated")]
        span: Span,
        #[label("first here")]
        first: Span,
        level: String,
    },
    #[error("unknown measurement group `({group})`")]
    #[diagnostic(code(insp::resolve::unknown_group), help("groups are `(T, F, *)` (a feature under a tolerance), `(T, *)` (a tolerance) and `(*, *)` (everything)"))]
    UnknownGroup {
        #[label("not a group")]
        span: Span,
        group: String,
    },
    #[error("a direction cannot be the zero vector")]
    #[diagnostic(
        code(insp::resolve::zero_vector),
        help("give a direction such as `+z` or `(0, 1, 1)`")
    )]
    ZeroVector {
        #[label("zero length")]
        span: Span,
    },
    #[error("stylus `{name}`'s stem ({stem} mm) is not thinner than its tip ({tip} mm)")]
    #[diagnostic(code(insp::resolve::stem_thicker_than_tip), severity(Warning), help("the stem would touch the part before the ball does on any flank; check the catalogue figures"))]
    StemThickerThanTip {
        #[label("stem diameter")]
        span: Span,
        name: String,
        stem: String,
        tip: String,
    },
    #[error("datum name `{name}` is not a datum letter")]
    #[diagnostic(
        code(insp::resolve::datum_letter),
        severity(Warning),
        help("ASME Y14.5 names datums with capital letters, not I, O or Q (`A`, `B`, … `AA`)")
    )]
    DatumLetter {
        #[label("not a datum letter")]
        span: Span,
        name: String,
    },
}

crate::diag::located!(ResolveError {
    PerUnit,
    UnknownName,
    WrongKind,
    DuplicateName,
    UnknownProperty,
    MissingProperty,
    DuplicateProperty,
    TypeMismatch,
    UnknownUnit,
    UnitMismatch,
    MissingUnit,
    NonPositive,
    OutOfRange,
    NoScanner,
    StepNotDividing,
    AngleOutOfRange,
    OffGrid,
    FixedHead,
    DatumsRequired,
    DatumsForbidden,
    DatumSelfReference,
    DuplicateDatum,
    Arity,
    ModifierNotAllowed,
    DiameterZone,
    MissingArgument,
    InvalidLimits,
    EmptyFeature,
    UnknownFace,
    NeedsMesh,
    NeedsStock,
    NoGeometry,
    DuplicateGeometry,
    FileNotFound,
    OutputOutside,
    MeshFormat,
    WrongOperation,
    HierarchyRequired,
    HierarchyOrder,
    DuplicateLevel,
    UnknownGroup,
    ZeroVector,
    StemThickerThanTip,
    DatumLetter,
});
