//! The seed's cones for one point (Spitz, ch. 2; paper 001): the half-line GAC, grown and
//! truncated half-lines of any component, D1, D2 (the weak GAC over dD1), D1′ for a
//! chosen second-component direction, approach and retract cones, feature cones as
//! intersections.
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
//! bent probes) plus D2; the batched forms of many points are in `batch.rs`.

use super::{
    heightmap, pose, refine, Backend, Cell, Component, ConeOptions, Cpu, CubeMap, D2Wanted,
    ProbeShape, Scene,
};
use crate::geometry::{P3, V3};
use crate::sample::Fpoint;

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
pub(crate) fn gac_with(
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
pub(super) fn gac_within(
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

pub(super) fn approach_at(
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
pub(super) fn stand(
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
    pub(super) fn unreachable(probe: &ProbeShape, n: u32, pref: &[V3]) -> PointCones {
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
pub(super) const FEW_WANTED: usize = 256;

/// D2's union of samples, in sample order, under its `wanted` cells (see [`d2`]); the
/// CPU path and the batched one share it so both give the same maps.
pub(super) struct D2Sampler {
    pub(super) out: CubeMap,
    wanted: Option<CubeMap>,
}

impl D2Sampler {
    pub(super) fn new(coarse: u32, preferred: &[V3], wanted: Option<&D2Wanted>) -> D2Sampler {
        D2Sampler {
            out: CubeMap::empty(coarse, preferred),
            wanted: wanted.map(|w| w.at(coarse)),
        }
    }

    /// The wanted cells D2 lacks (`Some(None)` when every cell is wanted); None when it
    /// has them all and no later sample matters.
    pub(super) fn need(&self) -> Option<Option<CubeMap>> {
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
    pub(super) fn add(&mut self, blocked: &CubeMap, need: Option<&CubeMap>) {
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
pub(super) fn d2_resolution(n: u32) -> u32 {
    if n >= 32 && n.is_multiple_of(2) {
        n / 2
    } else {
        n
    }
}

/// The articulation points [`d2`] samples: c + d·u for up to `samples` directions u
/// spread evenly over D1's cells.
pub(super) fn d2_points(c: &P3, probe: &ProbeShape, d1: &CubeMap, samples: usize) -> Vec<P3> {
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

#[cfg(test)]
mod tests {
    use super::*;

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
