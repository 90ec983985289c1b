//! The scene: camera, render settings, meshes with their materials and
//! emission, and the environment. [`load()`] reads one from a TOML file (the
//! format is documented in `docs/scene-format.md`); everything downstream
//! only reads a finished `Scene`.

pub mod camera;
pub mod format;
pub mod load;
pub mod shapes;
pub mod transform;

use std::fmt;
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

/// A scene-loading error located in the user's input: file, and the line
/// (1-based) and/or field where it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneError {
    pub file: PathBuf,
    pub line: Option<usize>,
    pub field: Option<String>,
    pub message: String,
}

impl SceneError {
    pub fn new(file: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        SceneError {
            file: file.into(),
            line: None,
            field: None,
            message: message.into(),
        }
    }
    pub fn at_line(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }
    pub fn in_field(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
        }
        write!(f, ": ")?;
        if let Some(field) = &self.field {
            write!(f, "field `{field}`: ")?;
        }
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for SceneError {}
