//! Cones of many points at once, in parallel and in input order: the half-lines of many
//! points in one backend call, and every component of many points' probes batched per
//! submission.

use super::cones::{d2_points, d2_resolution, stand, D2Sampler};
use super::{
    point_cones, Backend, Component, ConeOptions, CubeMap, PointCones, ProbeShape, Query, Scene,
};
use crate::geometry::{P3, V3};
use crate::sample::Fpoint;
use rayon::prelude::*;

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

/// [`super::gac_halfline`] at many points (as tip centres), in their order: on a batching
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
