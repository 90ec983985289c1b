//! Finding Embree 4 at run time, loading the functions lucent calls, and
//! refusing a library whose version the binding was not checked against.
//!
//! Where: the path in `LUCENT_EMBREE4` if that is set (the only place
//! looked at then), else `libembree4.so.4`, then `libembree4.so`, by the
//! dynamic loader's usual search; opened `RTLD_LOCAL` and never closed.
//! Which: Embree 4.3 and 4.4, the releases whose headers [`super::ffi`] was
//! transcribed from; the version is asked from the library itself before
//! any call whose structs differ between releases, and any other version,
//! or a library that lacks one of the functions, is refused with a message
//! naming what was found and what is needed. Why each of these:
//! `docs/testing.md`, "The Embree 4 backend".

use std::ffi::{c_char, c_uint, c_void, CString};
use std::sync::OnceLock;

use super::ffi::*;
use crate::error::Error;

/// The environment variable naming the Embree 4 library to load.
pub(crate) const ENV_VAR: &str = "LUCENT_EMBREE4";

/// The names looked for without `LUCENT_EMBREE4`: the soname Embree 4's
/// packages install, then the development symlink.
pub(crate) const LIB_NAMES: [&str; 2] = ["libembree4.so.4", "libembree4.so"];

/// The library as `dynlib` opens it and its errors name it.
const WANTED: crate::dynlib::Wanted = crate::dynlib::Wanted {
    env_var: ENV_VAR,
    names: &LIB_NAMES,
    name: "Embree 4",
    kind: "Embree 4",
    install: "Debian 13: `apt-get install libembree4-4`; or set LUCENT_EMBREE4 to the path of libembree4.so.4, e.g. the one scripts/install-deps.sh unpacks into .cache/embree4/",
};

/// The Embree 4 minor releases the binding was checked against.
pub(crate) const KNOWN_MINORS: std::ops::RangeInclusive<u32> = 3..=4;

/// The Embree 4 functions lucent calls, looked up in the loaded library.
/// Each pointer stays valid as long as `_lib`, which lives in a `static`
/// and so for the whole process.
pub struct Api {
    /// What was loaded: the path or name given to the loader.
    pub path: String,
    /// (major, minor, patch), as the library reports it.
    pub version: (u32, u32, u32),
    pub new_device: unsafe extern "C" fn(config: *const c_char) -> RTCDevice,
    pub release_device: unsafe extern "C" fn(device: RTCDevice),
    pub get_device_property: unsafe extern "C" fn(RTCDevice, RTCDeviceProperty) -> isize,
    pub get_device_error: unsafe extern "C" fn(device: RTCDevice) -> RTCError,
    pub set_device_error_function:
        unsafe extern "C" fn(device: RTCDevice, error: RTCErrorFunction, user: *mut c_void),
    pub new_scene: unsafe extern "C" fn(device: RTCDevice) -> RTCScene,
    pub release_scene: unsafe extern "C" fn(scene: RTCScene),
    pub set_scene_flags: unsafe extern "C" fn(scene: RTCScene, flags: RTCSceneFlags),
    pub get_scene_flags: unsafe extern "C" fn(scene: RTCScene) -> RTCSceneFlags,
    pub set_scene_build_quality: unsafe extern "C" fn(scene: RTCScene, q: RTCBuildQuality),
    pub attach_geometry_by_id:
        unsafe extern "C" fn(scene: RTCScene, geometry: RTCGeometry, id: c_uint),
    pub commit_scene: unsafe extern "C" fn(scene: RTCScene),
    pub new_geometry: unsafe extern "C" fn(device: RTCDevice, ty: RTCGeometryType) -> RTCGeometry,
    pub release_geometry: unsafe extern "C" fn(geometry: RTCGeometry),
    #[allow(clippy::type_complexity)]
    pub set_shared_geometry_buffer: unsafe extern "C" fn(
        geometry: RTCGeometry,
        ty: RTCBufferType,
        slot: c_uint,
        format: RTCFormat,
        ptr: *const c_void,
        byte_offset: usize,
        byte_stride: usize,
        item_count: usize,
    ),
    pub commit_geometry: unsafe extern "C" fn(geometry: RTCGeometry),
    pub intersect1: unsafe extern "C" fn(
        scene: RTCScene,
        rayhit: *mut RTCRayHit,
        args: *mut RTCIntersectArguments,
    ),
    pub occluded1:
        unsafe extern "C" fn(scene: RTCScene, ray: *mut RTCRay, args: *mut RTCOccludedArguments),
    _lib: libloading::Library,
}

/// What the embree4 backend needs, for the version errors.
fn need() -> String {
    let (lo, hi) = (KNOWN_MINORS.start(), KNOWN_MINORS.end());
    format!("the embree4 backend needs Embree 4.{lo} to 4.{hi}")
}

/// Why Embree 4 could not be loaded; every message names the library (or
/// the places it was looked for) and what is needed.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// Not opened, or a function missing from it.
    #[error(transparent)]
    Open(#[from] crate::dynlib::OpenError),
    #[error("{path}: rtcNewDevice failed: {} ({code})", super::super::embree_shared::error_name(*.code))]
    NoDevice { path: String, code: RTCError },
    #[error("{path} is Embree {major}.{minor}.{patch}, not Embree 4: {}", need())]
    NotEmbree4 {
        path: String,
        major: u32,
        minor: u32,
        patch: u32,
    },
    #[error(
        "{path} is Embree {major}.{minor}.{patch}, too old: {} (before 4.3 RTCRayHit \
         had another layout)",
        need()
    )]
    TooOld {
        path: String,
        major: u32,
        minor: u32,
        patch: u32,
    },
    #[error(
        "{path} is Embree {major}.{minor}.{patch}, newer than this lucent knows: {} \
         (the layouts of a later release are unchecked; use --accel embree3 or bvh, or a \
         lucent built for it)",
        need()
    )]
    TooNew {
        path: String,
        major: u32,
        minor: u32,
        patch: u32,
    },
    #[error(
        "{path} (Embree {major}.{minor}.{patch}) was built without triangle or \
         filter-function support"
    )]
    MissingFeatures {
        path: String,
        major: u32,
        minor: u32,
        patch: u32,
    },
}

/// Whether `version` is one the binding knows; the error says what was
/// found and what is needed.
pub fn check_version(path: &str, (major, minor, patch): (u32, u32, u32)) -> Result<(), LoadError> {
    let path = path.to_string();
    if major != 4 {
        return Err(LoadError::NotEmbree4 {
            path,
            major,
            minor,
            patch,
        });
    }
    if minor < *KNOWN_MINORS.start() {
        return Err(LoadError::TooOld {
            path,
            major,
            minor,
            patch,
        });
    }
    if minor > *KNOWN_MINORS.end() {
        return Err(LoadError::TooNew {
            path,
            major,
            minor,
            patch,
        });
    }
    Ok(())
}

/// The loaded Embree 4, or why there is none (loaded once per process).
pub fn api() -> Result<&'static Api, Error> {
    static API: OnceLock<Result<Api, LoadError>> = OnceLock::new();
    API.get_or_init(load)
        .as_ref()
        .map_err(|why| Error::Unavailable(why.to_string()))
}

fn load() -> Result<Api, LoadError> {
    bind(crate::dynlib::open(&WANTED)?)
}

/// Looks every function up, then asks the version before anything else.
fn bind(lib: crate::dynlib::Opened) -> Result<Api, LoadError> {
    macro_rules! sym {
        ($name:literal) => {
            // SAFETY: the symbol, if present, is the Embree function of
            // that name, whose C signature is the field's type (ffi.rs,
            // checked against the headers); the pointer is kept together
            // with the library, which is never unloaded.
            unsafe { lib.function(concat!($name, "\0")) }?
        };
    }
    let path = lib.path.clone();
    let mut api = Api {
        path: path.clone(),
        version: (0, 0, 0),
        new_device: sym!("rtcNewDevice"),
        release_device: sym!("rtcReleaseDevice"),
        get_device_property: sym!("rtcGetDeviceProperty"),
        get_device_error: sym!("rtcGetDeviceError"),
        set_device_error_function: sym!("rtcSetDeviceErrorFunction"),
        new_scene: sym!("rtcNewScene"),
        release_scene: sym!("rtcReleaseScene"),
        set_scene_flags: sym!("rtcSetSceneFlags"),
        get_scene_flags: sym!("rtcGetSceneFlags"),
        set_scene_build_quality: sym!("rtcSetSceneBuildQuality"),
        attach_geometry_by_id: sym!("rtcAttachGeometryByID"),
        commit_scene: sym!("rtcCommitScene"),
        new_geometry: sym!("rtcNewGeometry"),
        release_geometry: sym!("rtcReleaseGeometry"),
        set_shared_geometry_buffer: sym!("rtcSetSharedGeometryBuffer"),
        commit_geometry: sym!("rtcCommitGeometry"),
        intersect1: sym!("rtcIntersect1"),
        occluded1: sym!("rtcOccluded1"),
        _lib: lib.lib,
    };
    // rtcNewDevice, rtcGetDeviceProperty, rtcGetDeviceError and
    // rtcReleaseDevice have had these signatures since Embree 3.0, so they
    // are safe to call on any Embree before its version is known.
    let config = CString::new("threads=1").expect("no NUL");
    // SAFETY: a NUL-terminated config string alive for the call.
    let dev = unsafe { (api.new_device)(config.as_ptr()) };
    if dev.is_null() {
        // SAFETY: with a null device, the error of the failed rtcNewDevice.
        let code = unsafe { (api.get_device_error)(std::ptr::null_mut()) };
        return Err(LoadError::NoDevice { path, code });
    }
    // SAFETY: `dev` is a live device; properties are plain queries.
    let p = |prop| unsafe { (api.get_device_property)(dev, prop) };
    let v = |x: isize| u32::try_from(x).unwrap_or(u32::MAX);
    let version = (
        v(p(RTC_DEVICE_PROPERTY_VERSION_MAJOR)),
        v(p(RTC_DEVICE_PROPERTY_VERSION_MINOR)),
        v(p(RTC_DEVICE_PROPERTY_VERSION_PATCH)),
    );
    let features = (
        p(RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED),
        p(RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED),
    );
    // SAFETY: we own the one reference to `dev`.
    unsafe { (api.release_device)(dev) };
    check_version(&path, version)?;
    if features.0 == 0 || features.1 == 0 {
        return Err(LoadError::MissingFeatures {
            path,
            major: version.0,
            minor: version.1,
            patch: version.2,
        });
    }
    api.version = version;
    Ok(api)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_install_advice_names_the_variable_looked_at() {
        // the advice is a literal beside ENV_VAR: a renamed variable left
        // in it would send users to set the wrong one
        assert!(WANTED.install.contains(ENV_VAR), "{}", WANTED.install);
    }

    #[test]
    fn only_embree_4_3_and_4_4_pass_the_version_check() {
        for ok in [(4, 3, 0), (4, 3, 3), (4, 4, 0), (4, 4, 9)] {
            assert!(check_version("lib", ok).is_ok(), "{ok:?}");
        }
        let msg = |v| check_version("/x/lib.so", v).unwrap_err().to_string();
        let e = msg((3, 13, 5));
        assert!(
            e.contains("/x/lib.so is Embree 3.13.5, not Embree 4"),
            "{e}"
        );
        assert!(e.contains("needs Embree 4.3 to 4.4"), "{e}");
        let e = msg((4, 2, 0));
        assert!(e.contains("Embree 4.2.0, too old"), "{e}");
        let e = msg((4, 5, 0));
        assert!(
            e.contains("Embree 4.5.0, newer than this lucent knows"),
            "{e}"
        );
        assert!(msg((5, 0, 0)).contains("not Embree 4"));
    }
}
