//! Raw bindings to the part of the Embree 3 C API (`embree3/rtcore*.h`, as
//! shipped by Debian 12's `libembree-dev` 3.13.5) that lucent calls.
//!
//! Hand-written rather than generated so the crate needs no bindgen/libclang
//! and so every struct we share with Embree carries compile-time size and
//! offset checks. The values are those of a build with
//! `RTC_MAX_INSTANCE_LEVEL_COUNT == 1` and `RTC_MIN_WIDTH == 0` (see
//! `rtcore_config.h`); `tests/accel/embree_layout.rs` compiles a C program against
//! the installed headers and compares it with [`layout_table`], so a library
//! built with other options fails the tests instead of corrupting memory.

#![allow(non_camel_case_types, dead_code)]

use std::ffi::{c_char, c_int, c_uint, c_void};
use std::mem::{align_of, offset_of, size_of};

/// `RTC_INVALID_GEOMETRY_ID`, `((unsigned int)-1)`.
pub const RTC_INVALID_GEOMETRY_ID: c_uint = u32::MAX;

/// `RTC_MAX_INSTANCE_LEVEL_COUNT` of the installed library.
pub(crate) const RTC_MAX_INSTANCE_LEVEL_COUNT: usize = 1;

#[repr(C)]
pub struct RTCDeviceTy {
    _private: [u8; 0],
}
#[repr(C)]
pub(crate) struct RTCSceneTy {
    _private: [u8; 0],
}
#[repr(C)]
pub(crate) struct RTCGeometryTy {
    _private: [u8; 0],
}
pub(crate) type RTCDevice = *mut RTCDeviceTy;
pub(crate) type RTCScene = *mut RTCSceneTy;
pub(crate) type RTCGeometry = *mut RTCGeometryTy;

// C enums are `int`-sized on the x86-64 and AArch64 SysV ABIs; we pass them
// as plain integers so an out-of-range value from C can never be an invalid
// Rust enum.
pub(crate) type RTCError = c_int;
pub(crate) const RTC_ERROR_NONE: RTCError = 0;
pub(crate) const RTC_ERROR_UNKNOWN: RTCError = 1;
pub(crate) const RTC_ERROR_INVALID_ARGUMENT: RTCError = 2;
pub(crate) const RTC_ERROR_INVALID_OPERATION: RTCError = 3;
pub(crate) const RTC_ERROR_OUT_OF_MEMORY: RTCError = 4;
pub(crate) const RTC_ERROR_UNSUPPORTED_CPU: RTCError = 5;
pub(crate) const RTC_ERROR_CANCELLED: RTCError = 6;

pub(crate) type RTCDeviceProperty = c_int;
pub(crate) const RTC_DEVICE_PROPERTY_VERSION_MAJOR: RTCDeviceProperty = 1;
pub(crate) const RTC_DEVICE_PROPERTY_VERSION_MINOR: RTCDeviceProperty = 2;
pub(crate) const RTC_DEVICE_PROPERTY_VERSION_PATCH: RTCDeviceProperty = 3;
pub(crate) const RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED: RTCDeviceProperty = 66;
pub(crate) const RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED: RTCDeviceProperty = 96;

pub(crate) type RTCSceneFlags = c_int;
pub(crate) const RTC_SCENE_FLAG_NONE: RTCSceneFlags = 0;
pub(crate) const RTC_SCENE_FLAG_ROBUST: RTCSceneFlags = 1 << 2;
pub(crate) const RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION: RTCSceneFlags = 1 << 3;

pub(crate) type RTCBuildQuality = c_int;
pub(crate) const RTC_BUILD_QUALITY_LOW: RTCBuildQuality = 0;
pub(crate) const RTC_BUILD_QUALITY_MEDIUM: RTCBuildQuality = 1;
pub(crate) const RTC_BUILD_QUALITY_HIGH: RTCBuildQuality = 2;

pub(crate) type RTCGeometryType = c_int;
pub(crate) const RTC_GEOMETRY_TYPE_TRIANGLE: RTCGeometryType = 0;

pub(crate) type RTCBufferType = c_int;
pub(crate) const RTC_BUFFER_TYPE_INDEX: RTCBufferType = 0;
pub(crate) const RTC_BUFFER_TYPE_VERTEX: RTCBufferType = 1;

pub(crate) type RTCFormat = c_int;
pub(crate) const RTC_FORMAT_UINT3: RTCFormat = 0x5003;
pub(crate) const RTC_FORMAT_FLOAT3: RTCFormat = 0x9003;

pub(crate) type RTCIntersectContextFlags = c_int;
/// `RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT` is `(0 << 0)`, what
/// `rtcInitIntersectContext` sets.
pub(crate) const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: RTCIntersectContextFlags = 0;

/// `struct RTC_ALIGN(16) RTCRay`.
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

/// `struct RTC_ALIGN(16) RTCHit`.
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
}

/// `struct RTCRayHit` (no explicit alignment; 16 from its members).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCRayHit {
    pub ray: RTCRay,
    pub hit: RTCHit,
}

/// `RTCFilterFunctionN`: called by Embree for each candidate hit when a
/// filter is installed. Embree does not unwind, so implementations must not
/// panic.
pub(crate) type RTCFilterFunctionN =
    Option<unsafe extern "C" fn(args: *const RTCFilterFunctionNArguments)>;

/// `struct RTCIntersectContext` (without `instStackSize`, present only when
/// `RTC_MAX_INSTANCE_LEVEL_COUNT > 1`, and `minWidthDistanceFactor`, only
/// when `RTC_MIN_WIDTH`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct RTCIntersectContext {
    pub flags: RTCIntersectContextFlags,
    pub filter: RTCFilterFunctionN,
    pub inst_id: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
}

impl RTCIntersectContext {
    /// `rtcInitIntersectContext`, a `static inline` in `rtcore_common.h` and
    /// so not exported by the library.
    pub fn new() -> Self {
        RTCIntersectContext {
            flags: RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT,
            filter: None,
            inst_id: [RTC_INVALID_GEOMETRY_ID; RTC_MAX_INSTANCE_LEVEL_COUNT],
        }
    }
}

impl Default for RTCIntersectContext {
    fn default() -> Self {
        Self::new()
    }
}

/// Opaque `RTCRayN` / `RTCHitN`: structure-of-arrays packets of runtime
/// width `N`, read through the accessors below.
#[repr(C)]
pub struct RTCRayN {
    _private: [u8; 0],
}
#[repr(C)]
pub struct RTCHitN {
    _private: [u8; 0],
}

/// `struct RTCFilterFunctionNArguments`.
#[repr(C)]
#[derive(Debug)]
pub struct RTCFilterFunctionNArguments {
    pub valid: *mut c_int,
    pub geometry_user_ptr: *mut c_void,
    pub context: *mut RTCIntersectContext,
    pub ray: *mut RTCRayN,
    pub hit: *mut RTCHitN,
    pub n: c_uint,
}

/// `RTCErrorFunction`. Must not unwind into Embree.
pub(crate) type RTCErrorFunction =
    Option<unsafe extern "C" fn(user_ptr: *mut c_void, code: RTCError, str: *const c_char)>;

extern "C" {
    pub fn rtcNewDevice(config: *const c_char) -> RTCDevice;
    pub(crate) fn rtcReleaseDevice(device: RTCDevice);
    pub(crate) fn rtcGetDeviceProperty(device: RTCDevice, prop: RTCDeviceProperty) -> isize;
    pub(crate) fn rtcGetDeviceError(device: RTCDevice) -> RTCError;
    pub(crate) fn rtcSetDeviceErrorFunction(
        device: RTCDevice,
        error: RTCErrorFunction,
        user_ptr: *mut c_void,
    );

    pub(crate) fn rtcNewScene(device: RTCDevice) -> RTCScene;
    pub(crate) fn rtcReleaseScene(scene: RTCScene);
    pub(crate) fn rtcSetSceneFlags(scene: RTCScene, flags: RTCSceneFlags);
    pub(crate) fn rtcGetSceneFlags(scene: RTCScene) -> RTCSceneFlags;
    pub(crate) fn rtcSetSceneBuildQuality(scene: RTCScene, quality: RTCBuildQuality);
    pub(crate) fn rtcAttachGeometryByID(scene: RTCScene, geometry: RTCGeometry, geom_id: c_uint);
    pub(crate) fn rtcCommitScene(scene: RTCScene);

    pub(crate) fn rtcNewGeometry(device: RTCDevice, ty: RTCGeometryType) -> RTCGeometry;
    pub(crate) fn rtcReleaseGeometry(geometry: RTCGeometry);
    pub(crate) fn rtcSetGeometryBuildQuality(geometry: RTCGeometry, quality: RTCBuildQuality);
    pub(crate) fn rtcSetSharedGeometryBuffer(
        geometry: RTCGeometry,
        ty: RTCBufferType,
        slot: c_uint,
        format: RTCFormat,
        ptr: *const c_void,
        byte_offset: usize,
        byte_stride: usize,
        item_count: usize,
    );
    pub(crate) fn rtcCommitGeometry(geometry: RTCGeometry);

    pub(crate) fn rtcIntersect1(
        scene: RTCScene,
        context: *mut RTCIntersectContext,
        rayhit: *mut RTCRayHit,
    );
    pub(crate) fn rtcOccluded1(
        scene: RTCScene,
        context: *mut RTCIntersectContext,
        ray: *mut RTCRay,
    );
}

// Layout checks against the Embree 3.13.5 headers (x86-64 / AArch64).
const _: () = {
    assert!(size_of::<RTCRay>() == 48 && align_of::<RTCRay>() == 16);
    assert!(offset_of!(RTCRay, org_x) == 0);
    assert!(offset_of!(RTCRay, tnear) == 12);
    assert!(offset_of!(RTCRay, dir_x) == 16);
    assert!(offset_of!(RTCRay, time) == 28);
    assert!(offset_of!(RTCRay, tfar) == 32);
    assert!(offset_of!(RTCRay, mask) == 36);
    assert!(offset_of!(RTCRay, id) == 40);
    assert!(offset_of!(RTCRay, flags) == 44);

    assert!(size_of::<RTCHit>() == 32 && align_of::<RTCHit>() == 16);
    assert!(offset_of!(RTCHit, ng_x) == 0);
    assert!(offset_of!(RTCHit, u) == 12);
    assert!(offset_of!(RTCHit, v) == 16);
    assert!(offset_of!(RTCHit, prim_id) == 20);
    assert!(offset_of!(RTCHit, geom_id) == 24);
    assert!(offset_of!(RTCHit, inst_id) == 28);

    assert!(size_of::<RTCRayHit>() == 80 && align_of::<RTCRayHit>() == 16);
    assert!(offset_of!(RTCRayHit, ray) == 0);
    assert!(offset_of!(RTCRayHit, hit) == 48);

    assert!(size_of::<RTCIntersectContext>() == 24);
    assert!(offset_of!(RTCIntersectContext, flags) == 0);
    assert!(offset_of!(RTCIntersectContext, filter) == 8);
    assert!(offset_of!(RTCIntersectContext, inst_id) == 16);

    assert!(size_of::<RTCFilterFunctionNArguments>() == 48);
    assert!(offset_of!(RTCFilterFunctionNArguments, valid) == 0);
    assert!(offset_of!(RTCFilterFunctionNArguments, geometry_user_ptr) == 8);
    assert!(offset_of!(RTCFilterFunctionNArguments, context) == 16);
    assert!(offset_of!(RTCFilterFunctionNArguments, ray) == 24);
    assert!(offset_of!(RTCFilterFunctionNArguments, hit) == 32);
    assert!(offset_of!(RTCFilterFunctionNArguments, n) == 40);

    // The SoA accessors assume 4-byte lanes, as the header's casts to float*.
    assert!(size_of::<f32>() == 4 && size_of::<c_uint>() == 4);
    // Enums passed as c_int: the C ABI here gives them int size.
    assert!(size_of::<c_int>() == 4);
};

/// The folder of the Embree 3 headers this library was built against
/// (found by build.rs), for `tests/embree_layout.rs`.
#[doc(hidden)]
pub const INCLUDE_DIR: &str = env!("LUCENT_EMBREE_INCLUDE");

/// Sizes and offsets of the shared structs as Rust lays them out, named as
/// the C expression that should give the same number (`sizeof(RTCRay)`,
/// `offsetof(RTCRay, tfar)`, ...), for `tests/accel/embree_layout.rs`.
///
/// Over 120 lines on purpose: it is a flat table, one line per size or
/// offset checked, and reads best as one list beside the C side's.
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
        o!("struct RTCRay", "org_y", RTCRay, org_y),
        o!("struct RTCRay", "org_z", RTCRay, org_z),
        o!("struct RTCRay", "tnear", RTCRay, tnear),
        o!("struct RTCRay", "dir_x", RTCRay, dir_x),
        o!("struct RTCRay", "dir_y", RTCRay, dir_y),
        o!("struct RTCRay", "dir_z", RTCRay, dir_z),
        o!("struct RTCRay", "time", RTCRay, time),
        o!("struct RTCRay", "tfar", RTCRay, tfar),
        o!("struct RTCRay", "mask", RTCRay, mask),
        o!("struct RTCRay", "id", RTCRay, id),
        o!("struct RTCRay", "flags", RTCRay, flags),
        s!("struct RTCHit", RTCHit),
        a!("struct RTCHit", RTCHit),
        o!("struct RTCHit", "Ng_x", RTCHit, ng_x),
        o!("struct RTCHit", "Ng_y", RTCHit, ng_y),
        o!("struct RTCHit", "Ng_z", RTCHit, ng_z),
        o!("struct RTCHit", "u", RTCHit, u),
        o!("struct RTCHit", "v", RTCHit, v),
        o!("struct RTCHit", "primID", RTCHit, prim_id),
        o!("struct RTCHit", "geomID", RTCHit, geom_id),
        o!("struct RTCHit", "instID", RTCHit, inst_id),
        s!("struct RTCRayHit", RTCRayHit),
        a!("struct RTCRayHit", RTCRayHit),
        o!("struct RTCRayHit", "ray", RTCRayHit, ray),
        o!("struct RTCRayHit", "hit", RTCRayHit, hit),
        s!("struct RTCIntersectContext", RTCIntersectContext),
        a!("struct RTCIntersectContext", RTCIntersectContext),
        o!(
            "struct RTCIntersectContext",
            "flags",
            RTCIntersectContext,
            flags
        ),
        o!(
            "struct RTCIntersectContext",
            "filter",
            RTCIntersectContext,
            filter
        ),
        o!(
            "struct RTCIntersectContext",
            "instID",
            RTCIntersectContext,
            inst_id
        ),
        s!(
            "struct RTCFilterFunctionNArguments",
            RTCFilterFunctionNArguments
        ),
        a!(
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
        // Constants and enum sizes the bindings hard-code.
        ("RTC_MAX_INSTANCE_LEVEL_COUNT", RTC_MAX_INSTANCE_LEVEL_COUNT),
        ("RTC_INVALID_GEOMETRY_ID", RTC_INVALID_GEOMETRY_ID as usize),
        ("sizeof(enum RTCError)", size_of::<RTCError>()),
        ("sizeof(enum RTCFormat)", size_of::<RTCFormat>()),
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
            "RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION",
            RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION as usize,
        ),
        (
            "RTC_BUILD_QUALITY_MEDIUM",
            RTC_BUILD_QUALITY_MEDIUM as usize,
        ),
        (
            "RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT",
            RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT as usize,
        ),
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
