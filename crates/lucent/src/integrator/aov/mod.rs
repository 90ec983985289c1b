//! What the integrator measures for the passes (AOVs) besides the beauty:
//! each sample's radiance split by light path and by light group, the data
//! of its first hits, and, summed per pixel, the layers and ID coverage of
//! `crate::film::layers`.
//!
//! **Light paths** (Arnold's AOVs, `crate::film::passes`). A sample's
//! radiance is a sum of contributions, each added where the bounce loop
//! adds light: emission hit by a ray, the environment reached by an
//! escaping ray, a light sample at a vertex. Each contribution goes to one
//! pass, chosen by the path's *first event* (its scattering at the camera
//! ray's hit) and by how many events lie between that one and the light:
//!
//! - nothing scattered yet (the camera ray found the light): `emission`
//!   for an emitter, `background` for the environment;
//! - the first event was the last one (a light sample at it, or the light
//!   found by the ray it sent): `<class>_direct`;
//! - later events in between: `<class>_indirect`;
//!
//! with `<class>` diffuse (a diffuse lobe), specular (the coat of a
//! subsurface material, smooth or rough, or the reflection of a dielectric
//! or of a random walk's boundary), transmission (refraction through a
//! dielectric; one pass, direct and indirect together) or sss (light that
//! entered a subsurface material at xi and leaves it at xo: the probe's
//! entry vertex or the random walk; "direct" when the light is sampled at
//! xi, or found by the ray leaving it, i.e. split by the first event after
//! xi). These are the light path expressions of Arnold's `diffuse_direct`
//! (`C<RD>L`), `diffuse_indirect` (`C<RD>[DSVOB].*`), `sss_direct`
//! (`C<TD>L`), …; the environment, which lucent samples only by escaping
//! rays, counts as a light (like Arnold's skydome light), so sky light on
//! a diffuse surface is `diffuse_direct`. The coat at xo splits one sample
//! into a reflected path and the medium's path, each tagged with its own
//! class ([`super::path`]). Since every contribution goes to exactly one
//! pass, the passes sum to the beauty sample by sample (in f32, each pass
//! a sum of non-negative terms: within a few ulps per term).
//!
//! **Light groups.** Each contribution also goes to the group of its light
//! (`crate::scene::Output`): the emitter hit, the emitter sampled, the
//! environment, or a light of `[[lights]]`; these sum to the beauty the same way.
//!
//! **Cost.** The bounce loop is generic over a [`Recorder`]; [`NoAov`],
//! used when no pass is asked for, does nothing and its `ON` is false, so
//! that instance of the loop is the loop without passes. The choice is
//! made once per render (`crate::render`), not per sample.

pub mod pixels;
mod sample;

pub use pixels::{PixelPasses, TilePasses};
pub use sample::SampleAovs;

use std::collections::HashMap;

use crate::film::pass_layout::Layout;
use crate::film::passes::{Pass, PassSet};
use crate::geometry::Vec3;
use crate::lights::LightSet;
use crate::scene::Scene;

/// The class of a path's first event (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Event {
    Diffuse,
    Specular,
    Transmission,
    Subsurface,
}

/// Where a contribution's light came from, for its light group.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// An emitting object hit by a ray (its geom).
    Object(u32),
    /// An emissive triangle sampled by next-event estimation (its index in
    /// the light set; [`NO_LIGHT`] when the sample found none, and then
    /// contributes nothing).
    Light(u32),
    /// The environment, reached by an escaping ray.
    Environment,
    /// A light of `[[lights]]` (its index in the scene's `lights`), hit,
    /// reached by an escaping ray or sampled.
    Analytic(u32),
}

/// The light index of a light sample that found no light.
pub const NO_LIGHT: u32 = u32::MAX;

/// The pass of light found by a ray after `depth` hits (an emitter it hit,
/// or the environment it escaped to): `at_camera` ([`Pass::Emission`] or
/// [`Pass::Background`]) for the camera ray, else the first event's direct
/// or indirect pass.
#[inline(always)]
pub fn found(first: Event, depth: u32, at_camera: Pass) -> Pass {
    match depth {
        0 => at_camera,
        1 => direct(first),
        _ => indirect(first),
    }
}

/// The pass of a light sample at a vertex of hit `depth`.
#[inline(always)]
pub fn sampled(first: Event, depth: u32) -> Pass {
    if depth == 0 {
        direct(first)
    } else {
        indirect(first)
    }
}

fn direct(e: Event) -> Pass {
    match e {
        Event::Diffuse => Pass::DiffuseDirect,
        Event::Specular => Pass::SpecularDirect,
        Event::Transmission => Pass::Transmission,
        Event::Subsurface => Pass::SssDirect,
    }
}

fn indirect(e: Event) -> Pass {
    match e {
        Event::Diffuse => Pass::DiffuseIndirect,
        Event::Specular => Pass::SpecularIndirect,
        Event::Transmission => Pass::Transmission,
        Event::Subsurface => Pass::SssIndirect,
    }
}

/// What the bounce loop tells the passes about one sample.
pub trait Recorder {
    /// False for [`NoAov`]: callers skip work that only feeds a recorder
    /// (`if R::ON`), a constant the optimizer removes.
    const ON: bool;
    /// Light `l` added to the sample's radiance, of light path `path`
    /// (one of [`crate::film::passes::LIGHT_PATHS`]) from `source`.
    fn light(&mut self, l: Vec3, path: Pass, source: Source);
    /// The camera ray's hit: the object (geom) and the point.
    fn camera_hit(&mut self, geom: u32, p: Vec3);
    /// A hit that is not purely specular (diffuse, subsurface): its albedo
    /// and shading normal (towards the ray's side); the first one counts.
    fn surface(&mut self, albedo: Vec3, normal: Vec3);
}

/// The recorder of a render without passes: records nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoAov;

impl Recorder for NoAov {
    const ON: bool = false;
    #[inline(always)]
    fn light(&mut self, _: Vec3, _: Pass, _: Source) {}
    #[inline(always)]
    fn camera_hit(&mut self, _: u32, _: Vec3) {}
    #[inline(always)]
    fn surface(&mut self, _: Vec3, _: Vec3) {}
}

/// What recording needs from the scene, built once per render: the passes,
/// the light group of every light, the camera's axis for depth, and the
/// names matted by ID coverage.
#[derive(Clone, Debug)]
pub struct Setup {
    pub passes: PassSet,
    /// Light group names (index = group).
    pub groups: Vec<String>,
    /// Per geom, its light group.
    pub object_group: Vec<u32>,
    /// Per emissive triangle of the light set, its light group.
    pub light_group: Vec<u32>,
    pub environment_group: u32,
    /// Per light of `[[lights]]`, its light group.
    pub analytic_group: Vec<u32>,
    /// The camera's position and unit view direction: depth Z is
    /// (p − origin) · forward.
    pub origin: Vec3,
    pub forward: Vec3,
    /// Per geom, its material's index.
    pub object_material: Vec<u32>,
    /// Per geom, its index in `object_names` (objects sharing a name share
    /// an entry, as an ID matte of that name covers them all).
    pub object_name: Vec<u32>,
    pub object_names: Vec<String>,
    pub material_names: Vec<String>,
}

/// The layout of `passes` over `scene`'s names (what a part of its render
/// holds), without building the scene's lights.
pub fn layout(scene: &Scene, passes: PassSet) -> Layout {
    Setup::build(scene, None, passes).layout()
}

impl Setup {
    pub fn new(scene: &Scene, lights: &LightSet, passes: PassSet) -> Setup {
        Setup::build(scene, Some(lights), passes)
    }

    /// The layout of the passes over these names.
    pub fn layout(&self) -> Layout {
        Layout::new(
            self.passes,
            &self.groups,
            &self.object_names,
            &self.material_names,
        )
    }

    /// [`Setup::new`]; without `lights`, no light has a group.
    fn build(scene: &Scene, lights: Option<&LightSet>, passes: PassSet) -> Setup {
        let out = &scene.output;
        let groups = out.group_names();
        let group = |g: u32| g.min(groups.len() as u32 - 1);
        let object_group: Vec<u32> = (0..scene.objects.len())
            .map(|i| group(out.object_group.get(i).copied().unwrap_or(0)))
            .collect();
        let light_group = lights.map_or(Vec::new(), |lights| {
            (0..lights.len() as u32)
                .map(|t| object_group[lights.geom_of(t) as usize])
                .collect()
        });
        let mut object_names: Vec<String> = Vec::new();
        let mut by_name: HashMap<&str, u32> = HashMap::new();
        let object_name = scene
            .objects
            .iter()
            .map(|o| {
                *by_name.entry(&o.name).or_insert_with(|| {
                    object_names.push(o.name.clone());
                    object_names.len() as u32 - 1
                })
            })
            .collect();
        let c = &scene.camera;
        Setup {
            passes,
            object_group,
            light_group,
            environment_group: group(out.environment_group),
            analytic_group: (0..scene.lights.len())
                .map(|i| group(out.analytic_group.get(i).copied().unwrap_or(0)))
                .collect(),
            origin: c.look_from,
            forward: (c.look_at - c.look_from).normalize(),
            object_material: scene.objects.iter().map(|o| o.material as u32).collect(),
            object_name,
            object_names,
            material_names: (0..scene.materials.len())
                .map(|i| out.material_name(i))
                .collect(),
            groups,
        }
    }
}
