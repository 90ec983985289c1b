//! What the Embree 3 backend ([`super::embree`]) and the Embree 4 backend
//! ([`super::embree4`]) share: the device error callback and its sink, the
//! checks a mesh must pass before Embree may read its buffers, and the probe
//! filter's body, which reads candidate hits out of Embree's
//! structure-of-arrays packets.
//!
//! None of it depends on the API version: the error codes 0–6, the
//! `RTCErrorFunction` signature and the `RTCRayN`/`RTCHitN` packet layout
//! (field k of lane i is the 4-byte word k·N + i; `tfar` is field 8 of the
//! ray, u, v, primID, geomID fields 3–6 of the hit) are the same in
//! `embree3/rtcore_ray.h` 3.13.5 and `embree4/rtcore_ray.h` 4.3/4.4.

use std::ffi::{c_char, c_int, c_void, CStr};
use std::sync::Mutex;

use super::{Hit, ProbeHits};
use crate::error::Error;
use crate::geometry::Mesh;

/// `RTCError` codes, as both APIs number them.
pub(crate) fn error_name(code: c_int) -> &'static str {
    match code {
        0 => "no error",
        1 => "unknown error",
        2 => "invalid argument",
        3 => "invalid operation",
        4 => "out of memory",
        5 => "unsupported CPU",
        6 => "cancelled",
        _ => "unrecognized error code",
    }
}

/// Errors Embree reported through the device's error callback, kept until
/// the next [`ErrorSink::take`].
#[derive(Default)]
pub(crate) struct ErrorSink {
    messages: Mutex<Vec<String>>,
}

/// At most this many messages are kept between checks (the first ones, which
/// name the cause; later ones are usually consequences).
const MAX_ERRORS: usize = 8;

/// RTC_ERROR_OUT_OF_MEMORY.
const OUT_OF_MEMORY: c_int = 4;

/// The error of an Embree call that failed with `code`: running out of
/// memory is a failure while working (exit 1, "out of memory: …"), any
/// other error the backend's refusal.
pub(crate) fn backend_error(message: String, code: c_int) -> Error {
    if code == OUT_OF_MEMORY {
        Error::Runtime(format!("out of memory: {message}"))
    } else {
        Error::Backend(message)
    }
}

impl ErrorSink {
    /// The messages reported since the last call, plus `code` (the device's
    /// own error code, read by the caller) if nothing was reported; an error
    /// naming `what` if there is anything.
    pub(crate) fn take(&self, code: c_int, what: &str) -> Result<(), Error> {
        let mut msgs =
            std::mem::take(&mut *self.messages.lock().unwrap_or_else(|e| e.into_inner()));
        if code != 0 && msgs.is_empty() {
            msgs.push(format!("Embree: {} ({code})", error_name(code)));
        }
        let out_of_memory = msgs.iter().any(|m| m.contains("out of memory"));
        match () {
            _ if msgs.is_empty() => Ok(()),
            _ => Err(backend_error(
                format!("{what}: {}", msgs.join("; ")),
                if out_of_memory { OUT_OF_MEMORY } else { code },
            )),
        }
    }
}

/// The device error callback (`RTCErrorFunction` of both APIs). A panic here
/// would abort the process (Rust does not unwind out of `extern "C"`), and
/// nothing here can panic: the lock ignores poisoning.
pub(crate) unsafe extern "C" fn on_device_error(
    user: *mut c_void,
    code: c_int,
    msg: *const c_char,
) {
    if user.is_null() {
        return;
    }
    // SAFETY: `user` is the `ErrorSink` boxed in the device that installed
    // this callback; the device uninstalls the callback before the box is
    // freed, so it is alive here. The sink is only accessed through `&`.
    let sink = unsafe { &*(user as *const ErrorSink) };
    let text = if msg.is_null() {
        String::new()
    } else {
        // SAFETY: Embree passes a NUL-terminated message valid for the call.
        unsafe { CStr::from_ptr(msg) }
            .to_string_lossy()
            .into_owned()
    };
    let mut m = sink.messages.lock().unwrap_or_else(|e| e.into_inner());
    if m.len() < MAX_ERRORS {
        m.push(format!("Embree: {} ({code}): {text}", error_name(code)));
    }
}

/// Checks that Embree can share every mesh's buffers safely: Embree reads
/// them without bounds checks, so an index out of range would be an
/// out-of-bounds read (`Mesh::new` checks only in debug builds).
pub(crate) fn check_shareable(meshes: &[Mesh]) -> Result<(), Error> {
    if meshes.len() >= u32::MAX as usize {
        return Err(Error::Backend(format!(
            "Embree: too many meshes ({})",
            meshes.len()
        )));
    }
    for (i, m) in meshes.iter().enumerate() {
        let nv = m.vertex_count();
        if nv > u32::MAX as usize || m.triangle_count() > u32::MAX as usize {
            return Err(Error::Backend(format!("Embree: mesh {i} is too large")));
        }
        if let Some(bad) = m.indices.iter().flatten().find(|&&v| v as usize >= nv) {
            return Err(Error::Backend(format!(
                "Embree: mesh {i} has vertex index {bad} but only {nv} vertices"
            )));
        }
        // Embree's 16-byte vertex loads need the padding element
        // (`Mesh::default()` has none, but also no vertices to index).
        if m.triangle_count() > 0 && m.padded_positions().len() <= nv {
            return Err(Error::Backend(format!(
                "Embree: mesh {i} lacks its padding vertex"
            )));
        }
    }
    Ok(())
}

// Indices of the SoA fields, as in `RTCRayN_*` / `RTCHitN_*` of
// `rtcore_ray.h` (Embree 3 and 4 alike).
const RAYN_TFAR: usize = 8;
const HITN_U: usize = 3;
const HITN_V: usize = 4;
const HITN_PRIM_ID: usize = 5;
const HITN_GEOM_ID: usize = 6;

/// The body of both backends' probe filters: for each active lane of a
/// packet of width `n`, records the candidate in `out` if it lies on mesh
/// `geom`, and rejects it (valid = 0) whatever its mesh, so traversal goes
/// on over the whole segment with `tfar` unchanged. During a filter call,
/// the ray's `tfar` holds the candidate's distance.
///
/// # Safety
/// `valid` must point to `n` ints and `ray`/`hit` to `RTCRayN`/`RTCHitN`
/// packets of width `n`, all valid for the call (what Embree passes a
/// filter in `RTCFilterFunctionNArguments`).
pub(crate) unsafe fn record_and_reject(
    valid: *mut c_int,
    ray: *const c_void,
    hit: *const c_void,
    n: u32,
    geom: u32,
    out: &mut ProbeHits,
) {
    let w = n as usize;
    let (rf, hf, hu) = (ray as *const f32, hit as *const f32, hit as *const u32);
    for i in 0..w {
        // SAFETY: per the caller's contract, `valid` has `n` entries and the
        // packets have at least 9 (ray) and 7 (hit) fields of `n` lanes.
        unsafe {
            let v = valid.add(i);
            if *v == 0 {
                continue; // inactive lane
            }
            let g = *hu.add(HITN_GEOM_ID * w + i);
            if g == geom {
                out.record(Hit {
                    t: *rf.add(RAYN_TFAR * w + i),
                    geom: g,
                    prim: *hu.add(HITN_PRIM_ID * w + i),
                    u: *hf.add(HITN_U * w + i),
                    v: *hf.add(HITN_V * w + i),
                });
            }
            *v = 0;
        }
    }
}
