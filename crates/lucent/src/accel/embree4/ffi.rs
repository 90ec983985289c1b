//! Raw types and constants of the part of the Embree 4 C API
//! (`embree4/rtcore*.h`) that lucent calls, for releases 4.3 and 4.4 (the
//! ones [`super::load`] accepts). The functions themselves are not declared
//! here but looked up at run time ([`super::load::Api`]).
//!
//! Transcribed from the 4.3/4.4 headers for a library configured as the
//! release builds are; what changed from Embree 3
//! (`super::super::embree::ffi`) and matters here (the 96-byte `RTCRayHit`,
//! the query arguments that replace `RTCIntersectContext`, when the argument
//! filter runs): `docs/testing.md`, "The Embree 4 backend". Every size,
//! offset and constant below is asserted at compile time, and
//! `tests/accel/embree4_layout.rs` compares [`layout_table`] with the C compiler's
//! answer where Embree 4 headers are installed, and with [`TRANSCRIBED`]
//! everywhere.

#![allow(non_camel_case_types, dead_code)]

use std::ffi::{c_char, c_int, c_uint, c_void};
use std::mem::{align_of, offset_of, size_of};

/// `RTC_INVALID_GEOMETRY_ID`, `((unsigned int)-1)` (`rtcore_common.h`).
pub const RTC_INVALID_GEOMETRY_ID: c_uint = u32::MAX;

/// `RTC_MAX_INSTANCE_LEVEL_COUNT` of the release builds (`rtcore_config.h`).
pub(crate) const RTC_MAX_INSTANCE_LEVEL_COUNT: usize = 1;

#[repr(C)]
pub struct RTCDeviceTy {
    _private: [u8; 0],
}
#[repr(C)]
pub struct RTCSceneTy {
    _private: [u8; 0],
}
#[repr(C)]
pub struct RTCGeometryTy {
    _private: [u8; 0],
}
pub(crate) type RTCDevice = *mut RTCDeviceTy;
pub(crate) type RTCScene = *mut RTCSceneTy;
pub(crate) type RTCGeometry = *mut RTCGeometryTy;

// Enums are passed as plain `int`-sized integers (the SysV ABIs give these
// enums 4 bytes), so a value from C can never be an invalid Rust enum.

/// `enum RTCError` (`rtcore_device.h`).
pub(crate) type RTCError = c_int;
pub(crate) const RTC_ERROR_NONE: RTCError = 0;

/// `enum RTCDeviceProperty` (`rtcore_device.h`).
pub(crate) type RTCDeviceProperty = c_int;
pub(crate) const RTC_DEVICE_PROPERTY_VERSION_MAJOR: RTCDeviceProperty = 1;
pub(crate) const RTC_DEVICE_PROPERTY_VERSION_MINOR: RTCDeviceProperty = 2;
pub(crate) const RTC_DEVICE_PROPERTY_VERSION_PATCH: RTCDeviceProperty = 3;
pub(crate) const RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED: RTCDeviceProperty = 66;
pub(crate) const RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED: RTCDeviceProperty = 96;

/// `enum RTCSceneFlags` (`rtcore_scene.h`).
pub(crate) type RTCSceneFlags = c_int;
pub(crate) const RTC_SCENE_FLAG_ROBUST: RTCSceneFlags = 1 << 2;
pub(crate) const RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS: RTCSceneFlags = 1 << 3;

/// `enum RTCBuildQuality` (`rtcore_common.h`).
pub(crate) type RTCBuildQuality = c_int;
pub(crate) const RTC_BUILD_QUALITY_MEDIUM: RTCBuildQuality = 1;

/// `enum RTCGeometryType` (`rtcore_geometry.h`).
pub(crate) type RTCGeometryType = c_int;
pub(crate) const RTC_GEOMETRY_TYPE_TRIANGLE: RTCGeometryType = 0;

/// `enum RTCBufferType` (`rtcore_buffer.h`).
pub(crate) type RTCBufferType = c_int;
pub(crate) const RTC_BUFFER_TYPE_INDEX: RTCBufferType = 0;
pub(crate) const RTC_BUFFER_TYPE_VERTEX: RTCBufferType = 1;

/// `enum RTCFormat` (`rtcore_common.h`).
pub(crate) type RTCFormat = c_int;
pub(crate) const RTC_FORMAT_UINT3: RTCFormat = 0x5003;
pub(crate) const RTC_FORMAT_FLOAT3: RTCFormat = 0x9003;

/// `enum RTCRayQueryFlags` (`rtcore_common.h`).
pub(crate) type RTCRayQueryFlags = c_int;
/// `(0 << 16)`: what `rtcInitIntersectArguments` sets.
pub(crate) const RTC_RAY_QUERY_FLAG_INCOHERENT: RTCRayQueryFlags = 0;
/// `(1 << 1)`: run the argument filter on every geometry.
pub(crate) const RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER: RTCRayQueryFlags = 1 << 1;

/// `enum RTCFeatureFlags` (`rtcore_common.h`); only SYCL devices read it.
pub(crate) type RTCFeatureFlags = c_uint;
/// `RTC_FEATURE_FLAG_ALL = 0xffffffff`, what `rtcInitIntersectArguments`
/// sets.
pub(crate) const RTC_FEATURE_FLAG_ALL: RTCFeatureFlags = 0xffff_ffff;

/// `struct RTC_ALIGN(16) RTCRay` (`rtcore_ray.h`; unchanged from Embree 3).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug)]
pub struct RTCRay {
    pub org_x: f32,
    pub org_y: f32,
    pub org_z: f32,
    pub tnear: f32,
    pub dir_x: f32,
    pub dir_y: f32,
    pub dir_z: f32,
    pub time: f32,
    pub tfar: f32,
    pub mask: c_uint,
    pub id: c_uint,
    pub flags: c_uint,
}

/// `struct RTC_ALIGN(16) RTCHit` (`rtcore_ray.h`, 4.3+: with `instPrimID`).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug)]
pub struct RTCHit {
    pub ng_x: f32,
    pub ng_y: f32,
    pub ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub prim_id: c_uint,
    pub geom_id: c_uint,
    pub inst_id: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
    pub inst_prim_id: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
}

/// `struct RTCRayHit` (`rtcore_ray.h`; 16-aligned from its members).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

/// `struct RTCRayQueryContext` (`rtcore_common.h`): the instance stack
/// (no `instStackSize`, present only when `RTC_MAX_INSTANCE_LEVEL_COUNT >
/// 1`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCRayQueryContext {
    pub inst_id: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
    pub inst_prim_id: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
}

impl RTCRayQueryContext {
    /// `rtcInitRayQueryContext`, a `static inline` of `rtcore_common.h`.
    pub fn new() -> Self {
        RTCRayQueryContext {
            inst_id: [RTC_INVALID_GEOMETRY_ID; RTC_MAX_INSTANCE_LEVEL_COUNT],
            inst_prim_id: [RTC_INVALID_GEOMETRY_ID; RTC_MAX_INSTANCE_LEVEL_COUNT],
        }
    }
}

impl Default for RTCRayQueryContext {
    fn default() -> Self {
        Self::new()
    }
}

/// Opaque `RTCRayN` / `RTCHitN` packets of run-time width N.
#[repr(C)]
pub struct RTCRayN {
    _private: [u8; 0],
}
#[repr(C)]
pub struct RTCHitN {
    _private: [u8; 0],
}

/// `struct RTCFilterFunctionNArguments` (`rtcore_common.h`).
#[repr(C)]
#[derive(Debug)]
pub struct RTCFilterFunctionNArguments {
    pub valid: *mut c_int,
    pub geometry_user_ptr: *mut c_void,
    pub context: *mut RTCRayQueryContext,
    pub ray: *mut RTCRayN,
    pub hit: *mut RTCHitN,
    pub n: c_uint,
}

/// `RTCFilterFunctionN`. Embree does not unwind: implementations must not
/// panic.
pub(crate) type RTCFilterFunctionN =
    Option<unsafe extern "C" fn(args: *const RTCFilterFunctionNArguments)>;

/// `struct RTCIntersectArguments` (`rtcore_scene.h`; no
/// `minWidthDistanceFactor`, present only when `RTC_MIN_WIDTH`). The
/// user-geometry callback is never set by lucent, hence a plain pointer.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCIntersectArguments {
    pub flags: RTCRayQueryFlags,
    pub feature_mask: RTCFeatureFlags,
    pub context: *mut RTCRayQueryContext,
    pub filter: RTCFilterFunctionN,
    pub intersect: *const c_void,
}

/// `struct RTCOccludedArguments` (`rtcore_scene.h`), laid out as
/// [`RTCIntersectArguments`] with `occluded` in place of `intersect`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCOccludedArguments {
    pub flags: RTCRayQueryFlags,
    pub feature_mask: RTCFeatureFlags,
    pub context: *mut RTCRayQueryContext,
    pub filter: RTCFilterFunctionN,
    pub occluded: *const c_void,
}

impl RTCIntersectArguments {
    /// `rtcInitIntersectArguments` (a `static inline` of `rtcore_scene.h`).
    pub fn new() -> Self {
        RTCIntersectArguments {
            flags: RTC_RAY_QUERY_FLAG_INCOHERENT,
            feature_mask: RTC_FEATURE_FLAG_ALL,
            context: std::ptr::null_mut(),
            filter: None,
            intersect: std::ptr::null(),
        }
    }
}

impl Default for RTCIntersectArguments {
    fn default() -> Self {
        Self::new()
    }
}

impl RTCOccludedArguments {
    /// `rtcInitOccludedArguments` (a `static inline` of `rtcore_scene.h`).
    pub fn new() -> Self {
        RTCOccludedArguments {
            flags: RTC_RAY_QUERY_FLAG_INCOHERENT,
            feature_mask: RTC_FEATURE_FLAG_ALL,
            context: std::ptr::null_mut(),
            filter: None,
            occluded: std::ptr::null(),
        }
    }
}

impl Default for RTCOccludedArguments {
    fn default() -> Self {
        Self::new()
    }
}

/// `RTCErrorFunction` (`rtcore_device.h`). Must not unwind into Embree.
pub(crate) type RTCErrorFunction =
    Option<unsafe extern "C" fn(user_ptr: *mut c_void, code: RTCError, str: *const c_char)>;

// Layout checks against the Embree 4.3/4.4 headers (x86-64 / AArch64).
const _: () = {
    assert!(size_of::<RTCRay>() == 48 && align_of::<RTCRay>() == 16);
    assert!(offset_of!(RTCRay, tnear) == 12);
    assert!(offset_of!(RTCRay, dir_x) == 16);
    assert!(offset_of!(RTCRay, tfar) == 32);
    assert!(offset_of!(RTCRay, flags) == 44);

    assert!(size_of::<RTCHit>() == 48 && align_of::<RTCHit>() == 16);
    assert!(offset_of!(RTCHit, u) == 12);
    assert!(offset_of!(RTCHit, prim_id) == 20);
    assert!(offset_of!(RTCHit, geom_id) == 24);
    assert!(offset_of!(RTCHit, inst_id) == 28);
    assert!(offset_of!(RTCHit, inst_prim_id) == 32);

    assert!(size_of::<RTCRayHit>() == 96 && align_of::<RTCRayHit>() == 16);
    assert!(offset_of!(RTCRayHit, hit) == 48);

    assert!(size_of::<RTCRayQueryContext>() == 8);

    assert!(size_of::<RTCIntersectArguments>() == 32);
    assert!(offset_of!(RTCIntersectArguments, feature_mask) == 4);
    assert!(offset_of!(RTCIntersectArguments, context) == 8);
    assert!(offset_of!(RTCIntersectArguments, filter) == 16);
    assert!(offset_of!(RTCIntersectArguments, intersect) == 24);
    assert!(size_of::<RTCOccludedArguments>() == 32);
    assert!(offset_of!(RTCOccludedArguments, occluded) == 24);

    assert!(size_of::<RTCFilterFunctionNArguments>() == 48);
    assert!(offset_of!(RTCFilterFunctionNArguments, context) == 16);
    assert!(offset_of!(RTCFilterFunctionNArguments, ray) == 24);
    assert!(offset_of!(RTCFilterFunctionNArguments, hit) == 32);
    assert!(offset_of!(RTCFilterFunctionNArguments, n) == 40);

    assert!(size_of::<c_int>() == 4 && size_of::<c_uint>() == 4);
};

/// The Embree 4.3/4.4 headers' values for every entry of [`layout_table`],
/// written out by hand from `include/embree4/rtcore_ray.h` (`RTCRay`,
/// `RTCHit` with `instPrimID`, `RTCRayHit`), `rtcore_common.h`
/// (`RTCRayQueryContext`, `RTCFilterFunctionNArguments`, `RTCFormat`,
/// `RTCRayQueryFlags`, `RTCFeatureFlags`, `RTC_BUILD_QUALITY_*`),
/// `rtcore_scene.h` (`RTCIntersectArguments`, `RTCOccludedArguments`,
/// `RTCSceneFlags`), `rtcore_device.h` (`RTCDeviceProperty`) and
/// `rtcore_buffer.h` / `rtcore_geometry.h` (buffer and geometry types) of
/// the 4.3/4.4 releases, for x86-64 with the release configuration (one
/// instance level, instance arrays on, no minimum width). The test checks
/// the table against [`layout_table`] on every machine, and against the C
/// compiler where the headers are installed.
pub const TRANSCRIBED: &[(&str, usize)] = &[
    ("sizeof(struct RTCRay)", 48),
    ("_Alignof(struct RTCRay)", 16),
    ("offsetof(struct RTCRay, org_x)", 0),
    ("offsetof(struct RTCRay, tnear)", 12),
    ("offsetof(struct RTCRay, dir_x)", 16),
    ("offsetof(struct RTCRay, time)", 28),
    ("offsetof(struct RTCRay, tfar)", 32),
    ("offsetof(struct RTCRay, mask)", 36),
    ("offsetof(struct RTCRay, id)", 40),
    ("offsetof(struct RTCRay, flags)", 44),
    ("sizeof(struct RTCHit)", 48),
    ("_Alignof(struct RTCHit)", 16),
    ("offsetof(struct RTCHit, Ng_x)", 0),
    ("offsetof(struct RTCHit, u)", 12),
    ("offsetof(struct RTCHit, v)", 16),
    ("offsetof(struct RTCHit, primID)", 20),
    ("offsetof(struct RTCHit, geomID)", 24),
    ("offsetof(struct RTCHit, instID)", 28),
    ("offsetof(struct RTCHit, instPrimID)", 32),
    ("sizeof(struct RTCRayHit)", 96),
    ("_Alignof(struct RTCRayHit)", 16),
    ("offsetof(struct RTCRayHit, ray)", 0),
    ("offsetof(struct RTCRayHit, hit)", 48),
    ("sizeof(struct RTCRayQueryContext)", 8),
    ("offsetof(struct RTCRayQueryContext, instID)", 0),
    ("offsetof(struct RTCRayQueryContext, instPrimID)", 4),
    ("sizeof(struct RTCIntersectArguments)", 32),
    ("_Alignof(struct RTCIntersectArguments)", 8),
    ("offsetof(struct RTCIntersectArguments, flags)", 0),
    ("offsetof(struct RTCIntersectArguments, feature_mask)", 4),
    ("offsetof(struct RTCIntersectArguments, context)", 8),
    ("offsetof(struct RTCIntersectArguments, filter)", 16),
    ("offsetof(struct RTCIntersectArguments, intersect)", 24),
    ("sizeof(struct RTCOccludedArguments)", 32),
    ("offsetof(struct RTCOccludedArguments, flags)", 0),
    ("offsetof(struct RTCOccludedArguments, feature_mask)", 4),
    ("offsetof(struct RTCOccludedArguments, context)", 8),
    ("offsetof(struct RTCOccludedArguments, filter)", 16),
    ("offsetof(struct RTCOccludedArguments, occluded)", 24),
    ("sizeof(struct RTCFilterFunctionNArguments)", 48),
    ("offsetof(struct RTCFilterFunctionNArguments, valid)", 0),
    (
        "offsetof(struct RTCFilterFunctionNArguments, geometryUserPtr)",
        8,
    ),
    ("offsetof(struct RTCFilterFunctionNArguments, context)", 16),
    ("offsetof(struct RTCFilterFunctionNArguments, ray)", 24),
    ("offsetof(struct RTCFilterFunctionNArguments, hit)", 32),
    ("offsetof(struct RTCFilterFunctionNArguments, N)", 40),
    ("RTC_MAX_INSTANCE_LEVEL_COUNT", 1),
    ("RTC_INVALID_GEOMETRY_ID", 0xffff_ffff),
    ("sizeof(enum RTCError)", 4),
    ("sizeof(enum RTCFormat)", 4),
    ("sizeof(enum RTCRayQueryFlags)", 4),
    ("sizeof(enum RTCFeatureFlags)", 4),
    ("RTC_FORMAT_UINT3", 0x5003),
    ("RTC_FORMAT_FLOAT3", 0x9003),
    ("RTC_BUFFER_TYPE_INDEX", 0),
    ("RTC_BUFFER_TYPE_VERTEX", 1),
    ("RTC_GEOMETRY_TYPE_TRIANGLE", 0),
    ("RTC_SCENE_FLAG_ROBUST", 4),
    ("RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS", 8),
    ("RTC_BUILD_QUALITY_MEDIUM", 1),
    ("RTC_RAY_QUERY_FLAG_INCOHERENT", 0),
    ("RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER", 2),
    ("RTC_FEATURE_FLAG_ALL", 0xffff_ffff),
    ("RTC_DEVICE_PROPERTY_VERSION_MAJOR", 1),
    ("RTC_DEVICE_PROPERTY_VERSION_MINOR", 2),
    ("RTC_DEVICE_PROPERTY_VERSION_PATCH", 3),
    ("RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED", 66),
    ("RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED", 96),
];

/// Sizes, offsets and constants as Rust has them, named as the C expression
/// that should give the same number, for `tests/accel/embree4_layout.rs`.
///
/// Over 100 lines on purpose: a flat table, one line per value checked.
#[doc(hidden)]
pub fn layout_table() -> Vec<(&'static str, usize)> {
    macro_rules! s {
        ($c:literal, $t:ty) => {
            (concat!("sizeof(", $c, ")"), size_of::<$t>())
        };
    }
    macro_rules! a {
        ($c:literal, $t:ty) => {
            (concat!("_Alignof(", $c, ")"), align_of::<$t>())
        };
    }
    macro_rules! o {
        ($c:literal, $cf:literal, $t:ty, $f:ident) => {
            (concat!("offsetof(", $c, ", ", $cf, ")"), offset_of!($t, $f))
        };
    }
    vec![
        s!("struct RTCRay", RTCRay),
        a!("struct RTCRay", RTCRay),
        o!("struct RTCRay", "org_x", RTCRay, org_x),
        o!("struct RTCRay", "tnear", RTCRay, tnear),
        o!("struct RTCRay", "dir_x", RTCRay, dir_x),
        o!("struct RTCRay", "time", RTCRay, time),
        o!("struct RTCRay", "tfar", RTCRay, tfar),
        o!("struct RTCRay", "mask", RTCRay, mask),
        o!("struct RTCRay", "id", RTCRay, id),
        o!("struct RTCRay", "flags", RTCRay, flags),
        s!("struct RTCHit", RTCHit),
        a!("struct RTCHit", RTCHit),
        o!("struct RTCHit", "Ng_x", RTCHit, ng_x),
        o!("struct RTCHit", "u", RTCHit, u),
        o!("struct RTCHit", "v", RTCHit, v),
        o!("struct RTCHit", "primID", RTCHit, prim_id),
        o!("struct RTCHit", "geomID", RTCHit, geom_id),
        o!("struct RTCHit", "instID", RTCHit, inst_id),
        o!("struct RTCHit", "instPrimID", RTCHit, inst_prim_id),
        s!("struct RTCRayHit", RTCRayHit),
        a!("struct RTCRayHit", RTCRayHit),
        o!("struct RTCRayHit", "ray", RTCRayHit, ray),
        o!("struct RTCRayHit", "hit", RTCRayHit, hit),
        s!("struct RTCRayQueryContext", RTCRayQueryContext),
        o!(
            "struct RTCRayQueryContext",
            "instID",
            RTCRayQueryContext,
            inst_id
        ),
        o!(
            "struct RTCRayQueryContext",
            "instPrimID",
            RTCRayQueryContext,
            inst_prim_id
        ),
        s!("struct RTCIntersectArguments", RTCIntersectArguments),
        a!("struct RTCIntersectArguments", RTCIntersectArguments),
        o!(
            "struct RTCIntersectArguments",
            "flags",
            RTCIntersectArguments,
            flags
        ),
        o!(
            "struct RTCIntersectArguments",
            "feature_mask",
            RTCIntersectArguments,
            feature_mask
        ),
        o!(
            "struct RTCIntersectArguments",
            "context",
            RTCIntersectArguments,
            context
        ),
        o!(
            "struct RTCIntersectArguments",
            "filter",
            RTCIntersectArguments,
            filter
        ),
        o!(
            "struct RTCIntersectArguments",
            "intersect",
            RTCIntersectArguments,
            intersect
        ),
        s!("struct RTCOccludedArguments", RTCOccludedArguments),
        o!(
            "struct RTCOccludedArguments",
            "flags",
            RTCOccludedArguments,
            flags
        ),
        o!(
            "struct RTCOccludedArguments",
            "feature_mask",
            RTCOccludedArguments,
            feature_mask
        ),
        o!(
            "struct RTCOccludedArguments",
            "context",
            RTCOccludedArguments,
            context
        ),
        o!(
            "struct RTCOccludedArguments",
            "filter",
            RTCOccludedArguments,
            filter
        ),
        o!(
            "struct RTCOccludedArguments",
            "occluded",
            RTCOccludedArguments,
            occluded
        ),
        s!(
            "struct RTCFilterFunctionNArguments",
            RTCFilterFunctionNArguments
        ),
        o!(
            "struct RTCFilterFunctionNArguments",
            "valid",
            RTCFilterFunctionNArguments,
            valid
        ),
        o!(
            "struct RTCFilterFunctionNArguments",
            "geometryUserPtr",
            RTCFilterFunctionNArguments,
            geometry_user_ptr
        ),
        o!(
            "struct RTCFilterFunctionNArguments",
            "context",
            RTCFilterFunctionNArguments,
            context
        ),
        o!(
            "struct RTCFilterFunctionNArguments",
            "ray",
            RTCFilterFunctionNArguments,
            ray
        ),
        o!(
            "struct RTCFilterFunctionNArguments",
            "hit",
            RTCFilterFunctionNArguments,
            hit
        ),
        o!(
            "struct RTCFilterFunctionNArguments",
            "N",
            RTCFilterFunctionNArguments,
            n
        ),
        ("RTC_MAX_INSTANCE_LEVEL_COUNT", RTC_MAX_INSTANCE_LEVEL_COUNT),
        ("RTC_INVALID_GEOMETRY_ID", RTC_INVALID_GEOMETRY_ID as usize),
        ("sizeof(enum RTCError)", size_of::<RTCError>()),
        ("sizeof(enum RTCFormat)", size_of::<RTCFormat>()),
        (
            "sizeof(enum RTCRayQueryFlags)",
            size_of::<RTCRayQueryFlags>(),
        ),
        ("sizeof(enum RTCFeatureFlags)", size_of::<RTCFeatureFlags>()),
        ("RTC_FORMAT_UINT3", RTC_FORMAT_UINT3 as usize),
        ("RTC_FORMAT_FLOAT3", RTC_FORMAT_FLOAT3 as usize),
        ("RTC_BUFFER_TYPE_INDEX", RTC_BUFFER_TYPE_INDEX as usize),
        ("RTC_BUFFER_TYPE_VERTEX", RTC_BUFFER_TYPE_VERTEX as usize),
        (
            "RTC_GEOMETRY_TYPE_TRIANGLE",
            RTC_GEOMETRY_TYPE_TRIANGLE as usize,
        ),
        ("RTC_SCENE_FLAG_ROBUST", RTC_SCENE_FLAG_ROBUST as usize),
        (
            "RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS",
            RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS as usize,
        ),
        (
            "RTC_BUILD_QUALITY_MEDIUM",
            RTC_BUILD_QUALITY_MEDIUM as usize,
        ),
        (
            "RTC_RAY_QUERY_FLAG_INCOHERENT",
            RTC_RAY_QUERY_FLAG_INCOHERENT as usize,
        ),
        (
            "RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER",
            RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER as usize,
        ),
        ("RTC_FEATURE_FLAG_ALL", RTC_FEATURE_FLAG_ALL as usize),
        (
            "RTC_DEVICE_PROPERTY_VERSION_MAJOR",
            RTC_DEVICE_PROPERTY_VERSION_MAJOR as usize,
        ),
        (
            "RTC_DEVICE_PROPERTY_VERSION_MINOR",
            RTC_DEVICE_PROPERTY_VERSION_MINOR as usize,
        ),
        (
            "RTC_DEVICE_PROPERTY_VERSION_PATCH",
            RTC_DEVICE_PROPERTY_VERSION_PATCH as usize,
        ),
        (
            "RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED",
            RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED as usize,
        ),
        (
            "RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED",
            RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED as usize,
        ),
    ]
}
