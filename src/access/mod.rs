//! Stage 7, accessibility (seed ch. 2, paper 001): for a point near the part, the
//! directions from which a probe can reach it, as cube-map cones.
//!
//! The entry point is [`point_cones`] (one fpoint, one probe) and [`cones`] (many, in
//! parallel). The pieces:
//! - [`CubeMap`]: six N × N bitmaps plus exact preferred directions, with set operations
//!   and growing;
//! - [`Scene`]: the obstacle (part, and table once a setup is known);
//! - [`ProbeShape`]: the spec's probe as tip ball plus [`Component`]s (stylus and
//!   extensions as capsules, body, head and ram as cylinders);
//! - [`Backend`]: computes one component's blocked directions; [`Cpu`] is the software
//!   rasterizer, [`Gpu`] rasterizes the same shadow polygons with wgpu, many components
//!   per submission;
//! - the seed's family: the half-line GAC, grown and truncated half-lines (any
//!   component), D1, D2 (weak GAC over dD1), D1′ for a chosen second-component
//!   direction, feature cones as intersections, approach/retract cones;
//! - [`scan`]: a laser line scanner's visibility (laser and camera rays, incidence,
//!   housing at the stand-off) on the same maps and backends.
//!
//! **Architecture Invariant:** for components of non-zero radius a direction the
//! obstacle blocks is never reported accessible; the bare half-line is exact at pixel
//! centres.
//!
//! **Decision: D2 and D1′ err on the blocked side.** D2 samples
//! `ConeOptions::d2_samples` points of dD1 (16 by default, the seed's; the planner asks
//! 6), evenly by cell index, at half the cones' resolution from N = 32 up; it is a
//! lower bound, as in the seed. With `d2_wanted` it stops once it holds every wanted
//! setup, and a sample stops drawing once the cells still needed are blocked. D1′ reads
//! a 96 × 96 depth map ([`SecondMap`]) dilated by the largest second-component radius,
//! so it is pessimistic.
//!
//! `gac_with` is a union of components, each after the first drawn only where those
//! before leave the probe free (the retract point only where the contact does);
//! `point_cones` is the cone at the contact ∩ the cone at the retract point (D1 for
//! bent probes) plus D2; `cones` and the batched `gac_halfline_many` and
//! `point_cones_many` keep input order, so a batching backend gets every query of many
//! points in one call.

mod cpu;
mod cubemap;
mod errors;
mod exact;
mod gpu;
mod heightmap;
pub mod pose;
mod probe;
mod raster;
mod report;
pub mod scan;
mod scene;
mod swept;

pub use cpu::{blocked_plain, pixels_for};
pub use cubemap::{face_dir, face_uv, ones, Cell, CubeMap, Pixel, PreferredIndex};
pub use errors::AccessError;
pub use exact::{component_hits, refine};
pub use gpu::Gpu;
pub use pose::{Blocker, Contact, Head, Pose};
pub use probe::{Component, End, ProbeShape};
pub use raster::{shadow_polygon, Coverage};
pub use report::{cone_report, pgm, ConeInput, ConeReport, ConeRequest};
pub use scan::{scan_cones, ScanCones, ScannerShape};
pub use scene::{point_triangle_distance, Scene, Tri};

use crate::geometry::{PartGeometry, P3, V3};
use crate::sample::Fpoint;
use rayon::prelude::*;
use std::sync::Arc;

/// One component placed at one point: a question for [`Backend::blocked_many`].
#[derive(Debug, Clone, Copy)]
pub struct Query<'a> {
    /// Where the component's axis starts (the tip centre, or an articulation point).
    pub from: P3,
    /// The component.
    pub comp: &'a Component,
}

/// Computes the directions one probe component is blocked in. The CPU rasterizer
/// implements it; the GPU backend rasterizes the same shadows.
pub trait Backend: Sync {
    /// The directions in which `comp`, with its axis starting at `from`, meets the scene.
    fn blocked(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
    ) -> CubeMap;

    /// [`Backend::blocked`], right on the cells of `stop`; elsewhere it may hold fewer
    /// blocked cells (the CPU stops drawing once every cell of `stop` is blocked, and
    /// decides only those; others may draw the whole map).
    fn blocked_until(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        stop: &CubeMap,
    ) -> CubeMap {
        let _ = stop;
        self.blocked(scene, from, comp, n, preferred)
    }

    /// [`Backend::blocked`], right on the cells of `within` (and the pixels holding its
    /// preferred directions); elsewhere it may hold fewer blocked cells (the CPU passes
    /// over shadows that cannot reach them; others may draw the whole map).
    fn blocked_within(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        within: &CubeMap,
    ) -> CubeMap {
        let _ = within;
        self.blocked(scene, from, comp, n, preferred)
    }

    /// [`Backend::blocked`] for many queries, in their order.
    fn blocked_many(
        &self,
        scene: &Scene,
        queries: &[Query],
        n: u32,
        preferred: &[V3],
    ) -> Vec<CubeMap> {
        queries
            .iter()
            .map(|q| self.blocked(scene, &q.from, q.comp, n, preferred))
            .collect()
    }

    /// Whether [`Backend::blocked_many`] pays over one query at a time, so callers
    /// should gather their queries (the CPU stops early instead, once a cone is empty).
    fn batches(&self) -> bool {
        false
    }
}

/// The software backend.
#[derive(Debug, Clone, Copy, Default)]
pub struct Cpu;

impl Backend for Cpu {
    fn blocked(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
    ) -> CubeMap {
        cpu::blocked(scene, from, comp, n, preferred)
    }

    fn blocked_until(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        stop: &CubeMap,
    ) -> CubeMap {
        cpu::blocked_until(scene, from, comp, n, preferred, stop)
    }

    fn blocked_within(
        &self,
        scene: &Scene,
        from: &P3,
        comp: &Component,
        n: u32,
        preferred: &[V3],
        within: &CubeMap,
    ) -> CubeMap {
        cpu::blocked_within(scene, from, comp, n, preferred, within)
    }
}

/// Which backend computes the cones.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BackendKind {
    /// The software rasterizer: the reference, byte-identical on every machine.
    #[default]
    Cpu,
    /// wgpu ([`Gpu`]), found once per process.
    Gpu,
}

static GPU: std::sync::OnceLock<Result<Gpu, String>> = std::sync::OnceLock::new();

/// The process's GPU backend, set up on first use, or why there is none.
pub fn gpu() -> Result<&'static Gpu, String> {
    GPU.get_or_init(Gpu::new).as_ref().map_err(Clone::clone)
}

/// The backend `--backend auto` picks: the GPU when wgpu finds a hardware adapter; a
/// software one (lavapipe) is slower than the CPU backend it would replace, so there the
/// CPU. Also says why, for the summary.
pub fn auto_backend() -> (BackendKind, String) {
    match gpu() {
        Ok(g) if !g.is_software() => (
            BackendKind::Gpu,
            format!("cones on the GPU: {}", g.adapter()),
        ),
        Ok(g) => (
            BackendKind::Cpu,
            format!(
                "cones on the CPU: the only adapter is a software one ({})",
                g.adapter()
            ),
        ),
        Err(why) => (
            BackendKind::Cpu,
            format!("cones on the CPU: no GPU adapter ({why})"),
        ),
    }
}

impl BackendKind {
    /// The backend itself; the GPU's when one was found, else the CPU's.
    pub fn get(self) -> &'static dyn Backend {
        match self {
            BackendKind::Cpu => &Cpu,
            BackendKind::Gpu => match gpu() {
                Ok(g) => g,
                Err(_) => &Cpu,
            },
        }
    }
}

/// The part's triangles as corner points.
pub fn triangles_of(g: &PartGeometry) -> Vec<[P3; 3]> {
    g.triangles
        .iter()
        .map(|t| t.map(|i| g.vertices[i as usize]))
        .collect()
}

/// The global accessibility cone of a half-line at `p`: the directions d for which the
/// ray p + t·d, t > 0, misses every triangle (seed ch. 2.3), sampled at pixel centres.
/// `p` should be off the surface, such as a tip centre p + r·n.
pub fn gac_halfline(scene: &Scene, p: &P3, n: u32, preferred: &[V3]) -> CubeMap {
    Cpu.blocked(scene, p, &Component::half_line(), n, preferred)
        .not()
}

/// The directions from which all of `comps`, stacked along one axis from `from`, miss
/// the scene: the intersection of their cones (a straight probe, ch. 2.4).
pub fn gac(
    backend: &dyn Backend,
    scene: &Scene,
    from: &P3,
    comps: &[Component],
    n: u32,
    preferred: &[V3],
) -> CubeMap {
    gac_with(backend, scene, from, comps, n, preferred, false)
}

/// [`gac`], optionally with each component's cone [`refine`]d by exact tests at its
/// boundary.
pub fn gac_with(
    backend: &dyn Backend,
    scene: &Scene,
    from: &P3,
    comps: &[Component],
    n: u32,
    preferred: &[V3],
    exact: bool,
) -> CubeMap {
    gac_within(backend, scene, from, comps, (n, preferred), exact, None)
}

/// [`gac_with`], right on the cells of `within` (all cells when None); elsewhere it may
/// hold more. Each component after the first is needed only where those before leave
/// the probe free (and within `within`), so it is drawn for those cells alone
/// ([`Backend::blocked_within`]); refined cones are drawn whole, their boundary being
/// what refining reads.
fn gac_within(
    backend: &dyn Backend,
    scene: &Scene,
    from: &P3,
    comps: &[Component],
    (n, preferred): (u32, &[V3]),
    exact: bool,
    within: Option<&CubeMap>,
) -> CubeMap {
    let mut blocked = match within {
        Some(w) if !exact => w.not(),
        _ => CubeMap::empty(n, preferred),
    };
    for (k, c) in comps.iter().enumerate() {
        let mut b = if exact || (k == 0 && within.is_none()) {
            backend.blocked(scene, from, c, n, preferred)
        } else {
            backend.blocked_within(scene, from, c, n, preferred, &blocked.not())
        };
        if exact && c.radius > 0.0 {
            refine(scene, from, c, &mut b);
        }
        blocked.or_assign(&b);
        if blocked.is_full() {
            break;
        }
    }
    blocked.not()
}

/// Whether the tip ball of radius `r` centred at `c` stays clear of the scene, up to
/// the mesh's chordal error (a tenth of the radius).
pub fn tip_fits(scene: &Scene, c: &P3, r: f64) -> bool {
    scene.distance(c) >= pose::TIP_CLEARANCE * r
}

/// What to compute for a point.
#[derive(Debug, Clone)]
pub struct ConeOptions {
    /// Cube-map resolution N.
    pub n: u32,
    /// Preferred directions (exact axes and the like), shared by every cone.
    pub preferred: Vec<V3>,
    /// The retract distance along the normal (mm): approach cones hold at the contact
    /// and at the retract point.
    pub retract: f64,
    /// How many points of dD1 the weak GAC D2 samples.
    pub d2_samples: usize,
    /// Refine the grown components' cones with exact parry tests at their boundaries
    /// ([`refine`]): slower, and exact at the pixel centres it reaches.
    pub exact_boundary: bool,
    /// Which backend rasterizes the shadows.
    pub backend: BackendKind,
    /// The setups D2 is asked about, when the caller masks it by them (the planner: the
    /// realisable, unforbidden ones); D2 may then leave out other cells (see [`d2`]).
    pub d2_wanted: Option<Arc<D2Wanted>>,
}

/// The cells D2 is asked about ([`ConeOptions::d2_wanted`]), with their map at D2's
/// coarser resolution made once for every point that shares them (coarsening the
/// 24,600 cells of a sphere in a chuck for each point was 1.6 % of its build).
#[derive(Debug)]
pub struct D2Wanted {
    map: CubeMap,
    coarse: std::sync::OnceLock<CubeMap>,
}

impl D2Wanted {
    /// The cells of `map` (at the cones' resolution).
    pub fn new(map: CubeMap) -> D2Wanted {
        D2Wanted {
            map,
            coarse: std::sync::OnceLock::new(),
        }
    }

    /// The wanted cells at resolution `n`, a divisor of the map's.
    fn at(&self, n: u32) -> CubeMap {
        if n == d2_resolution(self.map.n()) {
            self.coarse.get_or_init(|| self.map.coarsened(n)).clone()
        } else {
            self.map.coarsened(n)
        }
    }
}

impl Default for ConeOptions {
    fn default() -> Self {
        ConeOptions {
            n: 64,
            preferred: axes(),
            retract: 2.0,
            d2_samples: 16,
            exact_boundary: false,
            backend: BackendKind::Cpu,
            d2_wanted: None,
        }
    }
}

/// The six axis directions, the usual preferred directions.
pub fn axes() -> Vec<V3> {
    vec![V3::x(), -V3::x(), V3::y(), -V3::y(), V3::z(), -V3::z()]
}

/// The cones of one fpoint under one probe.
#[derive(Debug, Clone, PartialEq)]
pub struct PointCones {
    /// Whether the tip ball fits at the point.
    pub tip_fits: bool,
    /// Straight probe: the probe directions that clear every component at the contact and
    /// at the retract point. Bent probe: D1 at both (the first component's cone).
    pub approach: CubeMap,
    /// Bent probe only: D2, the second component's directions (the setup's vertical)
    /// from which at least one point of dD1 is reachable.
    pub d2: Option<CubeMap>,
}

/// The approach cone of [`point_cones`] alone (no D2): the tip centre and the probe
/// directions that clear the leading components at the contact and the retract point;
/// `None` when the tip does not fit or has no room to touch.
pub fn approach_cone(
    backend: &dyn Backend,
    scene: &Scene,
    f: &Fpoint,
    probe: &ProbeShape,
    opts: &ConeOptions,
) -> Option<CubeMap> {
    approach_at(backend, scene, f, probe, opts).map(|(_, cone)| cone)
}

fn approach_at(
    backend: &dyn Backend,
    scene: &Scene,
    f: &Fpoint,
    probe: &ProbeShape,
    opts: &ConeOptions,
) -> Option<(P3, CubeMap)> {
    let (n, pref) = (opts.n, &opts.preferred[..]);
    let (c, retract) = stand(scene, f, probe, opts)?;
    let comps = probe.leading();
    let exact = opts.exact_boundary;
    let mut approach = gac_with(backend, scene, &c, &comps, n, pref, exact);
    if let Some(retract) = retract.filter(|_| !approach.is_empty()) {
        // Needed only where the contact leaves the probe free.
        let at_retract = gac_within(
            backend,
            scene,
            &retract,
            &comps,
            (n, pref),
            exact,
            Some(&approach),
        );
        approach.and_assign(&at_retract);
    }
    Some((c, approach))
}

/// Where the probe stands to touch `f`: the tip centre, and the retract point when the
/// approach is tested there too; None when the tip does not fit or has no room to touch.
/// In a narrow feature the retract point moves in (see `pose::backoff`); there the
/// contact's cone alone stands, and validation sweeps the real approach.
fn stand(
    scene: &Scene,
    f: &Fpoint,
    probe: &ProbeShape,
    opts: &ConeOptions,
) -> Option<(P3, Option<P3>)> {
    let r = probe.tip_radius;
    let c = f.tip_centre(r);
    if !tip_fits(scene, &c, r)
        || !pose::room_to_touch(scene, &f.position, &f.normal, r, opts.retract)
    {
        return None;
    }
    let travel = pose::backoff(scene, &f.position, &f.normal, r, opts.retract);
    let retract =
        (opts.retract > 0.0 && travel >= opts.retract).then(|| c + f.normal * opts.retract);
    Some((c, retract))
}

impl PointCones {
    /// The cones of a point whose tip does not fit: all empty.
    fn unreachable(probe: &ProbeShape, n: u32, pref: &[V3]) -> PointCones {
        PointCones {
            tip_fits: false,
            approach: CubeMap::empty(n, pref),
            d2: probe.head.indexable().then(|| CubeMap::empty(n, pref)),
        }
    }
}

/// The cones of one fpoint under one probe. A tip that does not fit gives empty cones.
pub fn point_cones(
    backend: &dyn Backend,
    scene: &Scene,
    f: &Fpoint,
    probe: &ProbeShape,
    opts: &ConeOptions,
) -> PointCones {
    let (n, pref) = (opts.n, &opts.preferred[..]);
    let Some((c, approach)) = approach_at(backend, scene, f, probe, opts) else {
        return PointCones::unreachable(probe, n, pref);
    };
    let d2 = probe
        .head
        .indexable()
        .then(|| d2(backend, scene, &c, probe, &approach, opts));
    PointCones {
        tip_fits: true,
        approach,
        d2,
    }
}

/// D1 (ch. 2.5.1): the first component's cone, the truncated (0, d) family.
pub fn d1(
    backend: &dyn Backend,
    scene: &Scene,
    c: &P3,
    probe: &ProbeShape,
    n: u32,
    pref: &[V3],
) -> CubeMap {
    gac(backend, scene, c, &probe.first, n, pref)
}

/// D2 (ch. 2.5.2): the weak GAC of dD1, the union of the second component's cones at up
/// to `opts.d2_samples` points c + d·u, u spread evenly over D1's cells (a lower bound).
///
/// With `opts.d2_wanted` (the setups a plan can use: the caller masks D2 by them) sampling stops
/// once D2 holds every wanted cell, and a sample whose components block every wanted
/// cell D2 still lacks adds nothing (its later components are not drawn). Each sample is
/// decided only on the wanted cells D2 still lacks, so D2 is the same on the wanted
/// cells and holds none of the others; [`D2Sampler`] is the rule.
pub fn d2(
    backend: &dyn Backend,
    scene: &Scene,
    c: &P3,
    probe: &ProbeShape,
    d1: &CubeMap,
    opts: &ConeOptions,
) -> CubeMap {
    // `preferred` is the list D1 was built with: rebuilt from D1's unit vectors, a
    // direction that normalizing does not leave fixed would key differently.
    let preferred = &opts.preferred[..];
    let coarse = d2_resolution(d1.n());
    let mut d2 = D2Sampler::new(coarse, preferred, opts.d2_wanted.as_deref());
    // Drawing stops early only for a few wanted cells: each needs its own discs.
    let few = d2.wanted.as_ref().is_some_and(|w| w.count() <= FEW_WANTED);
    for x in d2_points(c, probe, d1, opts.d2_samples) {
        let Some(need) = d2.need() else { break };
        let mut blocked = CubeMap::empty(coarse, preferred);
        // The ram first: it blocks the most, so the head is drawn less often. A sample
        // adds nothing once its components block every cell still needed, so drawing
        // stops as soon as they do; either order gives the same D2.
        for (ci, comp) in probe.second.iter().rev().enumerate() {
            let b = match &need {
                Some(nd) if few => {
                    let mut rest = nd.clone();
                    rest.and_not_assign(&blocked);
                    backend.blocked_until(scene, &x, comp, coarse, preferred, &rest)
                }
                _ if ci > 0 => {
                    // Needed only where the components before leave the probe free.
                    let mut rest = blocked.not();
                    if let Some(nd) = &need {
                        rest.and_assign(nd);
                    }
                    backend.blocked_within(scene, &x, comp, coarse, preferred, &rest)
                }
                _ => backend.blocked(scene, &x, comp, coarse, preferred),
            };
            blocked.or_assign(&b);
            if blocked.is_full() || need.as_ref().is_some_and(|nd| blocked.covers(nd)) {
                break;
            }
        }
        d2.add(&blocked, need.as_ref());
    }
    d2.out.refined(d1.n())
}

/// How many wanted cells [`d2`] may wait for (see [`Backend::blocked_until`]); more,
/// and the discs it would keep per cell cost more than stopping early saves.
const FEW_WANTED: usize = 256;

/// D2's union of samples, in sample order, under its `wanted` cells (see [`d2`]); the
/// CPU path and the batched one share it so both give the same maps.
struct D2Sampler {
    out: CubeMap,
    wanted: Option<CubeMap>,
}

impl D2Sampler {
    fn new(coarse: u32, preferred: &[V3], wanted: Option<&D2Wanted>) -> D2Sampler {
        D2Sampler {
            out: CubeMap::empty(coarse, preferred),
            wanted: wanted.map(|w| w.at(coarse)),
        }
    }

    /// The wanted cells D2 lacks (`Some(None)` when every cell is wanted); None when it
    /// has them all and no later sample matters.
    fn need(&self) -> Option<Option<CubeMap>> {
        match &self.wanted {
            None => Some(None),
            Some(w) => {
                let mut need = w.clone();
                need.and_not_assign(&self.out);
                (!need.is_empty()).then_some(Some(need))
            }
        }
    }

    /// Adds one sample's free directions among the cells still needed (every cell
    /// without wanted ones): a map drawn only for those may hold too few blocked cells
    /// elsewhere.
    fn add(&mut self, blocked: &CubeMap, need: Option<&CubeMap>) {
        let mut free = blocked.not();
        if let Some(nd) = need {
            free.and_assign(nd);
        }
        self.out.or_assign(&free);
    }
}

/// The resolution D2 is rasterized at for cones of resolution `n`: half of it from 32
/// up. The head and ram are wide (a pixel at N = 32 is under 4°), and a cone of grown
/// components is free only where every direction of a pixel is, so a coarse free pixel
/// frees its four fine ones soundly; a quarter of the pixels to draw, where D2 was over
/// half of a real part's planning.
fn d2_resolution(n: u32) -> u32 {
    if n >= 32 && n.is_multiple_of(2) {
        n / 2
    } else {
        n
    }
}

/// The articulation points [`d2`] samples: c + d·u for up to `samples` directions u
/// spread evenly over D1's cells.
fn d2_points(c: &P3, probe: &ProbeShape, d1: &CubeMap, samples: usize) -> Vec<P3> {
    let cells: Vec<Cell> = d1.cells().collect();
    if cells.is_empty() || samples == 0 {
        return Vec::new();
    }
    let step = cells.len().div_ceil(samples).max(1);
    cells
        .iter()
        .skip(step / 2)
        .step_by(step)
        .map(|cell| c + d1.direction(*cell) * probe.reach())
        .collect()
}

/// D1′ (ch. 2.5.3): the directions of D1 whose articulation point c + d·u lets the second
/// component, pointing along `v2`, clear the scene — read off an orthographic depth map
/// along `v2`, as the seed does.
pub fn d1_prime(scene: &Scene, c: &P3, probe: &ProbeShape, d1: &CubeMap, v2: &V3) -> CubeMap {
    let radius = probe.second.iter().map(|s| s.radius).fold(0.0, f64::max);
    let depth = heightmap::HeightMap::new(scene, c, probe.reach() + radius, v2, radius);
    let mut out = d1.empty_like();
    for cell in d1.cells() {
        let x = c + d1.direction(cell) * probe.reach();
        if depth.clear(&x) {
            out.set(cell, true);
        }
    }
    out
}

/// The depth map the second component of a bent probe is tested against in one setup
/// (ch. 2.5.3): the part seen along `v2`, dilated by the head's and ram's radius, wide
/// enough for any articulation point within `reach` of the part. One map serves every
/// fpoint of the setup.
pub struct SecondMap(heightmap::HeightMap);

impl SecondMap {
    /// The map for second components of radius `radius` along `v2`.
    pub fn new(scene: &Scene, v2: &V3, radius: f64, reach: f64) -> SecondMap {
        let mut lo = P3::new(f64::MAX, f64::MAX, f64::MAX);
        let mut hi = P3::new(f64::MIN, f64::MIN, f64::MIN);
        for v in scene.tris.iter().flat_map(|t| t.v.iter()) {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        let centre = if lo.x <= hi.x {
            nalgebra::center(&lo, &hi)
        } else {
            P3::origin()
        };
        let half = scene.size / 2.0 + reach + radius + 1.0;
        SecondMap(heightmap::HeightMap::new(scene, &centre, half, v2, radius))
    }

    /// Whether the second component standing on articulation point `x` clears the part.
    pub fn clear(&self, x: &P3) -> bool {
        self.0.clear(x)
    }
}

/// A feature's cone: the intersection of its points' cones (ch. 2.3).
pub fn feature_cone<'a>(cones: impl IntoIterator<Item = &'a CubeMap>) -> Option<CubeMap> {
    let mut it = cones.into_iter();
    let mut acc = it.next()?.clone();
    for c in it {
        acc.and_assign(c);
    }
    Some(acc)
}

/// [`point_cones`] for many fpoints, in parallel; the result is in the fpoints' order and
/// the same for any number of threads.
pub fn cones(
    backend: &dyn Backend,
    scene: &Scene,
    fpoints: &[Fpoint],
    probe: &ProbeShape,
    opts: &ConeOptions,
) -> Vec<PointCones> {
    fpoints
        .par_iter()
        .map(|f| point_cones(backend, scene, f, probe, opts))
        .collect()
}

/// [`gac_halfline`] at many points (as tip centres), in their order: on a batching
/// backend in one pass, otherwise in parallel.
pub fn gac_halfline_many(
    backend: &dyn Backend,
    scene: &Scene,
    points: &[P3],
    n: u32,
    preferred: &[V3],
) -> Vec<CubeMap> {
    let half = Component::half_line();
    if backend.batches() {
        let queries: Vec<Query> = points
            .iter()
            .map(|p| Query {
                from: *p,
                comp: &half,
            })
            .collect();
        return backend
            .blocked_many(scene, &queries, n, preferred)
            .into_iter()
            .map(|b| b.not())
            .collect();
    }
    points
        .par_iter()
        .map(|p| backend.blocked(scene, p, &half, n, preferred).not())
        .collect()
}

/// [`point_cones`] for many (fpoint, probe) pairs, in their order and the same for any
/// thread count. A batching backend gets every approach query in one call and every D2
/// sample in a second; the cones are those [`point_cones`] gives with that backend.
pub fn point_cones_many(
    backend: &dyn Backend,
    scene: &Scene,
    items: &[(&Fpoint, &ProbeShape)],
    opts: &ConeOptions,
) -> Vec<PointCones> {
    if !backend.batches() || opts.exact_boundary {
        return items
            .par_iter()
            .map(|(f, probe)| point_cones(backend, scene, f, probe, opts))
            .collect();
    }
    let (n, pref) = (opts.n, &opts.preferred[..]);
    // Where each pair's probe stands: None when the tip does not fit; else the tip
    // centre and, when the retract point is tested too, the retract point.
    let stands: Vec<Option<(P3, Option<P3>)>> = items
        .par_iter()
        .map(|(f, probe)| stand(scene, f, probe, opts))
        .collect();
    let leading: Vec<Vec<Component>> = items.iter().map(|(_, p)| p.leading()).collect();
    // The approach: every leading component at the contact and at the retract point.
    let mut queries: Vec<Query> = Vec::new();
    let mut owner: Vec<(usize, bool)> = Vec::new();
    for (k, stand) in stands.iter().enumerate() {
        let Some((c, retract)) = stand else { continue };
        for (at, second) in std::iter::once((c, false)).chain(retract.iter().map(|r| (r, true))) {
            for comp in &leading[k] {
                queries.push(Query { from: *at, comp });
                owner.push((k, second));
            }
        }
    }
    let blocked = backend.blocked_many(scene, &queries, n, pref);
    let mut at_contact: Vec<CubeMap> = vec![CubeMap::empty(n, pref); items.len()];
    let mut at_retract: Vec<Option<CubeMap>> = vec![None; items.len()];
    for (&(k, second), b) in owner.iter().zip(&blocked) {
        if second {
            at_retract[k]
                .get_or_insert_with(|| CubeMap::empty(n, pref))
                .or_assign(b);
        } else {
            at_contact[k].or_assign(b);
        }
    }
    let approach: Vec<CubeMap> = at_contact
        .into_iter()
        .zip(at_retract)
        .map(|(c, r)| {
            let mut a = c.not();
            if let Some(r) = r {
                if !a.is_empty() {
                    a.and_assign(&r.not());
                }
            }
            a
        })
        .collect();
    // D2: the second components at the sampled articulation points of each D1.
    let mut queries: Vec<Query> = Vec::new();
    let mut owner: Vec<(usize, usize)> = Vec::new();
    let mut samples = 0;
    for (k, (_, probe)) in items.iter().enumerate() {
        let Some((c, _)) = stands[k] else { continue };
        if !probe.head.indexable() {
            continue;
        }
        for x in d2_points(&c, probe, &approach[k], opts.d2_samples) {
            for comp in &probe.second {
                queries.push(Query { from: x, comp });
                owner.push((k, samples));
            }
            samples += 1;
        }
    }
    let coarse = d2_resolution(n);
    let blocked = backend.blocked_many(scene, &queries, coarse, pref);
    let mut sample_blocked: Vec<Option<(usize, CubeMap)>> = vec![None; samples];
    for (&(k, s), b) in owner.iter().zip(&blocked) {
        sample_blocked[s]
            .get_or_insert_with(|| (k, CubeMap::empty(coarse, pref)))
            .1
            .or_assign(b);
    }
    // Every sample was drawn; the samples are added as `d2` adds them, so the maps match.
    let wanted = opts.d2_wanted.as_deref();
    let mut d2s: Vec<Option<D2Sampler>> = items
        .iter()
        .map(|(_, p)| {
            p.head
                .indexable()
                .then(|| D2Sampler::new(coarse, pref, wanted))
        })
        .collect();
    for (k, b) in sample_blocked.into_iter().flatten() {
        if let Some(d) = &mut d2s[k] {
            if let Some(need) = d.need() {
                d.add(&b, need.as_ref());
            }
        }
    }
    let d2s: Vec<Option<CubeMap>> = d2s
        .into_iter()
        .map(|d| d.map(|d| d.out.refined(n)))
        .collect();
    items
        .iter()
        .zip(&stands)
        .zip(approach.into_iter().zip(d2s))
        .map(|((&(_, probe), stand), (approach, d2))| match stand {
            None => PointCones::unreachable(probe, n, pref),
            Some(_) => PointCones {
                tip_fits: true,
                approach,
                d2,
            },
        })
        .collect()
}

/// The probe direction of an indexable head at angles A (tilt from vertical) and B
/// (rotation about vertical), in degrees: the unit vector from the stylus tip towards the
/// head, in the machine frame. A = 0 hangs the stylus straight down, so the probe
/// approaches from +z; A = 90°, B = 0 lays it horizontal, reaching from +x.
pub fn head_direction(a_deg: f64, b_deg: f64) -> V3 {
    let (a, b) = (a_deg.to_radians(), b_deg.to_radians());
    V3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos())
}

/// The orientations of a head's grid whose direction is in the cone, in grid order.
pub fn orientations_in(cone: &CubeMap, orientations: &[(f64, f64)]) -> Vec<(f64, f64)> {
    orientations
        .iter()
        .copied()
        .filter(|&(a, b)| cone.contains(&head_direction(a, b)))
        .collect()
}

/// The cone of a set of orientations: the cells their directions fall in.
pub fn orientation_cone(orientations: &[(f64, f64)], n: u32, preferred: &[V3]) -> CubeMap {
    let mut c = CubeMap::empty(n, preferred);
    for &(a, b) in orientations {
        let cell = c.cell_of(&head_direction(a, b));
        c.set(cell, true);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_directions() {
        assert!((head_direction(0.0, 0.0) - V3::z()).norm() < 1e-12);
        assert!((head_direction(90.0, 0.0) - V3::x()).norm() < 1e-12);
        assert!((head_direction(90.0, 90.0) - V3::y()).norm() < 1e-12);
    }

    #[test]
    fn orientation_cone_round_trips() {
        let grid: Vec<(f64, f64)> = (0..=14)
            .flat_map(|a| (0..48).map(move |b| (a as f64 * 7.5, -180.0 + b as f64 * 7.5)))
            .collect();
        let c = orientation_cone(&grid, 64, &[V3::z()]);
        // Every orientation's own cell is in the cone; A = 0 is the exact +z.
        assert_eq!(orientations_in(&c, &grid).len(), grid.len());
        assert!(c.get(Cell::Preferred(0)));
    }

    #[test]
    fn a_single_triangle_blocks_what_is_behind_it() {
        let tri = [[
            P3::new(-1.0, -1.0, 1.0),
            P3::new(1.0, -1.0, 1.0),
            P3::new(0.0, 1.0, 1.0),
        ]];
        let gac = gac_halfline(&Scene::of_triangles(&tri), &P3::origin(), 32, &[V3::z()]);
        assert!(!gac.contains(&V3::z()));
        assert!(!gac.contains(&V3::new(0.0, -0.9, 1.0)));
        assert!(gac.contains(&V3::new(0.0, 0.0, -1.0)));
        assert!(gac.contains(&V3::new(1.0, 1.0, 1.0)));
    }
}
