//! The probe query of the BSSRDF's area integral (pbrt-v4 §15.4's split
//! between `SubsurfaceMaterial`'s BSSRDF and the integrator): the BSSRDF
//! samples a probe segment ([`ProbeSampler::sample_probe`]), the integrator
//! asks the accel for every hit of the segment on the exit point's object
//! ([`Accel::hits_on_segment`]), keeps one ([`pick_by_score`]) and the BSSRDF
//! weighs it ([`ProbeSampler::weigh`]); `docs/bssrdf.md` §5. The tests
//! (`probe/tests.rs`) check the whole estimator end to end.

use crate::accel::{Accel, Hit, ProbeHits, MAX_PROBE_HITS};
use crate::bssrdf::{pick_by_score, ProbeRandoms, ProbeSampler, ProbeSegment};
use crate::geometry::{Frame, Mesh, Vec3};

/// The object a probe searches: mesh `geom` of `accel`, and that mesh (for
/// its face normals).
#[derive(Clone, Copy)]
pub struct ProbeTarget<'a> {
    pub accel: &'a dyn Accel,
    pub geom: u32,
    pub mesh: &'a Mesh,
}

/// One sampled entry point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProbeSample {
    /// The accel hit (mesh `geom`, triangle `prim`, barycentrics).
    pub hit: Hit,
    /// xi, reconstructed along the probe ray.
    pub point: Vec3,
    /// Unit geometric normal of the hit triangle, oriented by its winding
    /// (outward for a consistently wound closed mesh); not flipped toward xo.
    pub normal: Vec3,
    /// Rd(|xo − xi|) / p(xi) × (hits on the segment), per channel.
    pub weight: Vec3,
}

/// Samples an entry point xi for exit point `xo` (shading frame `frame`,
/// surface curvature `kappa` there, from
/// [`crate::geometry::curvature::exit_curvature`]) on `target` with
/// one probe: sample the segment, query all its hits on the object into
/// the scratch buffer `hits` (no allocation), pick one, weigh it. None when
/// the material samples nothing, the probe finds nothing, or the picked hit
/// has zero density; the estimate is then 0.
pub fn sample_entry(
    sampler: &ProbeSampler,
    xo: Vec3,
    frame: &Frame,
    kappa: f32,
    u: &ProbeRandoms,
    target: &ProbeTarget,
    hits: &mut ProbeHits,
) -> Option<ProbeSample> {
    // docs/bssrdf.md §5: steps 1–2 in the BSSRDF, step 3 here (every hit
    // on the object, one picked uniformly), step 4 in the BSSRDF.
    let seg = sampler.sample_probe(xo, frame, kappa, u)?;
    entry_on_segment(sampler, &seg, u, target, hits)
}

/// Steps 3–4 of [`sample_entry`] for a probe segment already sampled (by
/// [`ProbeSampler::sample_probe`], or one of
/// [`ProbeSampler::sample_probe_pair`]'s two) with randoms `u`: every hit
/// of `seg` on the object, one picked, weighed.
pub(crate) fn entry_on_segment(
    sampler: &ProbeSampler,
    seg: &ProbeSegment,
    u: &ProbeRandoms,
    target: &ProbeTarget,
    hits: &mut ProbeHits,
) -> Option<ProbeSample> {
    target
        .accel
        .hits_on_segment(&seg.ray, seg.t_max, target.geom, u.seed, hits);
    let kept = hits.hits();
    let (hit, normal, entry) = match kept {
        [] => return None,
        // one hit: kept with probability 1, weight Rd/p × total
        [hit] => {
            let normal = target.mesh.face_normal(hit.prim);
            (
                *hit,
                normal,
                sampler.weigh(seg, hit.t, normal, hits.total())?,
            )
        }
        // several: each weighed, one kept in proportion to its weight
        _ => {
            let mut entries = [None; MAX_PROBE_HITS];
            let mut scores = [0.0f32; MAX_PROBE_HITS];
            for ((e, s), hit) in entries.iter_mut().zip(&mut scores).zip(kept) {
                *e = sampler.weigh(seg, hit.t, target.mesh.face_normal(hit.prim), 1);
                *s = e.map_or(0.0, |e| e.weight.element_sum());
            }
            let (k, factor) = pick_by_score(u, &scores[..kept.len()], hits.total())?;
            // a picked hit has a score > 0, so it was weighed
            let mut entry = entries[k]?;
            entry.weight *= factor;
            (kept[k], target.mesh.face_normal(kept[k].prim), entry)
        }
    };
    Some(ProbeSample {
        hit,
        point: entry.point,
        normal,
        weight: entry.weight,
    })
}

#[cfg(test)]
mod tests;
