//! Our BVH.
use super::{Accel, Hit, ProbeHits};
use crate::geometry::{Mesh, Ray};

pub struct Bvh {}

impl Bvh {
    pub fn build(_meshes: &[Mesh]) -> Self {
        Bvh {}
    }
}

impl Accel for Bvh {
    fn name(&self) -> &'static str {
        "bvh"
    }
    fn intersect(&self, _ray: &Ray, _tmin: f32, _tmax: f32) -> Option<Hit> {
        None
    }
    fn occluded(&self, _ray: &Ray, _tmin: f32, _tmax: f32) -> bool {
        false
    }
    fn hits_on_segment(&self, _ray: &Ray, _tmax: f32, _geom: u32, seed: u32, out: &mut ProbeHits) {
        out.reset(seed);
        out.finish();
    }
}
