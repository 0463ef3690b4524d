//! The manual alignment of a setup (seed ch. 5.6): after the operator places the part,
//! the program cannot know where it is, so the operator touches a few points by hand —
//! 3 on a primary plane, 2 on a secondary, 1 on a tertiary (3-2-1) — and `DATSET` builds
//! the part's frame from them. Features are chosen among those the setup inspects:
//! datum features first in datum order, then features no tolerance reads against a datum
//! (a feature the frame is built on reads perfect in it), then the rest, the largest
//! faces first in each — the rest, and faces the setup measures only part of, only
//! where the others and the part's untouched faces leave something free ([`align`]); a
//! plane parallel to the table ranks with the datum the part rests on; a plane qualifies when its normal is a part axis, a cylinder
//! when its axis is, so that every feature maps onto `XDIR`/`YDIR`/`ZDIR` and
//! `XORIG`/`YORIG`/`ZORIG`. A secondary plane comes before a bore (it fixes the turn);
//! a cylinder along a fixed direction (a bore in the primary face) can stand in for the
//! origins across it, and where a datum bore will, a non-datum secondary plane gives
//! only its direction; a sphere gives all three origins. What the setup's features leave
//! free comes from other faces the operator touches by hand ([`complete`]) — with the
//! setup's own probe orientations, or on an indexable head with one the head indexes to
//! for that touch alone ([`Touchable::orient`]). Whatever stays free is named in
//! [`Alignment::missing`] and becomes an operator instruction.
//!
//! **Decision: every setup aligned on the part.** What the setup's own features leave
//! free is taken from other faces of the part the operator can touch ([`complete`]),
//! not left to the operator's squaring: the target is a part placed anywhere within ±5
//! mm and ±3°. Datum faces first, then faces no tolerance reads (a bowed toleranced
//! face would turn the frame the others are read in), then toleranced faces, each only
//! for degrees of freedom every frame of its location and profile tolerances fixes
//! (`LeftFree`: a frame fixes only what its datum features constrain, ASME Y14.5-2018
//! ch. 7; the evaluation reads what it leaves free in the alignment,
//! `geometry::drf`, so a face aligned on in such a degree of freedom would
//! read in place in it). The steps: the plane facing most nearly up, a plane across it
//! touched twice along it, one touch per free origin, a sphere's centre; each touch
//! checked with `Pose::approach`, points from the `spread` grid; each step carries its
//! own touches (`AlignStep::extra`). These faces are touched by hand only; the DCC
//! realignment keeps their manual features (measuring them under DCC would need paths
//! the planner never planned). On an indexable head the operator may also index the
//! head for such a touch: per probe of the setup, the grid orientation nearest each
//! part axis that no group takes (`path::join::align_orients`, within 20°), offered after the
//! setup's own orientations — a setup that measures one face from above otherwise has
//! nothing to fix its turn.
//!
//! **Decision: long lines, clear of edges.** A hand-touched secondary line is first
//! sought a tenth of the part long (5–50 mm, `long_line`) on a face no tolerance reads:
//! a touch's error over the line turns the frame (a 6.4 mm line beside a bore turned a
//! frame 0.45° for 0.05 mm), and a long line on a profiled face moves the frame with
//! the profile. Hand touches keep `HAND_EDGE` (5 mm) beyond the tip from the face's
//! edges where three touchable points remain that way. Where the measuring run starts
//! in another orientation than the last hand touch, the operator is told to raise the
//! probe first. What stays free is `insp::path::alignment_incomplete`.
//!
//! **Decision: what a setup aligns on.** A feature the frame is built on reads perfect
//! in it (a moved feature aligned on in a setup without its datums passed its profile),
//! so the setup first aligns without two kinds of block — a feature a tolerance reads
//! against datums, even when a datum shares its face (FTC 08's datum F is one of the
//! holes of a pattern located to D, B and C), and a face whose points the setup takes
//! only some of (the rest in another setup's frame) — completing from faces touched by
//! hand; only where that leaves a degree of freedom does it use them, and
//! `insp::path::self_aligned` warns. A plane parallel to the table ranks with the datum
//! plane the part rests on, just after its own table-plane touches: a side datum turned
//! 0.5° swings the far end of a long part millimetres (FTC 06 resting on A, framed on
//! B, drove the stylus into the part), while a plane parallel to A reads B's
//! perpendicularity and nothing else. Hand touches on a bore are circles spread round
//! it (one circle; two for a primary axis), not the four points farthest apart in
//! space, which can lie on one line and leave the centre across them unknown.

mod complete;

use super::{BlockPath, Hlip, SetupPath};
use crate::access::Contact;
use crate::geometry::{FaceId, Surface, P3, V3};
use crate::graph::Node;
use crate::model::FeatureId;
use crate::plan::Input;
use complete::complete;
use std::collections::BTreeSet;

/// A setup's alignment.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Alignment {
    /// The features touched by hand, in order.
    pub steps: Vec<AlignStep>,
    /// After `DATSET`, the origin shifts that restore the part frame: (axis, value).
    pub trans: Vec<(char, f64)>,
    /// What the features leave free, in words (empty for a full 3-2-1).
    pub missing: Vec<String>,
}

/// One feature of the alignment.
#[derive(Debug, Clone, PartialEq)]
pub struct AlignStep {
    /// The group (index into [`SetupPath::groups`]) whose sensor touches it.
    pub group: usize,
    /// The head's A and B where the touch takes another orientation than the group's
    /// (a face no group of the setup faces: the head indexes to touch it by hand).
    pub orient: Option<(f64, f64)>,
    /// The block in that group; `None` for a face the setup measures nothing on, touched
    /// by hand only ([`AlignStep::extra`]).
    pub block: Option<usize>,
    /// Points touched (indices into [`Hlip::points`]), for a block.
    pub points: Vec<usize>,
    /// A face outside the plan and its touches (contact point, outward normal): what the
    /// setup's own features leave free comes from such faces.
    pub extra: Option<ExtraFace>,
    /// What it fixes: `ZDIR`, `-XDIR`, `YORIG`, ….
    pub keywords: Vec<String>,
}

/// A face of the part the operator touches only to align it.
#[derive(Debug, Clone, PartialEq)]
pub struct ExtraFace {
    /// The face.
    pub face: FaceId,
    /// Its touches: contact point and outward normal (part frame).
    pub touches: Vec<(P3, V3)>,
}

pub(super) const AXES: [char; 3] = ['X', 'Y', 'Z'];

/// The part axis a unit vector lies along, and its sign.
pub(super) fn axis_of(v: &V3) -> Option<(usize, bool)> {
    (0..3)
        .find(|&k| v[k].abs() > 1.0 - 1e-9)
        .map(|k| (k, v[k] > 0.0))
}

pub(super) fn dir_word(k: usize, positive: bool) -> String {
    format!("{}{}DIR", if positive { "" } else { "-" }, AXES[k])
}

pub(super) fn orig_word(k: usize) -> String {
    format!("{}ORIG", AXES[k])
}

/// A candidate feature: its surface as the alignment sees it.
enum Shape {
    Plane {
        axis: usize,
        positive: bool,
        at: f64,
    },
    Cylinder {
        axis: usize,
        positive: bool,
        at: P3,
    },
    Sphere {
        at: P3,
    },
}

impl Shape {
    /// The feature's nominal coordinate along axis `k` (where its origin lands).
    fn at(&self, k: usize) -> f64 {
        match self {
            Shape::Plane { at, .. } => *at,
            Shape::Cylinder { at, .. } | Shape::Sphere { at } => at[k],
        }
    }
}

/// The first datum (index into the part's datums) with a planar face resting on the
/// table: outward normal straight down, its plane at the table's height.
fn resting_datum(input: &Input, up: V3, table: f64) -> Option<usize> {
    let part = &input.model.parts[input.plan.part.0];
    let graph = input.graph;
    let on_table = |face: &crate::geometry::FaceId| {
        matches!(
            input.geometry.faces.get(face.0).map(|f| &f.surface),
            Some(Surface::Plane { origin, normal })
                if normal.dot(&up) < -1.0 + 1e-9 && (origin.coords.dot(&up) - table).abs() < 1e-2
        )
    };
    let rests = |feature: FeatureId| {
        graph.nodes().any(|(i, n)| {
            matches!(n, Node::Feature { feature: f, .. } if *f == feature)
                && graph.children(i).iter().any(
                    |(c, _)| matches!(&graph.graph[*c], Node::Face { face, .. } if on_table(face)),
                )
        })
    };
    part.datums.iter().position(|d| rests(d.feature))
}

/// Where the operator can touch the part by hand with one group's probe: the tip's
/// radius, and whether a touch at a contact point with an outward normal is clear (the
/// probe held as the group holds it, or with the head indexed to `orient`, approaching
/// along the normal).
pub struct Touchable<'a> {
    /// The group (index into [`SetupPath::groups`]) whose probe it is.
    pub group: usize,
    /// The head's A and B where they are not the group's: an orientation the setup
    /// measures nothing in, taken only to touch a face the alignment needs.
    pub orient: Option<(f64, f64)>,
    /// The probe (rack slot): groups of one probe along one direction touch alike.
    pub probe: usize,
    /// The probe's direction, tip to head (part frame).
    pub dir: V3,
    /// The tip radius (mm).
    pub tip: f64,
    /// The check.
    pub clear: &'a dyn Fn(&P3, &V3) -> bool,
}

/// Chooses the alignment of one setup from its groups' blocks, completed from other
/// faces of the part where they leave something free. Two kinds of block are aligned
/// on only where the setup's other blocks and the part's other faces cannot fix all six
/// degrees of freedom: a feature whose tolerance reads it against datums (the frame
/// would move with it, and a shift or tilt of it would read as none: CTC 02's F51, the
/// secondary of a setup, read 0 under a profile shifted twice its zone), and a face
/// whose points this setup takes only some of (the rest taken in another setup's frame:
/// aligned on one end of a bore, the setup moves that end back to nominal and the fit
/// over both ends reads a tilt at half its size, CTC 02's datum H), and a face of a
/// feature a tolerance reads against datums the setup does not measure, whatever datum
/// shares the face (FTC 08's datum F, one hole of a pattern located to D, B, C: the
/// frame carried B and C over as drawn, and the pattern moved twice its zone read in).
/// A face touched by hand only is no worse a datum for the frame than a block the
/// program measures.
pub fn align(input: &Input, hlip: &Hlip, sp: &SetupPath, touch: &[Touchable]) -> Alignment {
    let without = align_on(input, hlip, sp, touch, false);
    if without.missing.is_empty() && !without.steps.is_empty() {
        return without;
    }
    align_on(input, hlip, sp, touch, true)
}

/// [`align`] with or without the blocks of features whose tolerances read them
/// against datums.
fn align_on(
    input: &Input,
    hlip: &Hlip,
    sp: &SetupPath,
    touch: &[Touchable],
    on_referenced: bool,
) -> Alignment {
    let cands = candidates(input, hlip, sp, on_referenced);
    let mut out = Alignment::default();
    let mut dirs: Vec<usize> = Vec::new();
    let mut origins = [false; 3];
    let mut free = Free {
        dirs: &mut dirs,
        origins: &mut origins,
    };
    steps_on_blocks(hlip, &cands, &mut out, &mut free);
    // A primary cylinder or a lone sphere when no plane qualifies.
    if out.steps.is_empty() {
        step_on_round(hlip, &cands, &mut out, &mut free);
    }
    let used_faces: Vec<FaceId> = out
        .steps
        .iter()
        .filter_map(|st| {
            let b = sp.groups.get(st.group)?.blocks.get(st.block?)?;
            (b.contact == Contact::Part).then_some(b.face)
        })
        .collect();
    let group = out.steps.first().map_or(0, |st| st.group);
    let up = hlip.setups[sp.setup].up;
    complete(input, up, group, &used_faces, touch, &mut out, &mut free);
    if dirs.is_empty() {
        out.missing.push("the part's orientation".into());
    } else if dirs.len() == 1 {
        out.missing
            .push(format!("the rotation about {}", AXES[dirs[0]]));
    }
    for k in 0..3 {
        if !origins[k] {
            out.missing.push(format!("the {} origin", AXES[k]));
        }
    }
    out
}

/// A block of the setup the alignment may stand on.
struct Candidate {
    /// (class, datum, stands in for it): datum features first in datum order (the datum
    /// itself before a plane parallel to the one it rests on), then features no
    /// tolerance reads against datums, then the rest.
    rank: (u8, usize, u8),
    /// The face's area, negated: the largest first.
    neg_area: f64,
    /// The group (index into [`SetupPath::groups`]).
    group: usize,
    /// The block in that group.
    block: usize,
    /// Its surface as the alignment sees it.
    shape: Shape,
    /// Its points, in tour order.
    points: Vec<usize>,
}

/// The setup's blocks the alignment may stand on, best first: by rank, then area, then
/// in block order. Without `on_referenced`, the blocks of features a tolerance reads
/// against datums are left out, and so are faces this setup measures only part of and
/// faces a frame this setup does not build would carry over.
fn candidates(input: &Input, hlip: &Hlip, sp: &SetupPath, on_referenced: bool) -> Vec<Candidate> {
    let geometry = input.geometry;
    // Features whose tolerances refer to datums: aligned on, such a feature sets the
    // frame its own tolerance is read in (moved, it would read perfect).
    let part = &input.model.parts[input.plan.part.0];
    let referenced: Vec<FeatureId> = part
        .tolerances
        .iter()
        .filter(|t| !t.datums.is_empty())
        .flat_map(|t| t.targets.iter().copied())
        .collect();
    // The first datum (in datum order) whose plane the part rests on: the table stands
    // in for it, so a plane parallel to the table ranks with it. Aligned on such a
    // plane, the frame turns with the datum the part sits on, not with a side face a
    // tilt of which would swing the far end of the part into the probe.
    let setup = &hlip.setups[sp.setup];
    let resting = resting_datum(input, setup.up, setup.table);
    let vertical = axis_of(&setup.up).map(|(k, _)| k);
    let carried = carried_faces(input, sp);
    let split = split_faces(hlip, sp);
    let mut cands = Vec::new();
    for (gi, g) in sp.groups.iter().enumerate() {
        for (bi, b) in g.blocks.iter().enumerate() {
            let points: Vec<usize> = b.touches.iter().map(|t| t.point).collect();
            let Some(&first) = points.first() else {
                continue;
            };
            let split = split.contains(&b.face);
            if (split || carried.contains(&b.face)) && !on_referenced && b.contact == Contact::Part
            {
                continue;
            }
            let Some(shape) = block_shape(input, hlip, b, first) else {
                continue;
            };
            let mut rank = match (b.datum, b.feature) {
                (Some(d), _) => (0, d.0, 0),
                (None, Some(f)) if referenced.contains(&f) => {
                    if !on_referenced {
                        continue;
                    }
                    (2, 0, 0)
                }
                _ => (1, 0, 0),
            };
            if let (Some(r), Shape::Plane { axis, .. }) = (resting, &shape) {
                if Some(*axis) == vertical {
                    rank = rank.min((0, r, 1));
                }
            }
            let area = geometry.faces.get(b.face.0).map_or(0.0, |f| f.area);
            cands.push(Candidate {
                rank,
                neg_area: -area,
                group: gi,
                block: bi,
                shape,
                points,
            });
        }
    }
    // Datum rank first, then area, then order.
    cands.sort_by(|a, b| {
        a.rank
            .cmp(&b.rank)
            .then(a.neg_area.total_cmp(&b.neg_area))
            .then((a.group, a.block).cmp(&(b.group, b.block)))
    });
    cands
}

/// Faces of features a tolerance reads against datums this setup does not measure
/// (a datum bore that is also one of a toleranced pattern's holes): the frame would
/// carry those datums over as drawn and move with the face.
fn carried_faces(input: &Input, sp: &SetupPath) -> Vec<FaceId> {
    let part = &input.model.parts[input.plan.part.0];
    let here_features = sp.features();
    part.tolerances
        .iter()
        .filter(|t| {
            !t.datums.is_empty()
                && !t
                    .datums
                    .iter()
                    .all(|d| here_features.contains(&part.datums[d.datum.0].feature))
        })
        .flat_map(|t| t.targets.iter())
        .flat_map(|f| faces_in_graph(input, *f))
        .collect()
}

/// The faces this setup measures only part of: other setups take points on them that
/// this one does not.
fn split_faces(hlip: &Hlip, sp: &SetupPath) -> BTreeSet<FaceId> {
    let here: BTreeSet<usize> = sp
        .groups
        .iter()
        .flat_map(|g| &g.blocks)
        .flat_map(|b| b.touches.iter().map(|t| t.point))
        .collect();
    points_elsewhere(hlip, sp.setup)
        .into_iter()
        .filter(|(_, pts)| pts.iter().any(|p| !here.contains(p)))
        .map(|(face, _)| face)
        .collect()
}

/// The surface the alignment sees in block `b` (its first point `first`): the table's
/// plane there, or the block's face where its normal or axis is a part axis (any
/// sphere); `None` for anything else.
fn block_shape(input: &Input, hlip: &Hlip, b: &BlockPath, first: usize) -> Option<Shape> {
    if b.contact == Contact::Table {
        let p = &hlip.points[first];
        return axis_of(&p.normal).map(|(axis, positive)| Shape::Plane {
            axis,
            positive,
            at: p.position[axis],
        });
    }
    match input.geometry.faces.get(b.face.0).map(|f| &f.surface) {
        Some(Surface::Plane { origin, normal }) => {
            axis_of(normal).map(|(axis, positive)| Shape::Plane {
                axis,
                positive,
                at: origin[axis],
            })
        }
        Some(Surface::Cylinder { origin, axis, .. }) => {
            axis_of(axis).map(|(k, positive)| Shape::Cylinder {
                axis: k,
                positive,
                at: *origin,
            })
        }
        Some(Surface::Sphere { center, .. }) => Some(Shape::Sphere { at: *center }),
        _ => None,
    }
}

/// What a step fixes.
struct Fix {
    /// Its keywords: `ZDIR`, `XORIG`, ….
    keywords: Vec<String>,
    /// How many points it touches.
    points: usize,
    /// The origins it fixes (part axes).
    origins: Vec<usize>,
    /// The direction it fixes.
    dir: Option<usize>,
}

/// The steps the setup's own blocks give, stage by stage — a primary (0), a secondary
/// (1), tertiaries (2) — each the first candidate in order that fixes something still
/// free and whose points can show it.
fn steps_on_blocks(hlip: &Hlip, cands: &[Candidate], out: &mut Alignment, free: &mut Free) {
    let mut used = vec![false; cands.len()];
    let is_datum = |ci: usize| cands[ci].rank.0 == 0;
    let datum_bore = |primary: usize| {
        cands.iter().any(|c| {
            c.rank.0 == 0
                && c.points.len() >= 4
                && matches!(c.shape, Shape::Cylinder { axis, .. } if axis == primary)
        })
    };
    // A secondary plane fixes the turn about the primary that a bore cannot: planes are
    // tried first there, whatever their rank.
    let passes = |stage: usize| if stage == 1 { 2 } else { 1 };
    for stage in 0..3 {
        let order = (0..passes(stage)).flat_map(|pass| {
            cands.iter().enumerate().filter(move |(_, c)| {
                passes(stage) == 1 || (pass == 0) == matches!(c.shape, Shape::Plane { .. })
            })
        });
        for (ci, c) in order {
            if used[ci] {
                continue;
            }
            let Some(fix) = stage_fix(stage, &c.shape, free, is_datum(ci), &datum_bore) else {
                continue;
            };
            if fix.keywords.is_empty() {
                continue;
            }
            let primary = free.dirs.first().copied();
            let Some(points) = stage_points(hlip, stage, &c.shape, &c.points, fix.points, primary)
            else {
                continue;
            };
            used[ci] = true;
            free.dirs.extend(fix.dir);
            for k in fix.origins {
                free.origins[k] = true;
                out.trans.push((AXES[k], c.shape.at(k)));
            }
            out.steps.push(AlignStep {
                group: c.group,
                orient: None,
                block: Some(c.block),
                points,
                extra: None,
                keywords: fix.keywords,
            });
            break;
        }
    }
}

/// What a candidate of surface `shape` fixes at `stage`, given what `free` says is
/// fixed; `None` where it fixes nothing there. `is_datum`: whether it is a datum
/// feature's; `datum_bore(axis)`: whether a datum bore runs along part axis `axis`.
fn stage_fix(
    stage: usize,
    shape: &Shape,
    free: &Free,
    is_datum: bool,
    datum_bore: &dyn Fn(usize) -> bool,
) -> Option<Fix> {
    let dirs: &Vec<usize> = free.dirs;
    let origins: &[bool; 3] = free.origins;
    let free_origins = |skip: Option<usize>| -> Vec<usize> {
        (0..3).filter(|&k| Some(k) != skip && !origins[k]).collect()
    };
    let plane = |axis: usize, positive: bool, points: usize| Fix {
        keywords: vec![dir_word(axis, positive), orig_word(axis)],
        points,
        origins: vec![axis],
        dir: Some(axis),
    };
    let centre = |o: Vec<usize>| Fix {
        keywords: o.iter().map(|&k| orig_word(k)).collect(),
        points: 4,
        origins: o,
        dir: None,
    };
    Some(match (stage, shape) {
        (0, Shape::Plane { axis, positive, .. }) => plane(*axis, *positive, 3),
        // A plane that is no datum gives only its direction where a datum
        // bore along the primary will place the origins across it.
        (1, Shape::Plane { axis, positive, .. })
            if !dirs.contains(axis) && dirs.len() == 1 && !is_datum && datum_bore(dirs[0]) =>
        {
            Fix {
                keywords: vec![dir_word(*axis, *positive)],
                points: 2,
                origins: vec![],
                dir: Some(*axis),
            }
        }
        (1, Shape::Plane { axis, positive, .. }) if !dirs.contains(axis) && dirs.len() == 1 => {
            plane(*axis, *positive, 2)
        }
        (2, Shape::Plane { axis, .. }) if !origins[*axis] && dirs.len() == 2 => Fix {
            keywords: vec![orig_word(*axis)],
            points: 1,
            origins: vec![*axis],
            dir: None,
        },
        (1, Shape::Cylinder { axis, .. }) if *dirs == [*axis] => centre(free_origins(Some(*axis))),
        // A bore along one of the directions places the origins left free
        // across it (a plane and its edge, then a hole for the last one).
        (2, Shape::Cylinder { axis, .. }) if dirs.contains(axis) => {
            centre(free_origins(Some(*axis)))
        }
        (2, Shape::Sphere { .. }) => centre(free_origins(None)),
        _ => return None,
    })
}

/// The `n` points of `pts` a step at `stage` touches on a candidate of surface `shape`;
/// `primary` is the direction fixed first. `None` when its points cannot show what it
/// fixes.
fn stage_points(
    hlip: &Hlip,
    stage: usize,
    shape: &Shape,
    pts: &[usize],
    n: usize,
    primary: Option<usize>,
) -> Option<Vec<usize>> {
    match (stage, shape, primary) {
        (1, Shape::Plane { axis, .. }, Some(p)) => secondary_pair(hlip, pts, p, *axis),
        (_, Shape::Cylinder { axis, .. }, _) => round(hlip, pts, *axis, 1, n),
        // A primary plane: the widest triangle of its points (the farthest ones
        // may lie on one line, which fixes no plane).
        (0, Shape::Plane { .. }, _) => {
            let pos: Vec<P3> = pts.iter().map(|&k| hlip.points[k].position).collect();
            widest_triangle(&pos).map(|t| t.iter().map(|&i| pts[i]).collect())
        }
        _ => spread(hlip, pts, n),
    }
}

/// A secondary plane's two points (of `pts`, square to part axis `axis`): the pair
/// farthest apart along it, across the primary direction `primary` — two points one
/// above the other say nothing of the turn about it. `None` when no pair is 1 µm apart
/// that way.
fn secondary_pair(hlip: &Hlip, pts: &[usize], primary: usize, axis: usize) -> Option<Vec<usize>> {
    let along = V3::ith(primary, 1.0).cross(&V3::ith(axis, 1.0));
    let pos = |k: usize| hlip.points[k].position;
    let mut best: Option<(f64, [usize; 2])> = None;
    for (i, &a) in pts.iter().enumerate() {
        for &b in &pts[i + 1..] {
            let d = (pos(b) - pos(a)).dot(&along).abs();
            if best.is_none_or(|(x, _)| d > x + 1e-9) {
                best = Some((d, [a, b]));
            }
        }
    }
    match best {
        Some((d, pair)) if d > 1e-3 => Some(pair.to_vec()),
        _ => None,
    }
}

/// The step on a primary cylinder (its direction, from two circles, and the origins
/// across it) or a lone sphere (the three origins) of the setup's blocks, for a setup
/// where no plane qualifies.
fn step_on_round(hlip: &Hlip, cands: &[Candidate], out: &mut Alignment, free: &mut Free) {
    for c in cands {
        let (shape, pts) = (&c.shape, &c.points);
        let (keywords, fixed): (Vec<String>, Vec<usize>) = match shape {
            Shape::Cylinder { axis, positive, .. } => {
                let o: Vec<usize> = (0..3).filter(|k| k != axis).collect();
                let mut w = vec![dir_word(*axis, *positive)];
                w.extend(o.iter().map(|&k| orig_word(k)));
                (w, o)
            }
            Shape::Sphere { .. } => ((0..3).map(orig_word).collect(), (0..3).collect()),
            Shape::Plane { .. } => continue,
        };
        // A circle takes 3 touches, a sphere 4: a block of fewer (one of a
        // surface's split touches) aligns nothing.
        let need = if matches!(shape, Shape::Sphere { .. }) {
            4
        } else {
            3
        };
        if pts.len() < need {
            continue;
        }
        let points = match shape {
            // Its direction needs two circles.
            Shape::Cylinder { axis, .. } => round(hlip, pts, *axis, 2, 3),
            _ => spread(hlip, pts, 4.min(pts.len())),
        };
        let Some(points) = points else {
            continue;
        };
        if let Shape::Cylinder { axis, .. } = shape {
            free.dirs.push(*axis);
        }
        for k in fixed {
            free.origins[k] = true;
            out.trans.push((AXES[k], shape.at(k)));
        }
        out.steps.push(AlignStep {
            group: c.group,
            orient: None,
            block: Some(c.block),
            points,
            extra: None,
            keywords,
        });
        break;
    }
}

/// `n` of `pts`, each as far as it can be from those chosen before (positions seen
/// through `view`: a bore's points are spread by their angle about its axis).
fn spread_by(hlip: &Hlip, pts: &[usize], n: usize, view: &dyn Fn(&P3) -> P3) -> Option<Vec<usize>> {
    if pts.len() < n {
        return None;
    }
    let pos = |k: usize| view(&hlip.points[k].position);
    let mut chosen = vec![pts[0]];
    while chosen.len() < n {
        let next = pts
            .iter()
            .filter(|k| !chosen.contains(k))
            .max_by(|&&a, &&b| {
                let d = |x: usize| {
                    chosen
                        .iter()
                        .map(|&c| (pos(x) - pos(c)).norm())
                        .fold(f64::INFINITY, f64::min)
                };
                d(a).total_cmp(&d(b)).then(b.cmp(&a))
            })?;
        chosen.push(*next);
    }
    Some(chosen)
}

/// `n` of `pts`, each as far as it can be from those chosen before.
fn spread(hlip: &Hlip, pts: &[usize], n: usize) -> Option<Vec<usize>> {
    spread_by(hlip, pts, n, &|p: &P3| *p)
}

/// A bore touched by hand: circles of `per_level` points at `levels` heights along
/// its axis (most-touched heights first), each circle's points spread round it; the
/// points of one height alone say nothing of the centre across them.
fn round(
    hlip: &Hlip,
    pts: &[usize],
    axis: usize,
    levels: usize,
    per_level: usize,
) -> Option<Vec<usize>> {
    let mut by_level: Vec<(i64, Vec<usize>)> = Vec::new();
    for &k in pts {
        let h = (hlip.points[k].position[axis] * 1e3).round() as i64;
        match by_level.iter_mut().find(|(x, _)| *x == h) {
            Some((_, v)) => v.push(k),
            None => by_level.push((h, vec![k])),
        }
    }
    by_level.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
    let flat = |p: &P3| {
        let mut q = *p;
        q[axis] = 0.0;
        q
    };
    let mut out = Vec::new();
    for (_, at) in by_level.iter().take(levels) {
        out.extend(spread_by(hlip, at, per_level.min(at.len()).max(3), &flat)?);
    }
    (by_level.len() >= levels).then_some(out)
}

/// Per face, the points other setups than `setup` take on it.
fn points_elsewhere(hlip: &Hlip, setup: usize) -> std::collections::BTreeMap<FaceId, Vec<usize>> {
    let mut out: std::collections::BTreeMap<FaceId, Vec<usize>> = Default::default();
    let visits = hlip
        .setups
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != setup)
        .flat_map(|(_, s)| &s.probes)
        .flat_map(|p| &p.orients)
        .flat_map(|o| &o.inspections)
        .flat_map(|i| &i.faces)
        .filter(|v| v.contact == Contact::Part);
    for v in visits {
        out.entry(v.face)
            .or_default()
            .extend(v.points.iter().copied());
    }
    out
}

/// What an alignment has fixed so far: directions (part axes) and origins.
pub(super) struct Free<'a> {
    pub(super) dirs: &'a mut Vec<usize>,
    pub(super) origins: &'a mut [bool; 3],
}

/// The faces the measurement graph gives feature `f`.
pub(super) fn faces_in_graph(input: &Input, f: FeatureId) -> Vec<FaceId> {
    let graph = input.graph;
    graph
        .nodes()
        .filter(|(_, n)| matches!(n, Node::Feature { feature, .. } if *feature == f))
        .flat_map(|(i, _)| graph.children(i))
        .filter_map(|(c, _)| match &graph.graph[c] {
            Node::Face { face, .. } => Some(*face),
            _ => None,
        })
        .collect()
}

/// Three of `p` (indices) spanning a wide triangle: the farthest from the first, the
/// one farthest from the line through those two, then the first point moved to the one
/// farthest from the line through the other two. `None` when every point lies on one
/// line (less than 25 mm² of triangle).
fn widest_triangle(p: &[P3]) -> Option<[usize; 3]> {
    if p.len() < 3 {
        return None;
    }
    let far = |from: usize| {
        (0..p.len())
            .max_by(|&a, &b| {
                (p[a] - p[from])
                    .norm()
                    .total_cmp(&(p[b] - p[from]).norm())
                    .then(b.cmp(&a))
            })
            .unwrap_or(0)
    };
    let area = |a: usize, b: usize, c: usize| (p[b] - p[a]).cross(&(p[c] - p[a])).norm();
    let third = |a: usize, b: usize| {
        (0..p.len())
            .max_by(|&x, &y| area(a, b, x).total_cmp(&area(a, b, y)).then(y.cmp(&x)))
            .unwrap_or(0)
    };
    let a = far(0);
    let b = far(a);
    let c = third(a, b);
    let a = third(b, c);
    (area(a, b, c) > 25.0 && a != b && b != c && a != c).then_some([a, b, c])
}
