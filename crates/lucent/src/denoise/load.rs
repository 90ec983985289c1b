//! Finding Open Image Denoise at run time, loading the functions lucent
//! calls, and refusing a library that is not OIDN 2.x.
//!
//! Where: the path in `LUCENT_OIDN` if that is set (the only place looked
//! at then), else `libOpenImageDenoise.so.2`, then
//! `libOpenImageDenoise.so`, by the dynamic loader's usual search; opened
//! `RTLD_LOCAL` and never closed (OIDN loads its CPU device module from the
//! library's own directory). Which: major version 2, asked from a CPU
//! device before anything else is done with it (docs/output.md,
//! "Denoising").

use std::ffi::{c_char, c_int, c_void, CStr, CString};
use std::sync::OnceLock;

use super::ffi::*;
use crate::error::Error;

/// The environment variable naming the OIDN library to load.
pub const ENV_VAR: &str = "LUCENT_OIDN";

/// The names looked for without `LUCENT_OIDN`: the soname of OIDN 2, then
/// the development symlink.
pub(crate) const LIB_NAMES: [&str; 2] = ["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"];

/// The library as `dynlib` opens it and its errors name it.
const WANTED: crate::dynlib::Wanted = crate::dynlib::Wanted {
    env_var: ENV_VAR,
    names: &LIB_NAMES,
    name: "Open Image Denoise",
    kind: "Open Image Denoise 2",
    install: "set LUCENT_OIDN to the path of libOpenImageDenoise.so.2, e.g. the one scripts/install-deps.sh unpacks into .cache/oidn/lib/",
};

/// The OIDN functions lucent calls, looked up in the loaded library. Each
/// pointer stays valid as long as `_lib`, which lives in a `static` and so
/// for the whole process.
pub struct Api {
    /// What was loaded: the path or name given to the loader.
    pub path: String,
    /// (major, minor, patch), as the library reports it.
    pub version: (u32, u32, u32),
    pub new_device: unsafe extern "C" fn(ty: OIDNDeviceType) -> OIDNDevice,
    pub release_device: unsafe extern "C" fn(device: OIDNDevice),
    pub set_device_int: unsafe extern "C" fn(device: OIDNDevice, name: *const c_char, v: c_int),
    pub get_device_int: unsafe extern "C" fn(device: OIDNDevice, name: *const c_char) -> c_int,
    pub get_device_error:
        unsafe extern "C" fn(device: OIDNDevice, message: *mut *const c_char) -> OIDNError,
    pub commit_device: unsafe extern "C" fn(device: OIDNDevice),
    pub new_filter: unsafe extern "C" fn(device: OIDNDevice, ty: *const c_char) -> OIDNFilter,
    pub release_filter: unsafe extern "C" fn(filter: OIDNFilter),
    #[allow(clippy::type_complexity)]
    pub set_shared_filter_image: unsafe extern "C" fn(
        filter: OIDNFilter,
        name: *const c_char,
        ptr: *mut c_void,
        format: OIDNFormat,
        width: usize,
        height: usize,
        byte_offset: usize,
        pixel_byte_stride: usize,
        row_byte_stride: usize,
    ),
    pub set_filter_bool: unsafe extern "C" fn(filter: OIDNFilter, name: *const c_char, v: bool),
    pub set_filter_int: unsafe extern "C" fn(filter: OIDNFilter, name: *const c_char, v: c_int),
    pub commit_filter: unsafe extern "C" fn(filter: OIDNFilter),
    pub execute_filter: unsafe extern "C" fn(filter: OIDNFilter),
    _lib: libloading::Library,
}

/// Why OIDN could not be loaded; every message names the library (or the
/// places it was looked for) and what is needed.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// Not opened, or a function missing from it.
    #[error(transparent)]
    Open(#[from] crate::dynlib::OpenError),
    #[error("{path}: no CPU device: {message} ({})", error_name(*.code))]
    NoDevice {
        path: String,
        code: OIDNError,
        message: String,
    },
    #[error("{path} is Open Image Denoise {major}.{minor}.{patch}: lucent needs 2.x")]
    NotOidn2 {
        path: String,
        major: u32,
        minor: u32,
        patch: u32,
    },
}

/// Whether `version` is one the binding knows (any 2.x: the C API lucent
/// uses has no structs and keeps its signatures within a major release).
pub fn check_version(path: &str, (major, minor, patch): (u32, u32, u32)) -> Result<(), LoadError> {
    if major == 2 {
        return Ok(());
    }
    Err(LoadError::NotOidn2 {
        path: path.to_string(),
        major,
        minor,
        patch,
    })
}

/// The loaded OIDN, or why there is none (loaded once per process).
pub fn api() -> Result<&'static Api, Error> {
    static API: OnceLock<Result<Api, LoadError>> = OnceLock::new();
    API.get_or_init(load)
        .as_ref()
        .map_err(|why| Error::Unavailable(format!("cannot denoise: {why}")))
}

/// One line for `lucent info`: the version and where it came from, or why
/// there is none.
pub fn report() -> String {
    match api() {
        Ok(a) => {
            let (ma, mi, pa) = a.version;
            format!("denoiser: Open Image Denoise {ma}.{mi}.{pa} ({})", a.path)
        }
        Err(e) => format!("denoiser: unavailable ({e})"),
    }
}

fn load() -> Result<Api, LoadError> {
    bind(crate::dynlib::open(&WANTED)?)
}

/// Looks every function up, then asks a CPU device for the version.
fn bind(lib: crate::dynlib::Opened) -> Result<Api, LoadError> {
    macro_rules! sym {
        ($name:literal) => {
            // SAFETY: the symbol, if present, is the OIDN function of that
            // name, whose C signature (oidn.h, 2.x) is the field's type; the
            // pointer is kept together with the library, which is never
            // unloaded.
            unsafe { lib.function(concat!($name, "\0")) }?
        };
    }
    let path = lib.path.clone();
    let mut api = Api {
        path: path.clone(),
        version: (0, 0, 0),
        new_device: sym!("oidnNewDevice"),
        release_device: sym!("oidnReleaseDevice"),
        set_device_int: sym!("oidnSetDeviceInt"),
        get_device_int: sym!("oidnGetDeviceInt"),
        get_device_error: sym!("oidnGetDeviceError"),
        commit_device: sym!("oidnCommitDevice"),
        new_filter: sym!("oidnNewFilter"),
        release_filter: sym!("oidnReleaseFilter"),
        set_shared_filter_image: sym!("oidnSetSharedFilterImage"),
        set_filter_bool: sym!("oidnSetFilterBool"),
        set_filter_int: sym!("oidnSetFilterInt"),
        commit_filter: sym!("oidnCommitFilter"),
        execute_filter: sym!("oidnExecuteFilter"),
        _lib: lib.lib,
    };
    // SAFETY: creating a device has no preconditions.
    let dev = unsafe { (api.new_device)(OIDN_DEVICE_TYPE_CPU) };
    if dev.is_null() {
        let (code, message) = last_error(&api, std::ptr::null_mut());
        return Err(LoadError::NoDevice {
            path,
            code,
            message,
        });
    }
    let key = |k: &str| CString::new(k).expect("no NUL");
    let (ma, mi, pa) = (
        key("versionMajor"),
        key("versionMinor"),
        key("versionPatch"),
    );
    // SAFETY: `dev` is a live device; version queries are plain reads
    // allowed before commit, with NUL-terminated names alive for the call.
    let get = |k: &CString| unsafe { (api.get_device_int)(dev, k.as_ptr()) };
    let v = |x: c_int| u32::try_from(x).unwrap_or(u32::MAX);
    let version = (v(get(&ma)), v(get(&mi)), v(get(&pa)));
    // SAFETY: we own the one reference to `dev`.
    unsafe { (api.release_device)(dev) };
    check_version(&path, version)?;
    api.version = version;
    Ok(api)
}

/// The first error stored for `device` (or, with a null device, for this
/// thread) and its message, clearing it.
pub(crate) fn last_error(api: &Api, device: OIDNDevice) -> (OIDNError, String) {
    let mut msg: *const c_char = std::ptr::null();
    // SAFETY: `device` is live or null (both allowed); `msg` is a valid
    // out-pointer. OIDN owns the returned string, valid until the next
    // call on this thread, so it is copied at once.
    let code = unsafe { (api.get_device_error)(device, &mut msg) };
    let text = if msg.is_null() {
        String::new()
    } else {
        // SAFETY: a non-null message is a NUL-terminated C string.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    };
    (code, text)
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
    fn only_oidn_2_passes_the_version_check() {
        for ok in [(2, 0, 0), (2, 5, 1), (2, 9, 0)] {
            assert!(check_version("lib", ok).is_ok(), "{ok:?}");
        }
        for bad in [(1, 4, 3), (3, 0, 0), (0, 0, 0)] {
            let e = check_version("/x/lib.so", bad).unwrap_err().to_string();
            assert!(e.contains("/x/lib.so is Open Image Denoise"), "{e}");
            assert!(e.contains("lucent needs 2.x"), "{e}");
        }
    }
}
