//! A ray `o + t d`: what the accelerators are queried with and what the
//! integrators trace.

use super::Vec3;

/// A ray `o + t d`. `d` need not be normalized for the accel queries (t is in
/// units of `|d|`), but every integrator passes unit directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
}

impl Ray {
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Ray { o, d }
    }
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}
