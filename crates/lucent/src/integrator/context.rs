//! What an integrator reads while rendering ([`Context`]), built once per
//! render: the scene, its accelerator, lights and plan, the per-mesh
//! shading records, ray culling, the camera's footprint spread, per
//! subsurface mesh its curvatures and curvature-correction factors, and
//! (built when a random walk first needs them) the scene's distance bounds
//! and the subsurface meshes' edge neighbours.

#[cfg(feature = "subsurface")]
use super::control_variate;
use super::culling;
use super::footprint::CameraSpread;
use super::interaction::{self, Interaction};
use super::plan::Plan;
use crate::accel::Accel;
#[cfg(feature = "subsurface")]
use crate::geometry::adjacency::EdgeNeighbours;
#[cfg(feature = "subsurface")]
use crate::geometry::curvature::{MeshCurvature, TriangleCurvature};
#[cfg(feature = "subsurface")]
use crate::geometry::distance::DistanceGrid;
use crate::lights::LightSet;
use crate::scene::Scene;
use crate::stats::Counters;

/// Subsurface hits at depths below this, on materials with `probe_pair`
/// on (the default), sample two entry points from one probe's randoms,
/// the second at the opposite angle φ + π (antithetic), and sample light
/// at both, each weighted ½; the path goes on from each of them with
/// weight ½ (`pair_paths = 2`, the default) or from one chosen with
/// probability ½ (`pair_paths = 1`) (`docs/bssrdf.md` §5). Light varying
/// linearly across the profile cancels between the two. 1: the camera
/// vertex (the default of [`Context::pair_depth`]).
pub const PAIR_DEPTH: u32 = 1;

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
    /// ([`PAIR_DEPTH`], the default: the camera vertex); 0 turns the
    /// pair off everywhere.
    pub pair_depth: u32,
    /// Subsurface hits at depths below this add the plane control variate
    /// on materials with `control_variate` on (the default;
    /// `control_variate::CV_DEPTH`: the camera vertex); 0 turns it off
    /// everywhere.
    pub cv_depth: u32,
    /// The camera's pixel angle, for the footprint cone of subsurface
    /// level of detail ([`super::footprint`]).
    pub camera_spread: CameraSpread,
    /// Rays proven to meet nothing ([`culling`]); None for scenes of more
    /// than [`culling::MAX_OBJECTS`] objects, and where a caller turns it
    /// off to compare (the pixels are the same either way).
    pub culling: Option<culling::Culling>,
    /// Per mesh with a subsurface material, its triangles' curvatures and
    /// factors ([`SubsurfaceCurvature`]); None for the others.
    #[cfg(feature = "subsurface")]
    pub curvature: Vec<Option<SubsurfaceCurvature>>,
    /// The random walk's distance bounds ([`DistanceGrid`]), built at the
    /// first walk: a render without one never pays for it.
    #[cfg(feature = "subsurface")]
    distance: std::sync::OnceLock<Option<DistanceGrid>>,
    /// Per mesh with a subsurface material, which of its triangles share
    /// an edge ([`EdgeNeighbours`]), built at the first connection through
    /// a walk's boundary (`super::walk_nee`).
    #[cfg(feature = "subsurface")]
    neighbours: std::sync::OnceLock<Vec<Option<EdgeNeighbours>>>,
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
        let curvature = subsurface_curvatures(scene);
        let ray_epsilon = extent * 1e-6;
        Context {
            scene,
            accel,
            culling: culling::Culling::new(&scene.meshes, extent, ray_epsilon),
            lights: LightSet::new(scene),
            plan: Plan::new(scene),
            ray_epsilon,
            shading,
            pair_depth: PAIR_DEPTH,
            #[cfg(feature = "subsurface")]
            cv_depth: control_variate::CV_DEPTH,
            #[cfg(not(feature = "subsurface"))]
            cv_depth: 0,
            camera_spread: CameraSpread::new(
                scene.camera.fov_y,
                scene.camera.height,
                scene.camera.look_at - scene.camera.look_from,
            ),
            #[cfg(feature = "subsurface")]
            curvature,
            #[cfg(feature = "subsurface")]
            distance: std::sync::OnceLock::new(),
            #[cfg(feature = "subsurface")]
            neighbours: std::sync::OnceLock::new(),
        }
    }

    /// Switches the random walk's distance bounds off, so every flight
    /// asks the accelerator (to compare: the pixels are the same either
    /// way, `tests/physics/randomwalk.rs`).
    #[cfg(feature = "subsurface")]
    pub fn without_distance_bounds(&mut self) {
        self.distance = std::sync::OnceLock::from(None);
    }

    /// The edge neighbours of the triangles of mesh `geom`, when it has a
    /// subsurface material; all such meshes' are built on first use.
    #[cfg(feature = "subsurface")]
    pub(crate) fn edge_neighbours(&self, geom: u32) -> Option<&EdgeNeighbours> {
        self.neighbours
            .get_or_init(|| {
                let meshes = &self.scene.meshes;
                (0..meshes.len())
                    .map(|i| {
                        self.curvature[i]
                            .as_ref()
                            .map(|_| EdgeNeighbours::new(&meshes[i]))
                    })
                    .collect()
            })
            .get(geom as usize)?
            .as_ref()
    }

    /// The grid of lower bounds on the distance to the scene's triangles
    /// over the subsurface objects (over every object in a scene without
    /// one), built on first use (by the random walk, `super::randomwalk`).
    #[cfg(feature = "subsurface")]
    pub(crate) fn distance_grid(&self) -> Option<&DistanceGrid> {
        self.distance
            .get_or_init(|| {
                let sss: Vec<usize> = (0..self.scene.meshes.len())
                    .filter(|&i| self.curvature[i].is_some())
                    .collect();
                let domain: Vec<usize> = if sss.is_empty() {
                    (0..self.scene.meshes.len()).collect()
                } else {
                    sss
                };
                let (mut lo, mut hi) = (glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY);
                for (a, b) in domain.iter().filter_map(|&i| self.scene.meshes[i].bounds()) {
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                DistanceGrid::build(&self.scene.meshes, lo, hi)
            })
            .as_ref()
    }

    /// The curvatures of triangle `prim` of mesh `geom`
    /// ([`TriangleCurvature`]), from the cache where the mesh has one.
    #[cfg(feature = "subsurface")]
    #[inline]
    pub(crate) fn curvatures(&self, geom: u32, prim: u32) -> TriangleCurvature {
        match &self.curvature[geom as usize] {
            Some(c) => c.mesh.triangle(prim),
            None => TriangleCurvature::of(&self.scene.meshes[geom as usize], prim),
        }
    }

    /// f(κ) per channel of triangle `prim` of mesh `geom` under `cc`, its
    /// material's curvature correction, for its mean curvature: from the
    /// cache where the mesh has one ([`SubsurfaceCurvature::factor`]).
    #[cfg(feature = "subsurface")]
    #[inline]
    pub(crate) fn curvature_factor(
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
            None => cc.factor(self.curvatures(geom, prim).mean),
        }
    }

    /// The curvature the probe axes read at exit point `xo` on triangle
    /// `prim` of mesh `geom`: [`MeshCurvature::axes`] (the
    /// triangle's, or 1/s near a sharp edge at distance s), or
    /// [`crate::geometry::curvature::exit_curvature`] for a mesh without
    /// the cache.
    #[cfg(feature = "subsurface")]
    #[inline]
    pub fn axes_curvature(&self, geom: u32, prim: u32, xo: crate::geometry::Vec3) -> f32 {
        self.axes_curvature_up_to(geom, prim, xo, f32::INFINITY)
    }

    /// [`Context::axes_curvature`] for a reader to which every curvature
    /// ≥ `saturated` is the same
    /// ([`crate::geometry::curvature::MeshCurvature::axes_up_to`]).
    #[cfg(feature = "subsurface")]
    #[inline]
    pub fn axes_curvature_up_to(
        &self,
        geom: u32,
        prim: u32,
        xo: crate::geometry::Vec3,
        saturated: f32,
    ) -> f32 {
        match &self.curvature[geom as usize] {
            Some(c) => c.mesh.axes_up_to(prim, xo, saturated),
            None => {
                crate::geometry::curvature::exit_curvature(&self.scene.meshes[geom as usize], prim)
            }
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
    /// that side is the outside of a convex object
    /// ([`crate::geometry::convex`]). None otherwise, or without culling.
    #[inline(always)]
    pub fn leaving(&self, geom: u32, front: bool) -> Option<u32> {
        self.culling.as_ref().and_then(|c| c.outside(geom, front))
    }

    /// [`Context::leaving`] for a ray spawned at `si` in direction `dir`
    /// ([`Interaction::spawn`]: offset to the side `dir` points to).
    #[inline(always)]
    pub(crate) fn leaving_towards(
        &self,
        si: &Interaction,
        dir: crate::geometry::Vec3,
    ) -> Option<u32> {
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

/// Per mesh with a subsurface material, its [`SubsurfaceCurvature`]
/// (without the factors for a textured one); None for the others.
#[cfg(feature = "subsurface")]
fn subsurface_curvatures(scene: &Scene) -> Vec<Option<SubsurfaceCurvature>> {
    scene
        .meshes
        .iter()
        .zip(&scene.objects)
        .map(|(m, o)| match scene.materials[o.material].base() {
            crate::materials::Material::Subsurface(ss) => {
                // only the `curvature` axis rule reads sharp edges
                let reads_edges = ss.probe().options().axes == crate::bssrdf::ProbeAxes::Curvature;
                let reach = if reads_edges {
                    ss.probe().rmax() as f32
                } else {
                    0.0
                };
                let c = MeshCurvature::new(m, reach);
                // a textured material's correction changes from hit to hit
                let cc = match &scene.materials[o.material] {
                    crate::materials::Material::Textured(_) => None,
                    _ => ss.curvature_correction(),
                };
                Some(SubsurfaceCurvature::new(c, cc))
            }
            _ => None,
        })
        .collect()
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

/// A subsurface mesh's curvatures ([`MeshCurvature`]) and, under its
/// material's curvature correction, each triangle's factor f(κ) of its
/// mean curvature (`CurvatureCorrection::factor`, `docs/bssrdf.md` §10).
/// The factor is a BSSRDF quantity of the material on this mesh, so it is
/// cached here with the render's context, not in `geometry`.
#[cfg(feature = "subsurface")]
#[derive(Clone, Debug, Default)]
pub struct SubsurfaceCurvature {
    /// The mesh's curvatures and sharp edges.
    pub mesh: MeshCurvature,
    /// Per triangle, f(κ) of its mean curvature; empty without a
    /// correction.
    factor: Vec<[f32; 3]>,
}

#[cfg(feature = "subsurface")]
impl SubsurfaceCurvature {
    /// `mesh`'s cache, with each triangle's f(κ) under `cc` when the
    /// material has a curvature correction.
    pub fn new(
        mesh: MeshCurvature,
        cc: Option<&crate::bssrdf::curvature_correction::CurvatureCorrection>,
    ) -> Self {
        let factor = match cc {
            Some(cc) => mesh.triangles().iter().map(|k| cc.factor(k.mean)).collect(),
            None => Vec::new(),
        };
        SubsurfaceCurvature { mesh, factor }
    }

    /// f(κ) of triangle `prim`'s mean curvature, when cached.
    #[inline]
    pub fn factor(&self, prim: u32) -> Option<[f32; 3]> {
        self.factor.get(prim as usize).copied()
    }
}
