//! What a recording holds: one [`Record`] per ray query, of a [`Kind`].
//!
//! Memory: a record is [`RECORD_BYTES`] bytes, at most 48 (checked at
//! compile time), which the default cap and the documented log sizes
//! assume.

use lucent::geometry::Ray;

/// What the renderer asked the backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// Nearest hit of a primary ray (its origin is the camera's eye).
    Camera,
    /// Nearest hit of any other ray: bounces, refraction, random-walk steps.
    Nearest,
    /// Any hit: shadow rays of next-event estimation.
    Occluded,
    /// Every hit on one object along a segment: BSSRDF probe rays.
    Probe,
}

impl Kind {
    pub const ALL: [Kind; 4] = [Kind::Camera, Kind::Nearest, Kind::Occluded, Kind::Probe];
    pub fn name(self) -> &'static str {
        match self {
            Kind::Camera => "camera",
            Kind::Nearest => "nearest",
            Kind::Occluded => "occluded",
            Kind::Probe => "probe",
        }
    }
    pub(super) fn index(self) -> usize {
        self as usize
    }
}

/// One recorded query. `geom` and `seed` matter for probes only, `tmin`
/// for nearest and occluded only.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Record {
    pub ray: Ray,
    pub tmin: f32,
    pub tmax: f32,
    pub geom: u32,
    pub seed: u32,
    pub kind: Kind,
}

/// Bytes per [`Record`] in a log.
pub const RECORD_BYTES: usize = std::mem::size_of::<Record>();
// The memory figures in the docs and the default cap assume this.
const _: () = assert!(RECORD_BYTES <= 48);
