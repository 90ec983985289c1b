//! The coat at a subsurface hit xo (`docs/bssrdf.md` §6, "The coat"): it
//! reflects Fr (smooth) or E(μo) (rough) and passes the rest into the
//! medium, where the probes find the entry point ([`super::entries`]).

use super::entries::{entries, Entries};
use crate::fresnel;
use crate::geometry::{Ray, Vec3};
use crate::integrator::aov::{Event, Recorder};
use crate::integrator::branch::MAX_BRANCHES;
use crate::integrator::coated::Weighted;
use crate::integrator::lobe::{Bounce, Lobe, SubsurfaceLobe, Vertex};
use crate::integrator::scatter::{Scatter, SubsurfaceHit};
use crate::integrator::state::PathState;
use crate::integrator::{Context, Interaction};
use crate::materials::microfacet::{reflect, RoughCoat};
use crate::sampling::Draw;

/// Smooth-coated subsurface hits at depths below this split into the
/// mirror reflection and the medium (both followed); deeper ones choose
/// one. 1: the camera vertex only (`docs/bssrdf.md` §6, "The coat").
pub(crate) const COAT_SPLIT_DEPTH: u32 = 1;
const _: () = assert!(COAT_SPLIT_DEPTH as usize <= MAX_BRANCHES);

/// A subsurface hit at xo under the diffusion model: the coat at xo, then
/// the probe(s) for the entry point xi, where the path continues with the
/// entry lobe. Without `specular` the reflection is dropped and the medium
/// weighted by 1 − Fr or 1 − E. After a non-specular vertex the coat is
/// the regularized one where the material has it (`docs/bssrdf.md` §6,
/// "Regularized coat"): its reflection is light-sampled, so the caustics a
/// mirror would make are found by next-event estimation with MIS.
#[inline(never)]
pub(super) fn scatter<'s, R: Recorder>(
    ctx: &Context,
    hit: &SubsurfaceHit<'_, 's>,
    beta: &mut Vec3,
    st: &mut PathState<R>,
) -> Scatter<'s> {
    let coat = if hit.scattered {
        hit.ss.coat_after_diffuse()
    } else {
        hit.ss.rough_coat()
    };
    match coat {
        None => smooth(ctx, hit, beta, st),
        Some(rc) => rough(ctx, rc, hit, beta, st),
    }
}

/// The smooth coat, a mirror reflecting Fr: at depths below
/// [`COAT_SPLIT_DEPTH`] both the reflection and the medium are
/// followed; deeper, the reflection is taken with probability Fr (weight
/// 1) and the medium otherwise (weight 1).
#[inline(always)]
fn smooth<'s, R: Recorder>(
    ctx: &Context,
    hit: &SubsurfaceHit<'_, 's>,
    beta: &mut Vec3,
    st: &mut PathState<R>,
) -> Scatter<'s> {
    let (ss, si, wo) = (hit.ss, hit.si, hit.wo);
    // Boundary at xo: the normal facing the camera is "outside"
    // (a mesh wound inside-out is read consistently the other way).
    let n_out = if si.front { si.ng } else { -si.ng };
    let beta_in = *beta;
    let split = hit.depth < COAT_SPLIT_DEPTH;
    let fr = fresnel::dielectric(wo.dot(n_out).max(0.0), ss.eta());
    if !ss.specular() {
        *beta *= 1.0 - fr;
    } else if split {
        *beta *= 1.0 - fr;
        let reflected = Bounce {
            ray: mirror(ctx, si, wo, n_out),
            beta: beta_in * fr,
            prev: None,
        };
        let e = entries(ctx, hit, beta, st);
        return Scatter::Coated(e.under(None, Some(reflected)));
    } else if st.rng.uniform() < fr {
        // Specular reflection with probability Fr: weight 1.
        return Scatter::Continue(mirror(ctx, si, wo, n_out), Event::Specular);
    }
    entries(ctx, hit, beta, st).into_scatter()
}

/// The rough coat: a lobe with next-event estimation at xo every time;
/// the path goes on by its reflection with probability E (its weight
/// divided by E in the lobe's sample), else into the medium (weight
/// (1 − E)/(1 − E) = 1). Where the shading normal faces away from ωo it
/// reflects nothing and everything enters.
#[inline(always)]
fn rough<'s, R: Recorder>(
    ctx: &Context,
    rc: &'s RoughCoat,
    hit: &SubsurfaceHit<'_, 's>,
    beta: &mut Vec3,
    st: &mut PathState<R>,
) -> Scatter<'s> {
    let (ss, si, wo) = (hit.ss, hit.si, hit.wo);
    let n_out = if si.front { si.ng } else { -si.ng };
    let beta_in = *beta;
    let frame = si.shading_frame_facing(wo);
    let wo_local = frame.to_local(wo);
    let e = if wo_local.z > 0.0 {
        rc.albedo(wo_local.z)
    } else {
        0.0
    };
    if !ss.specular() || e <= 0.0 {
        *beta *= 1.0 - e;
        return entries(ctx, hit, beta, st).into_scatter();
    }
    let vertex = Vertex {
        p: si.p,
        ng: n_out,
        frame,
        wo_local,
        lobe: Lobe::Subsurface(SubsurfaceLobe::Coat {
            coat: rc,
            select: e,
        }),
        outside_of: ctx.leaving(si.geom, si.front),
    };
    if st.rng.uniform() < e {
        let reflected = vertex.bounce(ctx.ray_epsilon, beta_in, st.rng.uniform2_packed());
        let coat = Weighted {
            vertex,
            beta: beta_in,
        };
        return Scatter::Coated(Entries::none().under(Some(coat), reflected));
    }
    let e = entries(ctx, hit, beta, st);
    let coat = Weighted {
        vertex,
        beta: beta_in,
    };
    Scatter::Coated(e.under(Some(coat), None))
}

/// The smooth coat's reflection: the mirror direction about the shading
/// normal, which keeps highlights smooth on tessellated meshes; where it
/// would reflect below the surface the geometric normal is used instead.
fn mirror(ctx: &Context, si: &Interaction, wo: Vec3, n_out: Vec3) -> Ray {
    si.spawn(mirror_direction(wo, si.ns, n_out), ctx.ray_epsilon)
}

/// `wo` reflected about the shading normal `ns` (either orientation),
/// or about the geometric normal `n_out` (the side `wo` is on) where the
/// former would go below the surface.
fn mirror_direction(wo: Vec3, ns: Vec3, n_out: Vec3) -> Vec3 {
    let ns_out = if ns.dot(n_out) >= 0.0 { ns } else { -ns };
    let wi = reflect(wo, ns_out);
    if wi.dot(n_out) > 0.0 {
        wi
    } else {
        reflect(wo, n_out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Angle of reflection equals angle of incidence, in the plane of `wo`
    /// and `n`: `wi + wo` is along `n` and `wi·n = wo·n`.
    fn assert_mirror(wi: Vec3, wo: Vec3, n: Vec3) {
        assert!((wi.length() - 1.0).abs() < 1e-5, "{wi}");
        assert!((wi.dot(n) - wo.dot(n)).abs() < 1e-5, "{wi} {wo} {n}");
        assert!((wi + wo).cross(n).length() < 1e-5, "{wi} {wo} {n}");
    }

    #[test]
    fn the_coat_mirrors_about_the_shading_normal_or_the_geometric_one_below_it() {
        let ng = Vec3::Z;
        // A shading normal tilted 40° towards +x, given either way round.
        let ns = Vec3::new(40f32.to_radians().sin(), 0.0, 40f32.to_radians().cos());
        for ns in [ns, -ns] {
            // Steep incidence: the shading mirror stays above the surface.
            let wo = Vec3::new(0.2, 0.1, 1.0).normalize();
            let wi = mirror_direction(wo, ns, ng);
            assert!(wi.dot(ng) > 0.0);
            assert_mirror(wi, wo, ns);
            // Grazing from −x: about ns the reflection would point below
            // the surface, so it is the mirror about ng.
            let wo = Vec3::new(-0.95, 0.1, 0.2).normalize();
            let ns_up = if ns.dot(ng) >= 0.0 { ns } else { -ns };
            let below = reflect(wo, ns_up);
            assert!(
                below.dot(ng) <= 0.0,
                "the case is not the fallback: {below}"
            );
            let wi = mirror_direction(wo, ns, ng);
            assert!(wi.dot(ng) > 0.0);
            assert_mirror(wi, wo, ng);
        }
        // Seen from below (n_out = −ng) the same holds on that side.
        let wo = Vec3::new(0.95, -0.1, -0.2).normalize();
        let wi = mirror_direction(wo, ns, -ng);
        assert!(wi.dot(-ng) > 0.0);
        assert_mirror(wi, wo, -ng);
    }
}
