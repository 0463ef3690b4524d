//! The manual alignment completed from faces the setup does not measure (seed ch. 5.6):
//! where the setup's own features leave degrees of freedom free, the operator touches
//! other planes of the part by hand — a primary, a secondary, tertiaries — or a sphere,
//! with one of the setup's probes held as a group holds it or indexed for the touch.

use super::{
    axis_of, dir_word, faces_in_graph, orig_word, AlignStep, Alignment, ExtraFace, Free, Touchable,
    AXES,
};
use crate::geometry::{FaceId, PartGeometry, Surface, P3, V3};
use crate::model::{FeatureId, SampleMethod, Strategy};
use crate::plan::Input;
use crate::sample::{Fpoint, Sampler};
use std::cell::RefCell;
use std::collections::BTreeMap;

/// Completes an alignment from faces the setup does not measure: the plane that fixes
/// what is free (datum faces first, then faces no tolerance reads, then toleranced
/// faces for what their frames fix ([`LeftFree`]), the largest first in each), touched
/// where the operator can reach it with one of the setup's probe orientations (the
/// first step's first) — 3 touches on a primary, 2 along a secondary (across the
/// primary direction, as far apart as the face allows), 1 near the middle of a
/// tertiary. Nothing then depends on the operator
/// squaring the part or placing it at a nominal position: the 3-2-1 alignment of
/// coordinate metrology (Hocken & Pereira, *Coordinate Measuring Machines and
/// Systems*, 2nd ed., §13.3: a part coordinate system takes all six degrees of
/// freedom from features of the part).
pub(super) fn complete(
    input: &Input,
    up: V3,
    group: usize,
    used: &[FaceId],
    touch: &[Touchable],
    out: &mut Alignment,
    free: &mut Free,
) {
    let hand = HandTouch::new(input, up, group, used, touch);
    let mut taken: Vec<FaceId> = Vec::new();
    if free.dirs.is_empty() {
        hand_primary(&hand, up, out, free, &mut taken);
    }
    hand_secondary(&hand, out, free, &mut taken);
    // Tertiaries: one touch for each origin still free, once the frame's directions
    // are fixed.
    if free.dirs.len() >= 2 {
        hand_tertiaries(&hand, out, free, &mut taken);
    }
    for &gi in &hand.order {
        if let Some((f, pts, keywords, trans)) =
            sphere_origins(hand.g, &|f| hand.reachable(f, gi), free)
        {
            hand.push(out, gi, f, pts, keywords);
            out.trans.extend(trans);
            break;
        }
    }
}

/// What the operator can touch by hand on faces the setup does not measure: the
/// candidate planes, the groups whose probes may touch them, and the points each
/// probe reaches on a face.
struct HandTouch<'a> {
    g: &'a PartGeometry,
    touch: &'a [Touchable<'a>],
    left_free: LeftFree,
    /// Planes along a part axis, not facing the table — (face, axis, facing along it,
    /// its coordinate there) — datum faces first, then faces no tolerance reads, then
    /// toleranced faces, each the largest first.
    planes: Vec<(FaceId, usize, bool, f64)>,
    datum_faces: Vec<FaceId>,
    toleranced: Vec<FaceId>,
    /// The groups whose probe the operator may touch with: the first step's, then the
    /// setup's others in order (the writer selects each step's sensor).
    order: Vec<usize>,
    sampler: Sampler<'a>,
    /// A sampler keeping [`HAND_EDGE`] in from the faces' edges.
    inside: Sampler<'a>,
    strategy: Strategy,
    /// The samples of each face sampled so far.
    samples: RefCell<BTreeMap<FaceId, FaceSamples>>,
}

/// A face's samples for hand touches: those in from its edges, and all of them.
type FaceSamples = (Vec<Fpoint>, Vec<Fpoint>);

impl<'a> HandTouch<'a> {
    fn new(
        input: &Input<'a>,
        up: V3,
        group: usize,
        used: &[FaceId],
        touch: &'a [Touchable<'a>],
    ) -> HandTouch<'a> {
        let g = input.geometry;
        let part = &input.model.parts[input.plan.part.0];
        let datum_features: Vec<FeatureId> = part.datums.iter().map(|d| d.feature).collect();
        let left_free = LeftFree::of(input);
        // Candidate planes: along a part axis, not facing the table, by area.
        let mut planes: Vec<(FaceId, usize, bool, f64)> = g
            .faces
            .iter()
            .enumerate()
            .filter(|(i, _)| !used.contains(&FaceId(*i)))
            .filter_map(|(i, f)| match &f.surface {
                Surface::Plane { normal, origin } if normal.dot(&up) > -1e-6 => {
                    axis_of(normal).map(|(k, pos)| (FaceId(i), k, pos, origin[k]))
                }
                _ => None,
            })
            .collect();
        // Datum faces first, then faces no tolerance reads (a deviation of a toleranced
        // face would move the frame the others are read in), each the largest first.
        let datum_faces: Vec<FaceId> = datum_features
            .iter()
            .flat_map(|f| faces_in_graph(input, *f))
            .collect();
        let toleranced: Vec<FaceId> = part
            .tolerances
            .iter()
            .flat_map(|t| t.targets.iter())
            .flat_map(|f| faces_in_graph(input, *f))
            .collect();
        let rank = |f: FaceId| face_rank(&datum_faces, &toleranced, f);
        planes.sort_by(|a, b| {
            rank(a.0)
                .cmp(&rank(b.0))
                .then(g.faces[b.0 .0].area.total_cmp(&g.faces[a.0 .0].area))
                .then(a.0.cmp(&b.0))
        });
        let largest_tip = touch.iter().map(|t| t.tip).fold(0.0, f64::max);
        HandTouch {
            g,
            touch,
            left_free,
            planes,
            datum_faces,
            toleranced,
            order: touch_order(touch, group),
            sampler: Sampler::new(g, largest_tip + 1.0),
            inside: Sampler::new(g, largest_tip + HAND_EDGE),
            strategy: Strategy {
                method: SampleMethod::Uniform,
                points: Some(25),
                inset: None,
                spacing: None,
            },
            samples: RefCell::new(BTreeMap::new()),
        }
    }

    /// 0 for a datum face, 1 for a face no tolerance reads, 2 for a toleranced face.
    fn rank(&self, f: FaceId) -> u8 {
        face_rank(&self.datum_faces, &self.toleranced, f)
    }

    /// The points of face `f` group `gi`'s probe can touch: the face's samples (once a
    /// face), those the stylus does not stand behind, then those whose approach is clear
    /// — kept [`HAND_EDGE`] in from the face's edges where three such remain, since a
    /// joystick touch lands a few millimetres from where the controller shows it.
    fn reachable(&self, f: FaceId, gi: usize) -> Vec<(P3, V3)> {
        let t = &self.touch[gi];
        let mut samples = self.samples.borrow_mut();
        let (near_middle, all) = samples.entry(f).or_insert_with(|| {
            (
                self.inside.sample(f, &self.strategy),
                self.sampler.sample(f, &self.strategy),
            )
        });
        let touchable = |pts: &[Fpoint]| -> Vec<(P3, V3)> {
            pts.iter()
                .filter(|p| p.normal.dot(&t.dir) > BEHIND)
                .filter(|p| (t.clear)(&p.tip_centre(t.tip), &p.normal))
                .map(|p| (p.position, p.normal))
                .collect()
        };
        let inner = touchable(near_middle);
        if inner.len() >= 3 {
            inner
        } else {
            touchable(all)
        }
    }

    /// Adds the step of touches `touches` on `face` with group `gi`'s probe.
    fn push(
        &self,
        out: &mut Alignment,
        gi: usize,
        face: FaceId,
        touches: Vec<(P3, V3)>,
        keywords: Vec<String>,
    ) {
        out.steps.push(AlignStep {
            group: self.touch[gi].group,
            orient: self.touch[gi].orient,
            block: None,
            points: Vec::new(),
            extra: Some(ExtraFace { face, touches }),
            keywords,
        });
    }
}

/// A face's rank among faces touched by hand: 0 for a datum face, 1 for a face no
/// tolerance reads, 2 for a toleranced face.
fn face_rank(datum_faces: &[FaceId], toleranced: &[FaceId], f: FaceId) -> u8 {
    if datum_faces.contains(&f) {
        0
    } else if toleranced.contains(&f) {
        2
    } else {
        1
    }
}

/// The touchables (indices into `touch`) the operator may touch with, one per probe and
/// direction: group `group`'s first, then the others in order.
fn touch_order(touch: &[Touchable], group: usize) -> Vec<usize> {
    let mut order: Vec<usize> = Vec::new();
    for gi in std::iter::once(group).chain(0..touch.len()) {
        let same = |o: &usize| {
            touch[*o].probe == touch[gi].probe && (touch[*o].dir - touch[gi].dir).norm() < 1e-6
        };
        if gi < touch.len() && !order.iter().any(same) {
            order.push(gi);
        }
    }
    order
}

/// A primary touched by hand: the plane facing most nearly up (a setup on a sine plate
/// has no face straight up), the largest first among equals, 3 touches spanning it.
fn hand_primary(
    hand: &HandTouch,
    up: V3,
    out: &mut Alignment,
    free: &mut Free,
    taken: &mut Vec<FaceId>,
) {
    let facing = |k: usize, pos: bool| if pos { up[k] } else { -up[k] };
    let mut primaries: Vec<_> = hand.planes.clone();
    primaries.sort_by(|a, b| {
        let (fa, fb) = (facing(a.1, a.2), facing(b.1, b.2));
        (fb * 1e3).round().total_cmp(&(fa * 1e3).round())
    });
    for &gi in &hand.order {
        for &(f, k, pos, at) in &primaries {
            if !hand.left_free.may_fix(f, &Fixes::primary(k)) {
                continue;
            }
            let pts = hand.reachable(f, gi);
            let Some(chosen) = farthest(&pts, 3) else {
                continue;
            };
            if !spans_plane(&chosen) {
                continue;
            }
            hand.push(out, gi, f, chosen, vec![dir_word(k, pos), orig_word(k)]);
            free.dirs.push(k);
            free.origins[k] = true;
            out.trans.push((AXES[k], at));
            taken.push(f);
            return;
        }
    }
}

/// A secondary touched by hand: a plane across the primary, two touches along it —
/// first only lines long enough for the part ([`long_line`]) on faces no tolerance
/// reads (a toleranced face moved within its zone would carry the frame and its moves
/// with it), then any of [`SHORTEST_LINE`] or more in the usual order.
fn hand_secondary(hand: &HandTouch, out: &mut Alignment, free: &mut Free, taken: &mut Vec<FaceId>) {
    let long = long_line(hand.g);
    for (least, toleranced) in [(long, false), (SHORTEST_LINE, true)] {
        if free.dirs.len() != 1 {
            break;
        }
        let p = free.dirs[0];
        let tries = hand
            .order
            .iter()
            .flat_map(|&gi| hand.planes.iter().map(move |pl| (gi, pl)));
        for (gi, &(f, k, pos, at)) in tries {
            if k == p || taken.contains(&f) || (!toleranced && hand.rank(f) == 2) {
                continue;
            }
            let fixes = Fixes {
                turns: vec![p],
                moves: if free.origins[k] { vec![] } else { vec![k] },
            };
            if !hand.left_free.may_fix(f, &fixes) {
                continue;
            }
            let along = V3::ith(p, 1.0).cross(&V3::ith(k, 1.0));
            let pts = hand.reachable(f, gi);
            let Some((_, [i, j])) = longest_pair(&pts, &along).filter(|b| b.0 >= least) else {
                continue;
            };
            let mut keywords = vec![dir_word(k, pos)];
            if !free.origins[k] {
                keywords.push(orig_word(k));
                free.origins[k] = true;
                out.trans.push((AXES[k], at));
            }
            hand.push(out, gi, f, vec![pts[i], pts[j]], keywords);
            free.dirs.push(k);
            taken.push(f);
            break;
        }
    }
}

/// The two of `pts` (indices) farthest apart along `along`, and how far.
fn longest_pair(pts: &[(P3, V3)], along: &V3) -> Option<(f64, [usize; 2])> {
    let mut best: Option<(f64, [usize; 2])> = None;
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            let d = (pts[j].0 - pts[i].0).dot(along).abs();
            if best.is_none_or(|(x, _)| d > x + 1e-9) {
                best = Some((d, [i, j]));
            }
        }
    }
    best
}

/// Tertiaries touched by hand: for each origin still free, one touch near the middle of
/// a plane square to it.
fn hand_tertiaries(
    hand: &HandTouch,
    out: &mut Alignment,
    free: &mut Free,
    taken: &mut Vec<FaceId>,
) {
    for (k, axis) in AXES.iter().enumerate() {
        if free.origins[k] {
            continue;
        }
        let tries = hand
            .order
            .iter()
            .flat_map(|&gi| hand.planes.iter().map(move |pl| (gi, pl)));
        for (gi, &(f, kk, _, at)) in tries {
            let fixes = Fixes {
                turns: vec![],
                moves: vec![k],
            };
            if kk != k || taken.contains(&f) || !hand.left_free.may_fix(f, &fixes) {
                continue;
            }
            let pts = hand.reachable(f, gi);
            let c = hand.g.faces[f.0].centroid;
            let Some(&p) = pts
                .iter()
                .min_by(|a, b| (a.0 - c).norm().total_cmp(&(b.0 - c).norm()))
            else {
                continue;
            };
            hand.push(out, gi, f, vec![p], vec![orig_word(k)]);
            free.origins[k] = true;
            out.trans.push((*axis, at));
            taken.push(f);
            break;
        }
    }
}

/// The least cosine between a face's outward normal and the probe's direction (tip to
/// head) at which the probe may touch it: below, the stylus stands behind the face (a
/// face under an overhang for a vertical stylus), and no pose need be checked.
const BEHIND: f64 = -0.3;

/// The degrees of freedom a face touched by hand fixes: turns about part axes and
/// moves along them.
struct Fixes {
    turns: Vec<usize>,
    moves: Vec<usize>,
}

impl Fixes {
    /// A primary plane square to axis `k`: the turns about the other two, the move
    /// along `k`.
    fn primary(k: usize) -> Fixes {
        Fixes {
            turns: (0..3).filter(|&j| j != k).collect(),
            moves: vec![k],
        }
    }
}

/// Per face, what the datum reference frames of its location and profile tolerances
/// leave free: (moves, turns). A frame fixes only the degrees of freedom its datum
/// features constrain (ASME Y14.5-2018, ch. 7: a primary plane alone leaves the moves
/// along it and the turn about its normal free); the evaluation reads what is left in
/// the program's alignment ([`crate::geometry::drf`]), so a face aligned on in a
/// degree of freedom its own frame leaves free would read in place in it. Form and
/// orientation tolerances do not depend on the alignment, nor do those of datum
/// features (the frame is built on them).
struct LeftFree {
    faces: Vec<(FaceId, Vec<V3>, Vec<V3>)>,
}

impl LeftFree {
    fn of(input: &Input) -> LeftFree {
        use crate::geometry::cmm_fit::Shape as Fitted;
        use crate::model::TolKind;
        let part = &input.model.parts[input.plan.part.0];
        let datum_features: Vec<FeatureId> = part.datums.iter().map(|d| d.feature).collect();
        let nominal = |f: FeatureId| -> Option<Fitted> {
            let face = *faces_in_graph(input, f).first()?;
            Fitted::of_surface(&input.geometry.faces.get(face.0)?.surface).map(|x| x.0)
        };
        let mut faces = Vec::new();
        for t in &part.tolerances {
            let located = matches!(
                t.kind,
                TolKind::Position
                    | TolKind::Concentricity
                    | TolKind::Coaxiality
                    | TolKind::Symmetry
                    | TolKind::ProfileLine
                    | TolKind::ProfileSurface
            );
            if t.datums.is_empty() || !located {
                continue;
            }
            let shapes: Vec<(Fitted, Fitted)> = t
                .datums
                .iter()
                .filter_map(|d| nominal(part.datums[d.datum.0].feature))
                .map(|s| (s.clone(), s))
                .collect();
            let drf = crate::geometry::drf::drf(&shapes);
            for f in t.targets.iter().filter(|f| !datum_features.contains(f)) {
                for face in faces_in_graph(input, *f) {
                    faces.push((face, drf.free_t.clone(), drf.free_r.clone()));
                }
            }
        }
        LeftFree { faces }
    }

    /// Whether `face` may fix `fixes`: no frame of its tolerances leaves one of them
    /// free.
    fn may_fix(&self, face: FaceId, fixes: &Fixes) -> bool {
        self.faces
            .iter()
            .filter(|x| x.0 == face)
            .all(|(_, moves, turns)| {
                let moved = |k: usize| moves.iter().any(|m| m[k].abs() > 1e-3);
                let turned = |k: usize| turns.iter().any(|t| t[k].abs() > 0.999);
                !fixes.moves.iter().any(|&k| moved(k)) && !fixes.turns.iter().any(|&k| turned(k))
            })
    }
}

/// A sphere touched for the origins: its face, touches, keywords and origin shifts.
type SphereStep = (FaceId, Vec<(P3, V3)>, Vec<String>, Vec<(char, f64)>);

/// The origins a sphere of the part gives, where planes left some free: its centre,
/// from 4 touches spread over the part of it the probe reaches.
fn sphere_origins(
    g: &crate::geometry::PartGeometry,
    reachable: &dyn Fn(FaceId) -> Vec<(P3, V3)>,
    free: &mut Free,
) -> Option<SphereStep> {
    if free.origins.iter().all(|o| *o) {
        return None;
    }
    let mut spheres: Vec<(FaceId, P3)> = g
        .faces
        .iter()
        .enumerate()
        .filter_map(|(i, f)| match f.surface {
            Surface::Sphere { center, .. } => Some((FaceId(i), center)),
            _ => None,
        })
        .collect();
    spheres.sort_by(|a, b| {
        g.faces[b.0 .0]
            .area
            .total_cmp(&g.faces[a.0 .0].area)
            .then(a.0.cmp(&b.0))
    });
    for (f, centre) in spheres {
        let Some(pts) = farthest(&reachable(f), 4) else {
            continue;
        };
        let free_k: Vec<usize> = (0..3).filter(|&k| !free.origins[k]).collect();
        for &k in &free_k {
            free.origins[k] = true;
        }
        return Some((
            f,
            pts,
            free_k.iter().map(|&k| orig_word(k)).collect(),
            free_k.iter().map(|&k| (AXES[k], centre[k])).collect(),
        ));
    }
    None
}

/// How far beyond the largest tip's radius (mm) a face's edges keep the touches the
/// operator makes by hand where the face leaves room: a joystick touch lands a few
/// millimetres from the point shown, and one 2 mm from an edge with a Ø3 ball (as an
/// independent review found on CTC 02) slips off it.
const HAND_EDGE: f64 = 5.0;

/// The shortest hand-touched line that says anything of a turn (mm).
const SHORTEST_LINE: f64 = 5.0;

/// The length a hand-touched secondary line is first asked for: a tenth of the part's
/// largest extent, between [`SHORTEST_LINE`] and 50 mm. A touch's error over the line's
/// length turns the frame, and the far end of the part moves by it times the part's
/// length over the line's: on CTC 02 (800 mm) a 6.4 mm line beside a bore turned the
/// frame 0.45° for a 0.05 mm difference between its touches.
fn long_line(g: &crate::geometry::PartGeometry) -> f64 {
    let (lo, hi) = g.vertices.iter().fold(
        (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), v| (lo.inf(&v.coords), hi.sup(&v.coords)),
    );
    let extent = (hi - lo).max();
    (0.1 * extent).clamp(SHORTEST_LINE, 50.0)
}

/// `n` of `pts`, the first then each farthest from those chosen.
fn farthest(pts: &[(P3, V3)], n: usize) -> Option<Vec<(P3, V3)>> {
    if pts.len() < n {
        return None;
    }
    let mut chosen = vec![pts[0]];
    while chosen.len() < n {
        let next = pts.iter().filter(|p| !chosen.contains(p)).max_by(|a, b| {
            let d = |x: &(P3, V3)| {
                chosen
                    .iter()
                    .map(|c| (x.0 - c.0).norm())
                    .fold(f64::INFINITY, f64::min)
            };
            d(a).total_cmp(&d(b))
        })?;
        chosen.push(*next);
    }
    Some(chosen)
}

/// Three points far enough from a line to fix a plane (a triangle of some area).
fn spans_plane(p: &[(P3, V3)]) -> bool {
    p.len() >= 3 && (p[1].0 - p[0].0).cross(&(p[2].0 - p[0].0)).norm() > 25.0
}
