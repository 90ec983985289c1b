//! What a scene needs simulated, decided once before rendering, so a scene
//! without lights, environment or subsurface materials pays nothing for them.

use crate::scene::Scene;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Some object emits: do next-event estimation.
    pub area_lights: bool,
    /// Escaping rays see a non-zero environment.
    pub environment: bool,
    /// Some object has a subsurface material: probe rays will be cast.
    pub subsurface: bool,
}

impl Plan {
    pub fn new(scene: &Scene) -> Self {
        Plan {
            area_lights: scene
                .objects
                .iter()
                .any(|o| o.emission.is_some_and(|e| e.max_element() > 0.0)),
            environment: scene.environment.is_some_and(|e| e.max_element() > 0.0),
            subsurface: scene
                .objects
                .iter()
                .any(|o| scene.materials[o.material].is_subsurface()),
        }
    }
}
