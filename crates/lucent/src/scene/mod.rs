//! The scene: camera, render settings, meshes with their materials and
//! emission, and the environment. [`load()`] reads one from a TOML file (the
//! format is documented in `docs/scene-format.md`); everything downstream
//! only reads a finished `Scene`.

pub mod camera;
mod checked;
mod environment;
pub mod format;
mod glossy_material;
pub mod key_path;
mod lens;
mod lights;
pub mod load;
mod material;
mod mtl;
pub mod obj;
mod obj_materials;
mod objects;
mod output;
mod output_file;
pub mod regular_file;
mod shape_uvs;
pub mod shapes;
mod textures;
pub mod transform;

use std::path::PathBuf;
use std::sync::Arc;

pub use camera::Camera;
pub use lights::SUN_ANGLE;
pub use load::{load, load_str};
pub use output::{Output, DEFAULT_GROUP};
pub use output_file::OutputSettings;

use crate::geometry::{Mesh, Vec3};
use crate::materials::Material;

/// The largest |coordinate| (scene units) of any vertex after its shape's
/// transform, and of the camera's `look_from` and `look_at`: the loader
/// rejects anything beyond. See "Supported ranges" in
/// `docs/scene-format.md` for the reasons (f32 hit points, ray offsets and
/// probe segments; Embree's limit of 1.844e18 on ray components).
pub const MAX_COORDINATE: f32 = 1.0e7;

/// The largest subsurface probe radius Rmax (scene units) the loader
/// accepts: probe segments start up to Rmax away from a surface point and
/// are 2·Rmax long, so this keeps them within a few times
/// [`MAX_COORDINATE`].
pub const MAX_SUBSURFACE_RADIUS: f64 = 1.0e7;

/// `[x, y, z]` for messages: huge or tiny components in exponent form
/// (`1e30`, not thirty zeros), others as written (`0`, `1.5`).
pub(crate) fn show_point(p: [f32; 3]) -> String {
    let one = |x: f32| {
        if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
            format!("{x:e}")
        } else {
            format!("{x}")
        }
    };
    format!("[{}, {}, {}]", one(p[0]), one(p[1]), one(p[2]))
}

/// Sample count, path depth, seed, how rays treat shared edges, and the
/// sampler.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    /// `[render] traversal`: what `lucent render` asks of Embree
    /// ([`crate::accel::Traversal`]; the random walk is watertight
    /// whatever this says). `Fast` unless the scene says `"watertight"`.
    pub traversal: crate::accel::Traversal,
    /// `[render] sampler`: where the samples' random numbers come from
    /// ([`crate::sampling::SamplerKind`], its default unless given).
    pub sampler: crate::sampling::SamplerKind,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            max_depth: 8,
            seed: 0,
            traversal: crate::accel::Traversal::Fast,
            sampler: crate::sampling::SamplerKind::Sobol,
        }
    }
}

/// What is attached to one mesh: its material and optional emission.
/// `objects[i]` describes `meshes[i]`; `i` is the accel's `geom` id.
#[derive(Clone, Debug)]
pub struct Object {
    pub name: String,
    pub material: usize,
    /// Emitted radiance from the front face (the side the geometric normal,
    /// from counter-clockwise winding, points to). None: not a light.
    pub emission: Option<Vec3>,
    /// The accuracy budget gave its subsurface hits to the random walk
    /// (`crate::integrator::plan::budget`); never set by a key.
    pub walk: bool,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub settings: RenderSettings,
    pub meshes: Arc<Vec<Mesh>>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    /// What rays that escape see; None: black.
    pub environment: Option<crate::environment::Environment>,
    /// The sphere, spot and distant lights (`[[lights]]`).
    pub lights: Vec<crate::analytic_lights::Light>,
    /// Scene units per millimetre (subsurface parameters are in mm).
    pub units_per_mm: f32,
    /// Where the scene came from, for messages and caches.
    pub source: Option<PathBuf>,
    /// Its passes, light groups and material names.
    pub output: Output,
    /// What loading read past or approximated (MTL keys lucent ignores),
    /// one line each, for the user.
    pub notes: Vec<String>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangle_count()).sum()
    }

    /// The distinct textures its materials read and their bytes (all MIP
    /// levels), each counted once however many materials share it.
    pub fn texture_memory(&self) -> (usize, usize) {
        let seen = self.textures();
        let bytes = seen.iter().map(|t| t.bytes()).sum();
        (seen.len(), bytes)
    }

    /// The distinct textures its materials read, in material order.
    pub fn textures(&self) -> Vec<&Arc<crate::texture::Texture>> {
        let mut seen: Vec<&Arc<crate::texture::Texture>> = Vec::new();
        for m in &self.materials {
            if let Material::Textured(t) = m {
                for tex in t.textures() {
                    if !seen.iter().any(|s| Arc::ptr_eq(s, tex)) {
                        seen.push(tex);
                    }
                }
            }
        }
        seen
    }
}

/// The located input error scene loading fails with (the library-wide
/// [`crate::error::InputError`], under the name scene code has used).
pub type SceneError = crate::error::InputError;
