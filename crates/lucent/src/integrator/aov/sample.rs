//! One sample's passes: its radiance split by light path and by light
//! group, its camera hit and its first non-specular hit, as the bounce loop
//! reports them ([`Recorder`]).

use super::{Recorder, Setup, Source};
use crate::film::passes::{Pass, LIGHT_PATHS};
use crate::geometry::Vec3;

/// The [`Recorder`] of a render with passes; cleared before each sample.
pub struct SampleAovs<'a> {
    setup: &'a Setup,
    /// Radiance per light path (index: the [`Pass`], one of
    /// [`LIGHT_PATHS`]).
    pub paths: [Vec3; LIGHT_PATHS.len()],
    /// Radiance per light group.
    pub groups: Vec<Vec3>,
    /// The camera ray's hit: geom and point.
    pub hit: Option<(u32, Vec3)>,
    /// The first non-specular hit: albedo and shading normal.
    pub surface: Option<(Vec3, Vec3)>,
}

impl<'a> SampleAovs<'a> {
    pub fn new(setup: &'a Setup) -> Self {
        SampleAovs {
            setup,
            paths: [Vec3::ZERO; LIGHT_PATHS.len()],
            groups: vec![Vec3::ZERO; setup.groups.len()],
            hit: None,
            surface: None,
        }
    }

    /// Forgets the last sample.
    pub fn clear(&mut self) {
        self.paths = [Vec3::ZERO; LIGHT_PATHS.len()];
        self.groups.fill(Vec3::ZERO);
        self.hit = None;
        self.surface = None;
    }
}

impl Recorder for SampleAovs<'_> {
    const ON: bool = true;

    fn light(&mut self, l: Vec3, path: Pass, source: Source) {
        let s = self.setup;
        let group = match source {
            Source::Object(geom) => s.object_group[geom as usize],
            Source::Light(tri) => match s.light_group.get(tri as usize) {
                Some(g) => *g,
                None => return, // NO_LIGHT
            },
            Source::Environment => s.environment_group,
            Source::Analytic(i) => s.analytic_group[i as usize],
        };
        debug_assert!(LIGHT_PATHS.contains(&path), "{path:?} is not a light path");
        self.paths[path as usize] += l;
        self.groups[group as usize] += l;
    }

    fn camera_hit(&mut self, geom: u32, p: Vec3) {
        self.hit = Some((geom, p));
    }

    fn surface(&mut self, albedo: Vec3, normal: Vec3) {
        if self.surface.is_none() {
            self.surface = Some((albedo, normal));
        }
    }
}
