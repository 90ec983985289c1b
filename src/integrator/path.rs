//! Unidirectional path tracing (Kajiya 1986) of the rendering equation
//!
//!   L(x, ωo) = Le(x, ωo) + ∫ f(x, ωo, ωi) L(x', −ωi) |cos θi| dωi,
//!
//! estimated along one path per sample. At each diffuse vertex the direct
//! part of the integral is estimated twice — by sampling a point on an
//! area light (next-event estimation) and by sampling the BSDF and finding
//! a light — and the two are combined with the power heuristic (Veach 1997,
//! §9.2). Paths end at `max_depth` bounces or by Russian roulette once
//! their throughput is small (pbrt-v4 §13.1.1).

use super::interaction::offset_origin;
use super::{Context, Counters, Interaction};
use crate::geometry::{Frame, Ray, Vec3};
use crate::materials::{dielectric, diffuse, Material};
use crate::sampling::{power, Rng};

/// Bounces after which Russian roulette may end a path.
const RR_START: u32 = 3;

/// The radiance arriving along `ray` (from the camera): one sample of L.
pub fn radiance(ctx: &Context, camera_ray: Ray, rng: &mut Rng, counters: &mut Counters) -> Vec3 {
    let scene = ctx.scene;
    let eps = ctx.ray_epsilon;
    let mut l = Vec3::ZERO;
    // Path throughput: product of f |cos| / pdf along the path so far.
    let mut beta = Vec3::ONE;
    let mut ray = camera_ray;
    // Where the last non-specular vertex was and the solid-angle pdf its
    // BSDF sampling gave the current ray; None after the camera or a
    // specular bounce (no light sampling competed for this direction).
    let mut prev: Option<(Vec3, f32)> = None;

    for depth in 0..=scene.settings.max_depth {
        counters.rays += 1;
        let Some(hit) = ctx.accel.intersect(&ray, 0.0, f32::INFINITY) else {
            if ctx.plan.environment {
                l += beta * scene.environment.unwrap_or(Vec3::ZERO);
            }
            break;
        };
        let mesh = &scene.meshes[hit.geom as usize];
        let object = &scene.objects[hit.geom as usize];
        let si = Interaction::new(mesh, &ray, &hit);
        let wo = -ray.d;

        // Le: emitted radiance, MIS-weighted against next-event estimation.
        if let (Some(le), true) = (object.emission, si.front) {
            let w = match prev {
                None => 1.0,
                Some((p0, pdf_bsdf)) => {
                    let cos_l = wo.dot(si.ng);
                    let pdf_light =
                        ctx.lights.pdf_area(&scene.meshes, hit.geom, hit.prim) * (si.p - p0).length_squared() / cos_l;
                    power(pdf_bsdf, pdf_light)
                }
            };
            l += beta * le * w;
        }
        if depth == scene.settings.max_depth {
            break;
        }

        match &scene.materials[object.material] {
            Material::Diffuse { albedo } => {
                let frame = si.shading_frame_facing(wo);
                let wo_local = frame.to_local(wo);
                if ctx.plan.area_lights {
                    l += beta * direct_lighting(ctx, &si, &frame, *albedo, wo_local, rng, counters);
                }
                let Some((wi_local, weight, pdf)) = diffuse::sample(*albedo, wo_local, rng.uniform2()) else {
                    break;
                };
                let wi = frame.to_world(wi_local);
                // A shading normal can send wi through the geometric surface;
                // such a path would leak light, so it ends here.
                if wi.dot(si.ng) * wo.dot(si.ng) <= 0.0 {
                    break;
                }
                beta *= weight;
                prev = Some((si.p, pdf));
                ray = si.spawn(wi, eps);
            }
            Material::Dielectric { eta } => {
                let frame = Frame::from_normal(si.ng);
                let s = dielectric::sample(*eta, frame.to_local(wo), rng.uniform());
                beta *= s.weight;
                prev = None;
                ray = si.spawn(frame.to_world(s.wi), eps);
            }
        }

        if depth >= RR_START {
            let survive = beta.max_element().min(1.0);
            if survive <= 0.0 || rng.uniform() >= survive {
                break;
            }
            beta /= survive;
        }
    }
    l
}

/// Next-event estimation at a diffuse vertex: one light sample, weighted by
/// the power heuristic against BSDF sampling of the same direction.
fn direct_lighting(
    ctx: &Context,
    si: &Interaction,
    frame: &Frame,
    albedo: Vec3,
    wo_local: Vec3,
    rng: &mut Rng,
    counters: &mut Counters,
) -> Vec3 {
    let u_pick = rng.uniform();
    let u = rng.uniform2();
    let Some(ls) = ctx.lights.sample(ctx.scene, u_pick, u) else {
        return Vec3::ZERO;
    };
    let to_light = ls.point - si.p;
    let dist2 = to_light.length_squared();
    if dist2 <= 0.0 {
        return Vec3::ZERO;
    }
    let wi = to_light / dist2.sqrt();
    let cos_l = -wi.dot(ls.normal);
    let wi_local = frame.to_local(wi);
    let f = diffuse::eval(albedo, wo_local, wi_local);
    if cos_l <= 0.0 || f == Vec3::ZERO || wi.dot(si.ng) * wo_local.z.signum() * frame.n.dot(si.ng).signum() <= 0.0 {
        return Vec3::ZERO;
    }
    let pdf_light = ls.pdf_area * dist2 / cos_l;
    counters.rays += 1;
    let origin = offset_origin(si.p, si.ng, wi, ctx.ray_epsilon);
    // t is in units of |d| = the distance to the light point; stop just short
    // of it so the light's own triangle does not shadow itself.
    if ctx.accel.occluded(&Ray::new(origin, ls.point - origin), 0.0, 1.0 - 1e-4) {
        return Vec3::ZERO;
    }
    let w = power(pdf_light, diffuse::pdf(wo_local, wi_local));
    f * ls.radiance * (wi_local.z.abs() * w / pdf_light)
}
