//! The scene the library-level tests build in code: meshes with their
//! materials and emissions, an optional uniform environment, a camera and
//! the render settings a test varies (spp, depth, seed); every other
//! setting is the default, one unit per mm, no source file. Scenes written
//! as TOML text go through `lucent::scene::load_str` instead.

use std::sync::Arc;

use lucent::geometry::{Mesh, Vec3};
use lucent::materials::Material;
use lucent::scene::{Camera, Object, RenderSettings, Scene};

/// What a test chooses of a scene besides its objects.
pub struct TestScene {
    pub camera: Camera,
    pub spp: u32,
    pub max_depth: u32,
    pub seed: u64,
    /// Uniform environment radiance, if any.
    pub environment: Option<Vec3>,
}

impl TestScene {
    /// The scene of `meshes`, `materials` and `objects` (object i is
    /// mesh i, its `material` an index into `materials`).
    pub fn build(self, meshes: Vec<Mesh>, materials: Vec<Material>, objects: Vec<Object>) -> Scene {
        Scene {
            camera: self.camera,
            settings: RenderSettings {
                spp: self.spp,
                max_depth: self.max_depth,
                seed: self.seed,
                ..RenderSettings::default()
            },
            meshes: Arc::new(meshes),
            objects,
            materials,
            environment: self
                .environment
                .map(lucent::environment::Environment::Constant),
            lights: Vec::new(),
            units_per_mm: 1.0,
            source: None,
            output: Default::default(),
            notes: Vec::new(),
        }
    }
}

/// An object named `name` with material index `material`.
pub fn object(name: impl Into<String>, material: usize, emission: Option<Vec3>) -> Object {
    Object {
        name: name.into(),
        material,
        emission,
        walk: false,
    }
}
