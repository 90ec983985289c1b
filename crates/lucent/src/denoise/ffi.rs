//! Raw types and constants of the part of Intel Open Image Denoise's C API
//! (`OpenImageDenoise/oidn.h`, release 2.x) that lucent calls. The
//! functions are not declared here but looked up at run time
//! ([`super::load::Api`]); their signatures are the fields' types there.
//!
//! Transcribed from the 2.x header: handles are opaque pointers, enums are
//! C `int`s (passed as plain integers so a value from C is never an invalid
//! Rust enum), sizes and strides `size_t`. No struct crosses the boundary,
//! which is why any 2.x release is accepted (docs/output.md, "Denoising").

#![allow(non_camel_case_types, dead_code)]

use std::ffi::{c_char, c_int, c_void};

#[repr(C)]
pub struct OIDNDeviceImpl {
    _private: [u8; 0],
}
#[repr(C)]
pub struct OIDNFilterImpl {
    _private: [u8; 0],
}
/// `OIDNDevice`.
pub(crate) type OIDNDevice = *mut OIDNDeviceImpl;
/// `OIDNFilter`.
pub(crate) type OIDNFilter = *mut OIDNFilterImpl;

/// `OIDNDeviceType`.
pub(crate) type OIDNDeviceType = c_int;
pub(crate) const OIDN_DEVICE_TYPE_CPU: OIDNDeviceType = 1;

/// `OIDNError`.
pub(crate) type OIDNError = c_int;
pub(crate) const OIDN_ERROR_NONE: OIDNError = 0;
pub(crate) const OIDN_ERROR_OUT_OF_MEMORY: OIDNError = 4;
pub(crate) const OIDN_ERROR_UNSUPPORTED_HARDWARE: OIDNError = 5;

/// `OIDNFormat`.
pub(crate) type OIDNFormat = c_int;
pub(crate) const OIDN_FORMAT_FLOAT3: OIDNFormat = 3;

/// `OIDNErrorFunction`: `void (*)(void* userPtr, OIDNError code, const
/// char* message)`.
pub(crate) type OIDNErrorFunction =
    Option<unsafe extern "C" fn(user: *mut c_void, code: OIDNError, message: *const c_char)>;

/// The name of an `OIDNError` code, for messages.
pub(crate) fn error_name(code: OIDNError) -> &'static str {
    match code {
        0 => "OIDN_ERROR_NONE",
        1 => "OIDN_ERROR_UNKNOWN",
        2 => "OIDN_ERROR_INVALID_ARGUMENT",
        3 => "OIDN_ERROR_INVALID_OPERATION",
        4 => "OIDN_ERROR_OUT_OF_MEMORY",
        5 => "OIDN_ERROR_UNSUPPORTED_HARDWARE",
        6 => "OIDN_ERROR_CANCELLED",
        _ => "an unknown OIDNError",
    }
}

// The header's values, asserted so an edit that changes one is caught.
const _: () = assert!(OIDN_DEVICE_TYPE_CPU == 1 && OIDN_FORMAT_FLOAT3 == 3);
const _: () = assert!(std::mem::size_of::<OIDNErrorFunction>() == std::mem::size_of::<usize>());
