//! Integrators: estimators of the radiance arriving at the camera.
//!
//! [`path`] is the unidirectional path tracer with next-event estimation
//! and multiple importance sampling. [`plan`] decides once per scene which
//! effects exist, so a scene pays only for what it uses. [`interaction`]
//! turns an accel hit into the local surface geometry shading needs.
//! [`probe`] runs the BSSRDF's probe query: the BSSRDF samples the segment
//! and weighs the hit, the integrator queries the accel.
//! [`randomwalk`] is the brute-force volumetric reference for subsurface
//! materials, selected with [`IntegratorKind`]; [`diffuse_boundary`] is
//! its optional diffuse Fresnel boundary model. [`aov`] records what the
//! passes (light paths, light groups, data, ID coverage) measure.
//! [`effects`] counts ray queries and time per effect for `--stats`.
//! [`control_variate`] is the probe estimator's plane control variate.
//! `probe`, `control_variate`, `randomwalk` and `diffuse_boundary` exist
//! only with the `subsurface` feature (the default).

pub mod aov;
#[cfg(feature = "subsurface")]
pub mod control_variate;
pub mod convex;
pub mod culling;
#[cfg(feature = "subsurface")]
pub mod diffuse_boundary;
pub mod effects;
pub mod interaction;
pub mod path;
pub mod plan;
#[cfg(feature = "subsurface")]
pub mod probe;
#[cfg(feature = "subsurface")]
pub mod randomwalk;
#[cfg(feature = "subsurface")]
pub mod sharp_edges;

use crate::accel::{Accel, Traversal};
use crate::lights::LightSet;
use crate::scene::Scene;

pub use crate::stats::Counters;
pub use effects::{Clock, Effect, NoClock, Stopwatch, EFFECTS};
pub use interaction::Interaction;
pub use plan::Plan;

/// Everything an integrator reads while rendering; built once per render.
pub struct Context<'a> {
    pub scene: &'a Scene,
    pub accel: &'a dyn Accel,
    pub lights: LightSet,
    pub plan: Plan,
    /// Minimum offset for spawned rays, from the scene's size.
    pub ray_epsilon: f32,
    /// Per mesh, what [`Interaction::new`] reads.
    pub shading: Vec<interaction::MeshShading>,
    /// Subsurface hits at depths below this sample an antithetic pair of
    /// entry points on materials with `probe_pair` on
    /// ([`path::PAIR_DEPTH`], the default: the camera vertex); 0 turns the
    /// pair off everywhere.
    pub pair_depth: u32,
    /// Subsurface hits at depths below this add the plane control variate
    /// on materials with `control_variate` on (the default;
    /// `control_variate::CV_DEPTH`: the camera vertex); 0 turns it off
    /// everywhere.
    pub cv_depth: u32,
    /// The camera's pixel angle, for the footprint cone of subsurface
    /// level of detail ([`crate::materials::lod`]).
    pub camera_spread: crate::materials::lod::CameraSpread,
    /// Rays proven to meet nothing ([`culling`]); None for scenes of more
    /// than [`culling::MAX_OBJECTS`] objects, and where a caller turns it
    /// off to compare (the pixels are the same either way).
    pub culling: Option<culling::Culling>,
    /// Per mesh with a subsurface material, its triangles' curvatures
    /// ([`probe::MeshCurvature`]); None for the others.
    #[cfg(feature = "subsurface")]
    pub curvature: Vec<Option<probe::MeshCurvature>>,
}

impl<'a> Context<'a> {
    pub fn new(scene: &'a Scene, accel: &'a dyn Accel) -> Self {
        let (lo, hi) = scene_bounds(scene);
        let extent = (hi - lo).max_element();
        let extent = if extent.is_finite() && extent > 0.0 {
            extent
        } else {
            1.0
        };
        let shading = scene
            .meshes
            .iter()
            .map(interaction::MeshShading::new)
            .collect();
        #[cfg(feature = "subsurface")]
        let curvature = scene
            .meshes
            .iter()
            .zip(&scene.objects)
            .map(|(m, o)| match &scene.materials[o.material] {
                crate::materials::Material::Subsurface(ss) => {
                    // only the `curvature` axis rule reads sharp edges
                    let reads_edges =
                        ss.probe.options().axes == crate::bssrdf::ProbeAxes::Curvature;
                    let reach = if reads_edges {
                        ss.probe.rmax() as f32
                    } else {
                        0.0
                    };
                    let c = probe::MeshCurvature::new(m, reach);
                    Some(match ss.curvature_correction() {
                        Some(cc) => c.with_factors(cc),
                        None => c,
                    })
                }
                _ => None,
            })
            .collect();
        let ray_epsilon = extent * 1e-6;
        Context {
            scene,
            accel,
            culling: culling::Culling::new(&scene.meshes, extent, ray_epsilon),
            lights: LightSet::new(scene),
            plan: Plan::new(scene),
            ray_epsilon,
            shading,
            pair_depth: path::PAIR_DEPTH,
            #[cfg(feature = "subsurface")]
            cv_depth: control_variate::CV_DEPTH,
            #[cfg(not(feature = "subsurface"))]
            cv_depth: 0,
            camera_spread: crate::materials::lod::CameraSpread::new(
                scene.camera.fov_y,
                scene.camera.height,
                scene.camera.look_at - scene.camera.look_from,
            ),
            #[cfg(feature = "subsurface")]
            curvature,
        }
    }

    /// The curvatures of triangle `prim` of mesh `geom`: the probe axes'
    /// ([`probe::exit_curvature`]) and the mean curvature
    /// ([`crate::bssrdf::curvature_correction::mean_curvature`]), from the
    /// cache where the mesh has one.
    #[cfg(feature = "subsurface")]
    #[inline]
    pub fn curvatures(&self, geom: u32, prim: u32) -> (f32, f32) {
        match &self.curvature[geom as usize] {
            Some(c) => (c.exit(prim), c.mean(prim)),
            None => {
                let m = &self.scene.meshes[geom as usize];
                (
                    probe::exit_curvature(m, prim),
                    crate::bssrdf::curvature_correction::mean_curvature(m, prim),
                )
            }
        }
    }

    /// f(κ) per channel of triangle `prim` of mesh `geom` under `cc`, its
    /// material's curvature correction, for its mean curvature: from the
    /// cache where the mesh has one ([`probe::MeshCurvature::factor`]).
    #[cfg(feature = "subsurface")]
    #[inline]
    pub fn curvature_factor(
        &self,
        geom: u32,
        prim: u32,
        cc: &crate::bssrdf::curvature_correction::CurvatureCorrection,
    ) -> [f32; 3] {
        match self.curvature[geom as usize]
            .as_ref()
            .and_then(|c| c.factor(prim))
        {
            Some(f) => f,
            None => cc.factor(self.curvatures(geom, prim).1),
        }
    }

    /// The curvature the probe axes read at exit point `xo` on triangle
    /// `prim` of mesh `geom`: [`probe::MeshCurvature::axes`] (the
    /// triangle's, or 1/s near a sharp edge at distance s), or
    /// [`probe::exit_curvature`] for a mesh without the cache.
    #[cfg(feature = "subsurface")]
    #[inline]
    pub fn axes_curvature(&self, geom: u32, prim: u32, xo: crate::geometry::Vec3) -> f32 {
        match &self.curvature[geom as usize] {
            Some(c) => c.axes(prim, xo),
            None => probe::exit_curvature(&self.scene.meshes[geom as usize], prim),
        }
    }

    /// The nearest hit of `ray` (t from 0 to ∞), or None — without asking
    /// the accelerator where [`culling`] proves the ray meets nothing;
    /// `from`: the object the ray leaves, [`Context::leaving`].
    #[inline(always)]
    pub fn intersect(
        &self,
        ray: &crate::geometry::Ray,
        from: Option<u32>,
        counters: &mut Counters,
    ) -> Option<crate::accel::Hit> {
        if let Some(c) = &self.culling {
            if c.misses(ray, f32::INFINITY, [from, None]) {
                counters.culled += 1;
                return None;
            }
        }
        self.accel.intersect(ray, 0.0, f32::INFINITY)
    }

    /// Whether something blocks `ray` for t in [0, `t_max`] — without
    /// asking the accelerator where [`culling`] proves nothing does;
    /// `ends`: the objects the segment leaves and arrives on
    /// ([`Context::leaving`]).
    #[inline(always)]
    pub fn occluded(
        &self,
        ray: &crate::geometry::Ray,
        t_max: f32,
        ends: [Option<u32>; 2],
        counters: &mut Counters,
    ) -> bool {
        if let Some(c) = &self.culling {
            if c.misses(ray, t_max, ends) {
                counters.culled += 1;
                return false;
            }
        }
        self.accel.occluded(ray, 0.0, t_max)
    }

    /// `geom`, when a ray leaving it towards (or arriving on) the side of
    /// its triangles' front faces (`front`) or back faces cannot meet it:
    /// that side is the outside of a convex object ([`convex`]). None
    /// otherwise, or without culling.
    #[inline(always)]
    pub fn leaving(&self, geom: u32, front: bool) -> Option<u32> {
        self.culling.as_ref().and_then(|c| c.outside(geom, front))
    }

    /// [`Context::leaving`] for a ray spawned at `si` in direction `dir`
    /// ([`Interaction::spawn`]: offset to the side `dir` points to).
    #[inline(always)]
    pub fn leaving_towards(&self, si: &Interaction, dir: crate::geometry::Vec3) -> Option<u32> {
        self.leaving(si.geom, dir.dot(si.ng) >= 0.0)
    }

    /// The surface geometry at `hit` on the ray `ray`. Forced inline (a
    /// measured gain, see [`crate::kernels`]): the bounce loop is large
    /// enough that LLVM kept this out of line, and the call returned the
    /// 48-byte Interaction through memory.
    #[inline(always)]
    pub fn interaction(&self, ray: &crate::geometry::Ray, hit: &crate::accel::Hit) -> Interaction {
        Interaction::new(&self.shading[hit.geom as usize], ray, hit)
    }
}

fn scene_bounds(scene: &Scene) -> (glam::Vec3, glam::Vec3) {
    let mut lo = glam::Vec3::splat(f32::INFINITY);
    let mut hi = glam::Vec3::splat(f32::NEG_INFINITY);
    for (a, b) in scene.meshes.iter().filter_map(|m| m.bounds()) {
        lo = lo.min(a);
        hi = hi.max(b);
    }
    (lo, hi)
}

/// Which estimator renders the image. Both treat surfaces, lights and the
/// environment alike; they differ at subsurface objects.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IntegratorKind {
    /// [`path::radiance`]: the diffusion BSSRDF sampled with probe rays.
    #[default]
    Path,
    /// [`randomwalk::radiance`]: a volumetric random walk in the medium
    /// (only with the `subsurface` feature).
    #[cfg(feature = "subsurface")]
    RandomWalk,
}

impl IntegratorKind {
    /// The traversal a render with this estimator uses when the scene asks
    /// for `asked` ([`Traversal`]): the random walk is always watertight (a
    /// walk that slipped out of a closed medium through a crack would leave
    /// it at the wrong place); the path integrator takes what is asked.
    pub fn traversal(self, asked: Traversal) -> Traversal {
        match self {
            IntegratorKind::Path => asked,
            #[cfg(feature = "subsurface")]
            IntegratorKind::RandomWalk => Traversal::Watertight,
        }
    }

    /// One sample of the radiance along `ray` with this estimator; its
    /// parts go to `rec` ([`aov`]), its effects' time to `T` ([`effects`]).
    pub fn radiance<R: aov::Recorder, T: Clock>(
        self,
        ctx: &Context,
        ray: crate::geometry::Ray,
        rng: &mut crate::sampling::SampleRng,
        scratch: &mut path::Scratch,
        counters: &mut Counters,
        rec: &mut R,
    ) -> crate::geometry::Vec3 {
        match self {
            IntegratorKind::Path => path::radiance::<R, T>(ctx, ray, rng, scratch, counters, rec),
            #[cfg(feature = "subsurface")]
            IntegratorKind::RandomWalk => {
                randomwalk::radiance::<R, T>(ctx, ray, rng, scratch, counters, rec)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_render_traverses_as_the_scene_asks_except_the_random_walk_always_watertight() {
        for t in [Traversal::Watertight, Traversal::Fast] {
            assert_eq!(IntegratorKind::Path.traversal(t), t);
            #[cfg(feature = "subsurface")]
            assert_eq!(
                IntegratorKind::RandomWalk.traversal(t),
                Traversal::Watertight
            );
        }
    }
}
