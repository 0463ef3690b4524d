//! The software rasterizer behind the `Cpu` backend (`backend.rs`): the blocked
//! directions of one probe component, by projecting the obstacle onto the cube.
//!
//! Per triangle, cheapest test first:
//! - **distance**: a triangle entirely nearer than the component's nearest point or
//!   farther than its farthest cannot touch it (bounding spheres, then the exact distance);
//! - **facing**: for a component that starts at the viewpoint, a triangle of a closed
//!   solid facing away from it is skipped — a half-line entering the solid, or a grown one
//!   first touching it, does so through a triangle that faces the viewpoint (proof
//!   below);
//! - **shadow**: a bare half-line marks the triangle's shadow at pixel centres; a
//!   component of radius ρ marks every pixel its shadow touches and dilates it by
//!   asin(ρ / distance), rounded up to whole pixels, in bands so each band grows once;
//!   near triangles, whose dilation would be many pixels, are grown in space instead: the
//!   shadow of a prism that holds the triangle swept by a ball of radius ρ.
//!
//! The same tests decide whole nodes of the scene's bounding-volume hierarchy, plus one
//! of its own: a node whose footprint is already marked in a band grown at least as far
//! as any of its triangles' is hidden ([`draw`]). [`blocked_until`] stops once given
//! cells are blocked, for callers that need only those.
//!
//! **Decision: cone semantics.** A pixel stands for its centre direction (the
//! verification samples there). The bare half-line is rasterized at centres, so it is
//! exact; grown components are rasterized over whole cells and dilated, so they are
//! pessimistic, as the seed's abstractions are. `refine` (opt-in,
//! `ConeOptions::exact_boundary`) makes the reached boundary exact with parry, at about
//! 10 µs a pixel.
//!
//! **Decision: back-face culling is exact** for a component that starts at the
//! viewpoint c, with c outside the solid S grown by ρ. Let q be the first point where
//! the half-line from c along d enters S ⊕ B(ρ); its nearest surface point s has q − s
//! = ρ·w with w in the normal cone at s (a convex edge or a face; a reflex edge is
//! never nearest), and d·w ≤ 0 at entry. Then w·(c − s) = w·(c − q) + ρ ≥ ρ > 0, so
//! some triangle at s faces c, and a triangle facing away can be skipped. The rule is
//! off for open meshes (FTC 08) and for truncated components, whose start is not c.
//!
//! **Decision: speed-ups keep the maps bit-identical.** A cheaper but coarser (or less
//! pessimistic) D2 changes plans, often for the worse: the rasterized cones' pessimism
//! acts as a margin the planner's search relies on. So culling here is only ever of
//! what cannot change a map: a hierarchy node is skipped when its footprint is marked
//! in a band grown at least as far (a pixel in band j is grown j times, so it covers
//! whatever a shadow of dilation k ≤ j would add), and a D2 sample stops when it can no
//! longer add anything. `tests/suite/access.rs` compares the hierarchy with
//! triangle-by-triangle drawing (`blocked_plain`) on every example and two real parts.
//!
//! Triangles straddling a truncated component's start are split (4 levels) and the near
//! pieces dropped; a split piece's children that fall in its middle child's band are
//! drawn as one convex polygon (the midpoints kept as corners, so its shadow is the
//! union of theirs), four in one band as the piece itself, and a piece whose whole
//! shadow is already marked is not split. A prism is convex, so its faces that face the
//! viewpoint project onto its outline's projection: one polygon for up to seven faces.
//! [`blocked_within`] is right on given cells alone: a shadow in band k, or a node,
//! whose footprint meets no pixel of those cells' growth k cannot mark one and is
//! passed over (`Focus`). [`draw`] (which polygons go into which map, through a
//! `Canvas`) and [`finish`] (bands grown, preferred directions) are two halves, so
//! another rasterizer can sit between them.

use super::cubemap::{CubeMap, Disc};
use super::probe::Component;
use super::raster::{footprint, shadow_polygon_where, Coverage};
use super::scene::{point_triangle_distance, BvhNode, Scene, Tri};
use crate::geometry::{P3, V3};

/// Past this many pixels of dilation a triangle is grown in space, as a prism.
const PRISM_PIXELS: u32 = 3;

/// How many times a triangle straddling a component's nearest distance is split.
const MAX_SPLIT: u32 = 4;

/// The least angle (rad) between directions in pixels k + 1 apart, over k: one pixel
/// step along a cube face is at least 0.408 · 2/N rad (at the cube's corners).
const MIN_STEP: f64 = 0.408 * 2.0;

/// How many whole-pixel growths cover a dilation by `alpha` rad at resolution `n`.
pub(crate) fn pixels_for(alpha: f64, n: u32) -> u32 {
    (alpha * n as f64 / MIN_STEP * 1.02).ceil().max(1.0) as u32
}

/// Where shadows are drawn: the base map (target 0, pixels as they are) and band k ≥ 1
/// (pixels to grow k times). The CPU draws at once; the GPU backend records the polygons
/// and rasterizes many components' shadows in one submission.
pub(super) trait Canvas {
    /// Marks the shadow of the convex polygon `q` (relative to the viewpoint, 3 to 12
    /// corners) in `target`.
    fn draw(&mut self, target: u32, q: &[V3], cov: Coverage);

    /// Whether every pixel of the rectangle `area` gives (a face, rows j0..=j1, columns
    /// i0..=i1, as (face, j0, j1, i0, i1); None for no rectangle) is marked in the maps
    /// of targets `target` and up (for target 0, the base map alone). A canvas that
    /// cannot tell says false; `area` is asked only when a map could hold it.
    fn covered(
        &self,
        target: u32,
        area: impl FnOnce() -> Option<(u8, u32, u32, u32, u32)>,
    ) -> bool {
        let _ = (target, area);
        false
    }

    /// Whether a shadow in `target` within the rectangle `area` gives could mark a pixel
    /// the caller needs right (see [`blocked_within`]). A canvas that needs every pixel,
    /// or cannot tell, says true; `area` is asked only when it could say false.
    fn relevant(
        &mut self,
        target: u32,
        area: impl FnOnce() -> Option<(u8, u32, u32, u32, u32)>,
    ) -> bool {
        let _ = (target, area);
        true
    }

    /// Whether drawing may stop: what the caller waits for is blocked already.
    fn enough(&mut self) -> bool {
        false
    }
}

/// The CPU's canvas: the maps themselves.
pub(super) struct Maps {
    /// Target 0.
    pub base: CubeMap,
    /// Target k at index k − 1.
    pub bands: Vec<Option<CubeMap>>,
    /// Whether anything was drawn in the base.
    base_marked: bool,
    /// The pixels whose blocking ends the drawing early ([`blocked_until`]).
    stop: Option<Stop>,
    /// The pixels the map must be right on ([`blocked_within`]).
    focus: Option<Focus>,
}

/// What [`blocked_within`] must get right: pixels, and their growths. A shadow drawn
/// in band k marks pixel p of the finished map only through growth k, so only if it
/// meets p's disc k, which lies in growth k of the focus: a shadow whose rectangle
/// meets no pixel of that growth cannot mark a focus pixel.
struct Focus {
    /// Growth k at index k, made when first asked for.
    grown: Vec<CubeMap>,
}

impl Focus {
    /// Growth `k` of the focus pixels: the pixels a shadow drawn in band k must reach to
    /// mark one of them.
    fn growth(&mut self, k: u32) -> &CubeMap {
        while self.grown.len() <= k as usize {
            let k = self.grown.len();
            let before = k.checked_sub(2).map(|b| &self.grown[b]);
            let next = self.grown[k - 1].grow_pixels_after(before);
            self.grown.push(next);
        }
        &self.grown[k as usize]
    }

    fn meets(&mut self, k: u32, (face, j0, j1, i0, i1): (u8, u32, u32, u32, u32)) -> bool {
        self.growth(k).spans_meet(face, j0, j1, i0, i1)
    }
}

/// What [`blocked_until`] waits for: pixels not yet blocked, each with its discs
/// ([`CubeMap::discs`]). A look reads each pending pixel's discs of the bands drawn;
/// the next is taken once [`LOOK_EVERY`] polygons per word the last one read are drawn.
struct Stop {
    pending: Vec<(usize, std::sync::Arc<[Disc]>)>,
    drawn: usize,
    next: usize,
}

/// Polygons drawn per word a look reads (a polygon costs about as much as reading a
/// hundred words).
const LOOK_EVERY: usize = 1;

/// Past this many pixels to wait for, [`blocked_until`] draws the whole map.
const MOST_PENDING: usize = 512;

impl Maps {
    pub fn new(n: u32, preferred: &[V3]) -> Maps {
        Maps {
            base: CubeMap::empty(n, preferred),
            bands: Vec::new(),
            base_marked: false,
            stop: None,
            focus: None,
        }
    }

    /// Whether pixel `index` is blocked in the map [`finish`] would make of these (in
    /// the base, or in a band k that meets its disc k), and how many words that read.
    fn pixel_blocked(&self, index: usize, discs: &[Disc]) -> (bool, usize) {
        let mut read = 0;
        let blocked = self.base.has_index(index)
            || self.bands.iter().zip(&discs[1..]).any(|(b, d)| {
                b.as_ref().is_some_and(|b| {
                    read += d.words();
                    b.meets(d)
                })
            });
        (blocked, read)
    }
}

impl Canvas for Maps {
    fn draw(&mut self, target: u32, q: &[V3], cov: Coverage) {
        let map = if target == 0 {
            self.base_marked = true;
            &mut self.base
        } else {
            let k = target as usize;
            if self.bands.len() < k {
                self.bands.resize(k, None);
            }
            let base = &self.base;
            self.bands[k - 1].get_or_insert_with(|| base.empty_like())
        };
        let matter = self.focus.as_mut().map(|f| f.growth(target));
        shadow_polygon_where(map, q, cov, matter);
        if let Some(stop) = &mut self.stop {
            stop.drawn += 1;
        }
    }

    fn relevant(
        &mut self,
        target: u32,
        area: impl FnOnce() -> Option<(u8, u32, u32, u32, u32)>,
    ) -> bool {
        match &mut self.focus {
            None => true,
            Some(focus) => area().is_none_or(|rect| focus.meets(target, rect)),
        }
    }

    fn enough(&mut self) -> bool {
        let Some(mut stop) = self.stop.take() else {
            return false;
        };
        if stop.drawn >= stop.next {
            let mut read = 0;
            stop.pending.retain(|(p, discs)| {
                let (blocked, words) = self.pixel_blocked(*p, discs);
                read += words;
                !blocked
            });
            stop.drawn = 0;
            stop.next = LOOK_EVERY * read;
        }
        let done = stop.pending.is_empty();
        self.stop = Some(stop);
        done
    }

    fn covered(
        &self,
        target: u32,
        area: impl FnOnce() -> Option<(u8, u32, u32, u32, u32)>,
    ) -> bool {
        if target == 0 {
            self.base_marked
                && area()
                    .is_some_and(|(face, j0, j1, i0, i1)| self.base.spans_set(face, j0, j1, i0, i1))
        } else {
            let from = (target as usize - 1).min(self.bands.len());
            let bands = &self.bands[from..];
            bands.iter().any(Option::is_some)
                && area().is_some_and(|(face, j0, j1, i0, i1)| {
                    CubeMap::spans_set_any(bands, face, j0, j1, i0, i1)
                })
        }
    }
}

/// What drawing left for [`finish`]: whether the component meets the scene in every
/// direction, and the triangles a truncated half-line's preferred directions are tested
/// against.
pub(super) struct Drawn<'s> {
    pub full: bool,
    pub candidates: Vec<&'s Tri>,
}

/// Marks the directions in which `comp`, placed with its axis from `from`, meets the
/// scene.
pub fn blocked(scene: &Scene, from: &P3, comp: &Component, n: u32, preferred: &[V3]) -> CubeMap {
    let mut maps = Maps::new(n, preferred);
    let drawn = draw(scene, from, comp, n, &mut maps);
    finish(scene, from, comp, maps.base, maps.bands, &drawn)
}

/// [`blocked`], right on the cells of `within` (and the pixels holding its preferred
/// directions); elsewhere it may hold fewer blocked cells. Shadows that cannot reach
/// those pixels ([`Focus`]) are passed over, whole nodes of the hierarchy at once: a
/// union of components needs each one only where the others leave it free. A bare
/// half-line is drawn whole.
pub fn blocked_within(
    scene: &Scene,
    from: &P3,
    comp: &Component,
    n: u32,
    preferred: &[V3],
    within: &CubeMap,
) -> CubeMap {
    let mut maps = Maps::new(n, preferred);
    if comp.radius > 0.0 && within.n() == n {
        maps.focus = Some(Focus {
            grown: vec![within.pixels_of_cells()],
        });
    }
    let drawn = draw(scene, from, comp, n, &mut maps);
    finish(scene, from, comp, maps.base, maps.bands, &drawn)
}

/// [`blocked`], right on the cells of `stop`, stopping early once all of them are
/// blocked; elsewhere it may hold fewer blocked cells. A preferred direction counts as
/// blocked when every pixel holding it is, as [`finish`] decides for a grown component;
/// a bare half-line is drawn whole. With few enough pixels to wait for, those alone are
/// decided at the end (each from its discs, as the early stop reads them) instead of
/// growing every band of the whole map.
pub fn blocked_until(
    scene: &Scene,
    from: &P3,
    comp: &Component,
    n: u32,
    preferred: &[V3],
    stop: &CubeMap,
) -> CubeMap {
    let mut maps = Maps::new(n, preferred);
    if comp.radius > 0.0 && stop.n() == n {
        let mut pixels: Vec<usize> = Vec::new();
        for cell in stop.cells() {
            match cell {
                super::Cell::Pixel(_) => pixels.push(stop.index(cell)),
                super::Cell::Preferred(k) => pixels.extend(
                    stop.pixels_holding(&stop.preferred(k))
                        .into_iter()
                        .map(|p| stop.index(super::Cell::Pixel(p))),
                ),
            }
        }
        pixels.sort_unstable();
        pixels.dedup();
        // Many pending pixels are seldom all blocked, and each look costs more.
        if pixels.len() <= MOST_PENDING {
            maps.stop = Some(Stop {
                next: LOOK_EVERY * 16 * pixels.len(),
                pending: pixels
                    .into_iter()
                    .map(|p| (p, CubeMap::discs(n, p)))
                    .collect(),
                drawn: 0,
            });
            let drawn = draw(scene, from, comp, n, &mut maps);
            return stop_cells(stop, &maps, drawn.full);
        }
    }
    let drawn = draw(scene, from, comp, n, &mut maps);
    finish(scene, from, comp, maps.base, maps.bands, &drawn)
}

/// [`blocked_until`]'s map once drawn: `stop`'s cells decided from the pixels waited
/// for (every pixel that is or holds one of them); every other cell free.
fn stop_cells(stop: &CubeMap, maps: &Maps, full: bool) -> CubeMap {
    let mut out = stop.empty_like();
    if full {
        out.or_assign(stop);
        return out;
    }
    // The pixels still pending at the last look may have been blocked since.
    let open: Vec<usize> = maps
        .stop
        .as_ref()
        .map(|s| {
            s.pending
                .iter()
                .filter(|(p, discs)| !maps.pixel_blocked(*p, discs).0)
                .map(|(p, _)| *p)
                .collect()
        })
        .unwrap_or_default();
    let blocked = |p: usize| !open.contains(&p);
    for cell in stop.cells() {
        let hit = match cell {
            super::Cell::Pixel(_) => blocked(stop.index(cell)),
            super::Cell::Preferred(k) => stop
                .pixels_holding(&stop.preferred(k))
                .into_iter()
                .all(|p| blocked(stop.index(super::Cell::Pixel(p)))),
        };
        out.set(cell, hit);
    }
    out
}

/// [`blocked`] triangle by triangle in the scene's order, without the hierarchy: the
/// plain baseline the hierarchy's maps must equal bit for bit (tests, benches).
pub fn blocked_plain(
    scene: &Scene,
    from: &P3,
    comp: &Component,
    n: u32,
    preferred: &[V3],
) -> CubeMap {
    let mut maps = Maps::new(n, preferred);
    let at = Placed::new(from, comp, n);
    let (mut candidates, mut q) = (Vec::new(), [V3::zeros(); 12]);
    let full = !scene
        .tris
        .iter()
        .all(|t| draw_triangle(scene, &at, &mut maps, t, &mut candidates, &mut q));
    finish(
        scene,
        from,
        comp,
        maps.base,
        maps.bands,
        &Drawn { full, candidates },
    )
}

/// Draws the shadows of the scene's triangles for `comp` at `from` (cube maps of
/// resolution `n`), cheapest test first (see the module's documentation). The scene's
/// hierarchy is walked nearest child first, so the large shadows of near triangles are
/// drawn before the far triangles they hide; a node is passed over whole when every
/// triangle in it would be (too far, too near, under the floor, all facing away) or
/// when what its triangles could add is already marked ([`node_band`]). The maps are the
/// same as triangle by triangle: a shadow adds nothing where its pixels are already
/// marked in a band grown at least as far as its own.
pub(super) fn draw<'s>(
    scene: &'s Scene,
    from: &P3,
    comp: &Component,
    n: u32,
    canvas: &mut impl Canvas,
) -> Drawn<'s> {
    let mut candidates: Vec<&Tri> = Vec::new();
    let mut q = [V3::zeros(); 12];
    let at = Placed::new(from, comp, n);
    let (near, far) = (at.near, at.far);
    let from_tip = comp.a == 0.0;
    let bvh = &scene.bvh;
    let full = |candidates| Drawn {
        full: true,
        candidates,
    };
    for &k in &bvh.large {
        let t = &scene.tris[k as usize];
        if !draw_triangle(scene, &at, canvas, t, &mut candidates, &mut q) {
            return full(candidates);
        }
    }
    let partial = |candidates| Drawn {
        full: false,
        candidates,
    };
    let mut stack: Vec<u32> = if bvh.nodes.is_empty() {
        Vec::new()
    } else {
        vec![0]
    };
    while let Some(k) = stack.pop() {
        let node = &bvh.nodes[k as usize];
        if scene.skips_ball(&node.centre, node.radius) {
            continue;
        }
        let w = from - node.centre;
        let dc = w.norm();
        let margin = 1e-9 * (1.0 + dc + node.radius);
        if dc - node.radius > far + margin || dc + node.radius < near - margin {
            continue;
        }
        if from_tip && faces_away(node, &w, dc, margin) {
            continue;
        }
        let (hi, lo) = (dc + node.radius + margin, dc - node.radius - margin);
        // A leaf's few triangles are drawn untested: projecting its box's eight corners
        // costs about what their own shadows' already-marked checks do.
        if node.kids.is_some() {
            if let Some((target, cov)) = node_band(&at, lo, hi) {
                let mut rect = None;
                let mut area = || *rect.get_or_insert_with(|| node_footprint(&at, node, cov));
                if canvas.covered(target, &mut area) || !canvas.relevant(target, &mut area) {
                    continue;
                }
            }
        }
        match node.kids {
            Some((a, b)) => {
                let d = |c: u32| (bvh.nodes[c as usize].centre - from).norm_squared();
                let (first, second) = if d(b) < d(a) { (b, a) } else { (a, b) };
                stack.push(second);
                stack.push(first);
            }
            None => {
                let leaf = &bvh.order[node.first as usize..(node.first + node.count) as usize];
                for &t in leaf {
                    let t = &scene.tris[t as usize];
                    if !draw_triangle(scene, &at, canvas, t, &mut candidates, &mut q) {
                        return full(candidates);
                    }
                }
                if canvas.enough() {
                    return partial(candidates);
                }
            }
        }
    }
    partial(candidates)
}

/// Whether every triangle of `node` faces away from the viewpoint at `w` from the
/// node's centre (`dc` = |w|), as [`draw_triangle`] culls them for a component from the
/// tip: each normal n is within θ of the node's axis a and each corner p within its
/// ball, so n·(viewpoint − p) ≤ |w|·cos(φ − θ) + radius, with φ the angle from a to w.
fn faces_away(node: &BvhNode, w: &V3, dc: f64, margin: f64) -> bool {
    let Some((a, cos_t, sin_t)) = node.normals else {
        return false;
    };
    if dc <= node.radius {
        return false;
    }
    let cos_p = a.dot(w) / dc;
    if cos_p >= cos_t {
        return false;
    }
    let sin_p = (1.0 - cos_p * cos_p).max(0.0).sqrt();
    dc * (cos_p * cos_t + sin_p * sin_t) + node.radius < -margin
}

/// The band and coverage that bound every shadow `node`'s triangles (at distances `lo`
/// to `hi` from the viewpoint) could be drawn with: a node whose box's footprint is
/// marked in that band or a more grown one adds nothing (it is hidden), and one whose
/// footprint cannot reach a pixel the caller needs is not drawn ([`Canvas::relevant`]).
/// None for a truncated bare half-line (its triangles are kept as candidates for the
/// preferred directions), and when a triangle of the node could be drawn as a prism or
/// meet the component in every direction.
fn node_band(at: &Placed, lo: f64, hi: f64) -> Option<(u32, Coverage)> {
    let &Placed { comp, n, near, .. } = at;
    let r = comp.radius;
    if r == 0.0 {
        return (near <= 0.0).then_some((0, Coverage::Centres));
    }
    if comp.a == 0.0 {
        let d = lo.max(near);
        if d <= r || pixels_for((r / d).asin(), n) > PRISM_PIXELS {
            return None;
        }
    }
    let alpha = at.dilation(lo.max(0.0), hi)?;
    let k = pixels_for(alpha * (1.0 + 1e-9), n);
    (k as usize <= 2 * n as usize).then_some((k, Coverage::Cells))
}

/// The rectangle that holds the shadow of every polygon inside `node`'s box (see
/// [`footprint`]).
fn node_footprint(at: &Placed, node: &BvhNode, cov: Coverage) -> Option<(u8, u32, u32, u32, u32)> {
    let (a, b) = (node.lo - at.from, node.hi - at.from);
    // A box whose corners are not all strictly inside one face's pyramid has none (what
    // `footprint` finds corner by corner): told from its extents first, as about half
    // the boxes asked straddle a cube edge. Inside the +m pyramid every corner has
    // c_m > |c_j|, so a_m > b_j and a_m > −a_j for both other axes j (−b_m for −m).
    let inside = |m: usize, near: f64| {
        let (j, k) = ((m + 1) % 3, (m + 2) % 3);
        near > 0.0 && near > b[j] && near > -a[j] && near > b[k] && near > -a[k]
    };
    if !(0..3).any(|m| inside(m, a[m]) || inside(m, -b[m])) {
        return None;
    }
    let corners = [0, 1, 2, 3, 4, 5, 6, 7].map(|c: u8| {
        V3::new(
            if c & 1 == 0 { a.x } else { b.x },
            if c & 2 == 0 { a.y } else { b.y },
            if c & 4 == 0 { a.z } else { b.z },
        )
    });
    footprint(&corners, cov, at.n)
}

/// A component placed at `from` for maps of resolution `n`, with its nearest and
/// farthest distances (computed once, not per triangle).
struct Placed<'c> {
    from: P3,
    comp: &'c Component,
    n: u32,
    near: f64,
    far: f64,
    /// The distance where [`Placed::dilation`] peaks, and the peak (for `near` > 0).
    turn: f64,
    peak: f64,
}

impl<'c> Placed<'c> {
    fn new(from: &P3, comp: &'c Component, n: u32) -> Placed<'c> {
        let (r, near) = (comp.radius, comp.near());
        Placed {
            from: *from,
            comp,
            n,
            near,
            far: comp.far(),
            turn: near.hypot(r),
            peak: (r / near).atan(),
        }
    }

    /// The largest angle between the component's axis and a direction to an obstacle
    /// point it touches, for obstacle points between `dmin` and `dmax` away; None when it
    /// touches whatever its direction. A point at distance D and angle θ is inside only
    /// if D·sin θ ≤ r and D·cos θ ≥ near: θ ≤ min(asin(r/D), acos(near/D)), which peaks
    /// at atan(r/near).
    fn dilation(&self, dmin: f64, dmax: f64) -> Option<f64> {
        let (r, near) = (self.comp.radius, self.near);
        if near <= 0.0 {
            return (dmin > r).then(|| (r / dmin).asin());
        }
        Some(if dmax <= self.turn {
            (near / dmax).min(1.0).acos()
        } else if dmin >= self.turn {
            (r / dmin).asin()
        } else {
            self.peak
        })
    }
}

/// One triangle's shadow for `comp` at `from`, cheapest test first; false when the
/// component meets it in every direction.
#[allow(clippy::too_many_arguments)]
fn draw_triangle<'s>(
    scene: &Scene,
    at: &Placed,
    canvas: &mut impl Canvas,
    t: &'s Tri,
    candidates: &mut Vec<&'s Tri>,
    q: &mut [V3; 12],
) -> bool {
    let &Placed {
        from,
        comp,
        n,
        near,
        far,
        ..
    } = at;
    let from = &from;
    let r = comp.radius;
    let from_tip = comp.a == 0.0;
    if scene.skips(t) {
        return true;
    }
    let dc = (t.centre - from).norm();
    if dc - t.radius > far || dc + t.radius < near {
        return true;
    }
    let h = t.normal.dot(&(from - t.v[0]));
    if from_tip && t.closed && h < 0.0 {
        return true;
    }
    let exact = || point_triangle_distance(from, &t.v);
    if r == 0.0 {
        // Bare (possibly truncated) half-line: the shadow, sampled at pixel centres.
        if dc - t.radius < near || dc + t.radius > far {
            let d = exact();
            if d > far {
                return true;
            }
        }
        for (k, v) in t.v.iter().enumerate() {
            q[k] = v - from;
        }
        canvas.draw(0, &q[..3], Coverage::Centres);
        if near > 0.0 {
            candidates.push(t);
        }
        return true;
    }
    let lower = dc - t.radius;
    let dmin = if lower > 20.0 * r { lower } else { exact() };
    if dmin > far {
        return true;
    }
    if from_tip && dmin.max(near) > r {
        let k = pixels_for((r / dmin.max(near)).asin(), n);
        if k > PRISM_PIXELS && t.normal != V3::zeros() && prism_shadow(canvas, from, t, r, h) {
            return true;
        }
    }
    grown_shadow(canvas, at, t.v, dmin)
}

/// The blocked map from the drawn shadows: ∪ₖ growₖ(bandₖ) added to the base, then the
/// preferred directions.
pub(super) fn finish(
    scene: &Scene,
    from: &P3,
    comp: &Component,
    mut base: CubeMap,
    bands: Vec<Option<CubeMap>>,
    drawn: &Drawn,
) -> CubeMap {
    if drawn.full {
        base.fill_pixels();
        base.fill_preferred();
        return base;
    }
    let (r, near, far) = (comp.radius, comp.near(), comp.far());
    // ∪ₖ growₖ(bandₖ), growing each accumulated band once per step (Horner's scheme).
    // Pixels only: the preferred directions are decided below.
    // Each step holds the one before it grown, so grows only its own new pixels across
    // cube edges.
    let (mut acc, mut before): (Option<CubeMap>, Option<CubeMap>) = (None, None);
    for band in bands.into_iter().rev() {
        let mut m = match acc.take() {
            Some(a) => {
                let g = a.grow_pixels_after(before.as_ref());
                before = Some(a);
                g
            }
            None => base.empty_like(),
        };
        if let Some(b) = band {
            m.or_assign(&b);
        }
        acc = Some(m);
    }
    if let Some(a) = acc {
        base.or_assign(&a.grow_pixels_after(before.as_ref()));
    }
    // Preferred directions.
    for k in 0..base.preferred_len() {
        let d = base.preferred(k);
        let hit = if r == 0.0 && near == 0.0 {
            scene.cast_ray(from, &d, far).is_some_and(|t| t > 0.0)
        } else if r == 0.0 {
            drawn.candidates.iter().any(|t| {
                crate::geometry::line_triangle(from, &d, &t.v[0], &t.v[1], &t.v[2])
                    .is_some_and(|s| s > 0.0 && s >= near && s <= far)
            })
        } else {
            // Blocked unless a pixel holding the direction is free: the pixel maps mark
            // every pixel their blocked region touches.
            base.pixels_holding(&d)
                .iter()
                .all(|p| base.get(super::Cell::Pixel(*p)))
        };
        base.set(super::Cell::Preferred(k), hit);
    }
    base
}

/// Marks the shadow of the triangle `v` (at distance `dmin`) dilated for a component of
/// radius ρ, in the band of its dilation. A triangle that reaches inside the component's
/// nearest distance is split, up to `MAX_SPLIT` times, and the pieces wholly inside are
/// dropped. False when the component meets the triangle in every direction.
fn grown_shadow(canvas: &mut impl Canvas, at: &Placed, v: [P3; 3], dmin: f64) -> bool {
    let (n, from) = (at.n, &at.from);
    let dist = v.map(|p| (p - from).norm());
    match grown_piece(canvas, at, v, dist, dmin, 0) {
        Err(Everywhere) => false,
        Ok(Some(k)) => {
            draw_grown(canvas, n, k, &v.map(|p| p - from));
            true
        }
        Ok(None) => true,
    }
}

/// The component meets a triangle whatever its direction.
struct Everywhere;

/// Marks a grown shadow (corners relative to the viewpoint) in band `k`, unless it
/// cannot reach a pixel the canvas needs.
fn draw_grown(canvas: &mut impl Canvas, n: u32, k: u32, q: &[V3]) {
    if canvas.relevant(k, || footprint(q, Coverage::Cells, n)) {
        canvas.draw(k, q, Coverage::Cells);
    }
}

/// [`grown_shadow`]'s rule for one piece, leaving its drawing to the caller where the
/// whole piece falls in one band: `Some(k)` when the piece is to be drawn whole in band
/// k, None when it is drawn (or adds nothing). A split piece's children that fall in the
/// same band as its middle child are drawn as one convex polygon (the middle and the
/// corners sharing its band; the midpoints kept as corners, so its outline is the
/// children's own edges); all four in one band make the piece itself whole. The union
/// of the children's shadows is the shadow of their union, so the maps are the same as
/// drawing every child.
///
/// `dist` holds the corners' distances from `from`. `dmin` is the piece's distance, or,
/// for a piece with a corner nearer than the component's nearest distance, any distance
/// under it: the rule then reads no more of it than that it is under (see [`dilation`]).
fn grown_piece(
    canvas: &mut impl Canvas,
    at: &Placed,
    v: [P3; 3],
    dist: [f64; 3],
    dmin: f64,
    depth: u32,
) -> Result<Option<u32>, Everywhere> {
    let (n, from, near, far) = (at.n, &at.from, at.near, at.far);
    let reach = dist.iter().copied().fold(0.0, f64::max);
    if reach < near {
        return Ok(None);
    }
    // Splitting pays only for triangles large beside the distance they straddle.
    let size = (v[1] - v[0])
        .norm()
        .max((v[2] - v[1]).norm())
        .max((v[0] - v[2]).norm());
    if dmin < near && depth < MAX_SPLIT && size > 0.1 * near {
        // Its pieces, each dilated at most as far as the whole triangle would be, add
        // nothing where its shadow is already marked in a band grown as far or further.
        if let Some(alpha) = at.dilation(dmin * (1.0 - 1e-9), reach * (1.0 + 1e-9)) {
            let k = pixels_for(alpha * (1.0 + 1e-9), n);
            let q = v.map(|p| p - from);
            if k as usize <= 2 * n as usize {
                let mut rect = None;
                let mut area = || *rect.get_or_insert_with(|| footprint(&q, Coverage::Cells, n));
                if canvas.covered(k, &mut area) || !canvas.relevant(k, &mut area) {
                    return Ok(None);
                }
            }
        }
        let m = [0, 1, 2].map(|k| P3::from((v[k].coords + v[(k + 1) % 3].coords) / 2.0));
        let dm = m.map(|p| (p - from).norm());
        let parts = [
            [v[0], m[0], m[2]],
            [m[0], v[1], m[1]],
            [m[2], m[1], v[2]],
            [m[0], m[1], m[2]],
        ];
        let dists = [
            [dist[0], dm[0], dm[2]],
            [dm[0], dist[1], dm[1]],
            [dm[2], dm[1], dist[2]],
            dm,
        ];
        let mut bands = [None; 4];
        for ((band, part), dist) in bands.iter_mut().zip(parts).zip(dists) {
            let corner = dist.iter().copied().fold(f64::INFINITY, f64::min);
            // A corner under `near` tells all the rule needs (and it is within `far`).
            let d = if corner < near {
                corner
            } else {
                point_triangle_distance(from, &part)
            };
            if d <= far {
                *band = grown_piece(canvas, at, part, dist, d, depth + 1)?;
            }
        }
        let Some(middle) = bands[3] else {
            for (band, part) in bands.iter().zip(&parts) {
                if let Some(k) = *band {
                    draw_grown(canvas, n, k, &part.map(|p| p - from));
                }
            }
            return Ok(None);
        };
        if bands[..3].iter().all(|b| *b == Some(middle)) {
            return Ok(Some(middle));
        }
        // v0, m0, v1, m1, v2, m2 around the piece; a corner's vertex where it joins.
        let mut outline = [V3::zeros(); 6];
        let mut len = 0;
        for k in 0..3 {
            if bands[k] == Some(middle) {
                outline[len] = v[k] - from;
                len += 1;
            } else if let Some(b) = bands[k] {
                draw_grown(canvas, n, b, &parts[k].map(|p| p - from));
            }
            outline[len] = m[k] - from;
            len += 1;
        }
        draw_grown(canvas, n, middle, &outline[..len]);
        return Ok(None);
    }
    let Some(alpha) = at.dilation(dmin, reach) else {
        return Err(Everywhere);
    };
    let k = pixels_for(alpha, n);
    if k as usize > 2 * n as usize {
        return Err(Everywhere);
    }
    Ok(Some(k))
}

/// The prism that holds a triangle swept by a ball of radius `r`, relative to the
/// viewpoint: its cross-section is the triangle offset by `r` in its plane with
/// bevelled corners (six sides), and it reaches `r` to either side of the plane.
struct Prism {
    /// The cross-section's corners in the triangle's plane.
    hex: [V3; 6],
    /// Whether side k (corners k and k + 1) faces the viewpoint.
    facing: [bool; 6],
    /// Whether the top (`hex + up`) faces the viewpoint (the bottom never does).
    above: bool,
    up: V3,
}

impl Prism {
    /// None when the viewpoint is inside the prism (or the triangle is degenerate).
    fn of(from: &P3, t: &Tri, r: f64, h: f64) -> Option<Prism> {
        let nn = t.normal;
        let mut hex = [V3::zeros(); 6];
        for i in 0..3 {
            let (prev, v, next) = (t.v[(i + 2) % 3], t.v[i], t.v[(i + 1) % 3]);
            let t_in = (v - prev).normalize();
            let t_out = (next - v).normalize();
            let m_in = t_in.cross(&nn);
            let m_out = t_out.cross(&nn);
            let b = (m_in + m_out).normalize();
            let lam_in = r * (1.0 - b.dot(&m_in)) / b.dot(&t_in);
            let lam_out = r * (1.0 - b.dot(&m_out)) / b.dot(&-t_out);
            hex[2 * i] = (v - from) + m_in * r + t_in * lam_in;
            hex[2 * i + 1] = (v - from) + m_out * r - t_out * lam_out;
        }
        if hex.iter().any(|p| !p.iter().all(|x| x.is_finite())) {
            return None;
        }
        // The viewpoint is the origin here: a side faces it when m·(0 − p) > 0.
        let facing: [bool; 6] = std::array::from_fn(|k| {
            let side = hex[(k + 1) % 6] - hex[k];
            side.norm_squared() > 1e-24 && side.cross(&nn).dot(&-hex[k]) > 0.0
        });
        let above = h.abs() > r;
        if !above && !facing.iter().any(|&f| f) {
            return None;
        }
        let up = nn * (r * if h >= 0.0 { 1.0 } else { -1.0 });
        Some(Prism {
            hex,
            facing,
            above,
            up,
        })
    }

    /// Side k as a quadrilateral.
    fn side(&self, k: usize) -> [V3; 4] {
        let (p, q, up) = (self.hex[k], self.hex[(k + 1) % 6], self.up);
        [p + up, q + up, q - up, p - up]
    }
}

/// Marks the shadow of the triangle's [`Prism`]; false, drawing nothing, when the
/// viewpoint is inside the prism.
fn prism_shadow(out: &mut impl Canvas, from: &P3, t: &Tri, r: f64, h: f64) -> bool {
    let Some(prism) = Prism::of(from, t, r, h) else {
        return false;
    };
    let Prism {
        hex,
        facing,
        above,
        up,
    } = prism;
    // The prism is convex and the viewpoint outside it, so the faces that face the
    // viewpoint project onto the projection of their outline (the edges between a face
    // that faces it and one that does not): one polygon drawn for up to seven.
    let mut outline = [V3::zeros(); 12];
    let mut len = 0;
    let mut push = |p: V3| {
        if len == 0 || outline[len - 1] != p {
            outline[len] = p;
            len += 1;
        }
    };
    if above {
        // The top faces the viewpoint: a side that does too shows its bottom edge, one
        // that does not its top edge, and the vertical edges join them.
        for k in 0..6 {
            let (p, q) = (hex[k], hex[(k + 1) % 6]);
            let off = if facing[k] { -up } else { up };
            push(p + off);
            push(q + off);
        }
    } else {
        // Neither top nor bottom does: the sides that face the viewpoint (one run of
        // them around the prism), their top edges out and their bottom edges back.
        let first = (0..6).find(|&k| facing[k] && !facing[(k + 5) % 6]);
        let run: Vec<usize> = first.map_or_else(Vec::new, |first| {
            (0..6)
                .map(|i| (first + i) % 6)
                .take_while(|&k| facing[k])
                .collect()
        });
        if run.is_empty() || run.len() != facing.iter().filter(|&&f| f).count() {
            // Two runs, with a degenerate side between them: side by side instead.
            for k in (0..6).filter(|&k| facing[k]) {
                out.draw(0, &prism.side(k), Coverage::Cells);
            }
            return true;
        }
        for &k in &run {
            push(hex[k] + up);
        }
        let end = (run[run.len() - 1] + 1) % 6;
        push(hex[end] + up);
        push(hex[end] - up);
        for &k in run.iter().rev() {
            push(hex[k] - up);
        }
    }
    if len > 1 && outline[len - 1] == outline[0] {
        len -= 1;
    }
    if len >= 3 {
        out.draw(0, &outline[..len], Coverage::Cells);
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A prism drawn as its outline marks the pixels its faces that face the viewpoint
    /// mark drawn one by one (the top when above, and those sides): near and far,
    /// above and beside, thin and fat triangles, at three resolutions.
    #[test]
    fn a_prism_drawn_as_its_outline_marks_what_its_faces_do() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let (mut drawn, mut beside, mut differ) = (0, 0, Vec::new());
        for case in 0..3000 {
            let v = [0, 1, 2].map(|_| P3::new(next() * 20.0, next() * 20.0, next() * 20.0));
            let normal = (v[1] - v[0]).cross(&(v[2] - v[0]));
            if normal.norm() < 1e-3 {
                continue;
            }
            let t = Tri {
                v,
                normal: normal.normalize(),
                centre: v[0],
                radius: 0.0,
                closed: true,
            };
            let r = 1.0 + 15.0 * next().abs();
            let from = P3::new(next() * 60.0, next() * 60.0, next() * 60.0);
            let h = t.normal.dot(&(from - t.v[0]));
            let Some(prism) = Prism::of(&from, &t, r, h) else {
                continue;
            };
            beside += usize::from(!prism.above);
            for n in [16, 32, 64] {
                let mut outline = Maps::new(n, &[]);
                assert!(prism_shadow(&mut outline, &from, &t, r, h));
                let mut faces = Maps::new(n, &[]);
                if prism.above {
                    let top = prism.hex.map(|p| p + prism.up);
                    faces.draw(0, &top, Coverage::Cells);
                }
                for k in (0..6).filter(|&k| prism.facing[k]) {
                    faces.draw(0, &prism.side(k), Coverage::Cells);
                }
                drawn += 1;
                if outline.base != faces.base {
                    differ.push((case, n));
                }
            }
        }
        assert!(drawn > 3000 && beside > 100, "{drawn} {beside}");
        assert!(
            differ.is_empty(),
            "{} of {drawn} differ: {:?}",
            differ.len(),
            &differ[..differ.len().min(10)]
        );
    }
}
