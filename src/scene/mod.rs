//! The scene: camera, render settings, meshes with their materials and
//! emission, and the environment. [`load()`] reads one from a TOML file (the
//! format is documented in `docs/scene-format.md`); everything downstream
//! only reads a finished `Scene`.

pub mod camera;
mod checked;
pub mod format;
pub mod key_path;
pub mod load;
mod material;
pub mod obj;
mod objects;
pub mod shapes;
pub mod transform;

use std::path::PathBuf;
use std::sync::Arc;

pub use camera::Camera;
pub use load::{load, load_str};

use crate::geometry::{Mesh, Vec3};
use crate::materials::Material;

/// Sample count, path depth and seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            max_depth: 8,
            seed: 0,
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
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub settings: RenderSettings,
    pub meshes: Arc<Vec<Mesh>>,
    pub objects: Vec<Object>,
    pub materials: Vec<Material>,
    /// Constant environment radiance seen by rays that escape.
    pub environment: Option<Vec3>,
    /// Scene units per millimetre (subsurface parameters are in mm).
    pub units_per_mm: f32,
    /// Where the scene came from, for messages and caches.
    pub source: Option<PathBuf>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangle_count()).sum()
    }
}

/// The located input error scene loading fails with (the library-wide
/// [`crate::error::InputError`], under the name scene code has used).
pub type SceneError = crate::error::InputError;
