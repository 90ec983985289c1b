//! The Embree 4 backend: [`Embree4Accel`] answers the [`Accel`] queries with
//! an Embree 4.3/4.4 library loaded at run time ([`load`]) through our own
//! bindings ([`ffi`]).
//!
//! It does what the Embree 3 backend ([`super::embree`]) does, in Embree 4's
//! API: the meshes' buffers are shared, geometry ids are mesh indices, the
//! scene is `ROBUST` (watertight triangle test) unless asked for
//! [`Traversal::Fast`], and MEDIUM quality (binned
//! SAH, no spatial splits, so a filter sees each triangle once per ray).
//! Embree 4 has no intersect context: [`Accel::hits_on_segment`] passes its
//! filter in the query's `RTCIntersectArguments`, with
//! `RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER`, on a scene built with
//! `RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS`. The filter records each
//! candidate on the wanted mesh and rejects every candidate, so one
//! traversal visits every hit of the segment, with the same 64-hit bound
//! and seeded subset ([`ProbeHits`]) as the other backends. The plain
//! queries pass no filter and so never call it.

#[doc(hidden)]
pub mod ffi;
pub mod load;

use std::ffi::{c_void, CString};
use std::marker::PhantomData;
use std::ptr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use super::embree_shared::{check_shareable, on_device_error, record_and_reject, ErrorSink};
use super::{valid_query, Accel, Hit, ProbeHits, RejectedRays, Traversal};
use crate::error::Error;
use crate::geometry::{Mesh, Ray, Vec3};
use load::Api;

static LIVE_DEVICES: AtomicUsize = AtomicUsize::new(0);
static LIVE_SCENES: AtomicUsize = AtomicUsize::new(0);

/// How many Embree 4 devices and scenes this process currently holds
/// (devices, scenes): the leak check of `tests/embree_lifetime.rs`.
#[doc(hidden)]
pub fn live_objects() -> (usize, usize) {
    (
        LIVE_DEVICES.load(Ordering::SeqCst),
        LIVE_SCENES.load(Ordering::SeqCst),
    )
}

/// The version of the loaded Embree 4 and where it came from, e.g.
/// "4.4.0 (libembree4.so.4)", or why there is none.
pub fn version() -> Result<String, Error> {
    let api = load::api()?;
    let (a, b, c) = api.version;
    Ok(format!("{a}.{b}.{c} ({})", api.path))
}

/// An owned `RTCDevice` of the loaded library, released on drop.
struct Device {
    api: &'static Api,
    raw: ffi::RTCDevice,
    // Boxed so its address, the callback's user pointer, stays put.
    errors: Box<ErrorSink>,
}

impl Device {
    /// A device whose builds use at most `threads` threads; `None`:
    /// Embree's default (all hardware threads).
    fn new(api: &'static Api, threads: Option<usize>) -> Result<Device, Error> {
        let config = match threads {
            Some(n) => format!("threads={}", n.max(1)),
            None => String::new(),
        };
        let config = CString::new(config).expect("no NUL");
        // SAFETY: `config` is a NUL-terminated string alive for the call.
        let raw = unsafe { (api.new_device)(config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: with a null device, the error of the failed call.
            let code = unsafe { (api.get_device_error)(ptr::null_mut()) };
            return Err(super::embree_shared::backend_error(
                format!(
                    "Embree 4: rtcNewDevice failed: {} ({code})",
                    super::embree_shared::error_name(code)
                ),
                code,
            ));
        }
        LIVE_DEVICES.fetch_add(1, Ordering::SeqCst);
        let dev = Device {
            api,
            raw,
            errors: Box::default(),
        };
        // SAFETY: `raw` is live; the user pointer is the boxed sink, which
        // outlives the registration (see `Drop`).
        unsafe {
            (api.set_device_error_function)(
                raw,
                Some(on_device_error),
                &*dev.errors as *const ErrorSink as *mut c_void,
            )
        };
        Ok(dev)
    }

    /// Fails with the errors reported since the last check, if any.
    fn check(&self, what: &str) -> Result<(), Error> {
        // SAFETY: `self.raw` is live. Reading the code also clears it.
        let code = unsafe { (self.api.get_device_error)(self.raw) };
        self.errors.take(code, what)
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: `self.raw` is a live device we own one reference to; the
        // callback is uninstalled first, as the sink is freed after this.
        unsafe {
            (self.api.set_device_error_function)(self.raw, None, ptr::null_mut());
            (self.api.release_device)(self.raw);
        }
        LIVE_DEVICES.fetch_sub(1, Ordering::SeqCst);
    }
}

/// An owned `RTCScene`, released on drop.
struct Scene {
    api: &'static Api,
    raw: ffi::RTCScene,
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: `self.raw` is a live scene we own one reference to.
        unsafe { (self.api.release_scene)(self.raw) };
        LIVE_SCENES.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The Embree 4 backend over a set of meshes (geometry id = mesh index).
pub struct Embree4Accel {
    // Field order is drop order: the scene before its device, both before
    // the meshes whose buffers Embree shares.
    scene: Scene,
    device: Device,
    meshes: Arc<Vec<Mesh>>,
    rejected: RejectedRays,
}

// SAFETY: as for the Embree 3 backend: after `build` commits the scene,
// `&self` methods only call rtcIntersect1/rtcOccluded1, thread-safe on a
// committed scene, each with its own stack-allocated ray and arguments; the
// shared buffers are immutable behind our `Arc`; the error sink is a Mutex;
// the `Api` is immutable and `'static`. Release needs `&mut self`.
unsafe impl Send for Embree4Accel {}
// SAFETY: see `Send` above.
unsafe impl Sync for Embree4Accel {}

/// `RTC_SCENE_FLAG_ROBUST` for a watertight traversal, else no flag.
fn robust_flag(traversal: Traversal) -> ffi::RTCSceneFlags {
    match traversal {
        Traversal::Watertight => ffi::RTC_SCENE_FLAG_ROBUST,
        Traversal::Fast => 0,
    }
}

impl Embree4Accel {
    /// Builds and commits an Embree 4 scene over `meshes`, sharing their
    /// buffers (inside a rayon pool, with that many build threads). Fails
    /// with [`Error::Unavailable`] if no usable Embree 4 is loaded, and
    /// without leaking if Embree reports an error or a mesh cannot be
    /// shared safely.
    pub fn build(meshes: &Arc<Vec<Mesh>>) -> Result<Embree4Accel, Error> {
        Self::build_with(meshes, Traversal::Watertight)
    }

    /// [`build`](Self::build) with the given [`Traversal`]: `ROBUST` for
    /// `Watertight`, Embree's default arithmetic for `Fast`.
    pub fn build_with(
        meshes: &Arc<Vec<Mesh>>,
        traversal: Traversal,
    ) -> Result<Embree4Accel, Error> {
        let api = load::api()?;
        check_shareable(meshes)?;
        let threads = rayon::current_thread_index().map(|_| rayon::current_num_threads());
        let device = Device::new(api, threads)?;
        device.check("Embree 4 device")?;

        // SAFETY: `device.raw` is live.
        let raw = unsafe { (api.new_scene)(device.raw) };
        if raw.is_null() {
            return Err(device
                .check("rtcNewScene")
                .err()
                .unwrap_or_else(|| Error::Backend("rtcNewScene returned null".into())));
        }
        LIVE_SCENES.fetch_add(1, Ordering::SeqCst);
        let scene = Scene { api, raw };
        // SAFETY: `scene.raw` is a live, uncommitted scene.
        unsafe {
            (api.set_scene_flags)(
                scene.raw,
                robust_flag(traversal) | ffi::RTC_SCENE_FLAG_FILTER_FUNCTION_IN_ARGUMENTS,
            );
            (api.set_scene_build_quality)(scene.raw, ffi::RTC_BUILD_QUALITY_MEDIUM);
        }
        for (i, m) in meshes.iter().enumerate() {
            if m.triangle_count() == 0 {
                continue; // nothing to hit; later ids are unaffected
            }
            // SAFETY: `device.raw` is live.
            let geom = unsafe { (api.new_geometry)(device.raw, ffi::RTC_GEOMETRY_TYPE_TRIANGLE) };
            if geom.is_null() {
                return Err(device
                    .check("rtcNewGeometry")
                    .err()
                    .unwrap_or_else(|| Error::Backend("rtcNewGeometry returned null".into())));
            }
            // SAFETY: as in the Embree 3 backend: tightly packed f32 triples
            // plus the padding vertex (16-byte loads stay in bounds), u32
            // index triples all in range (checked), owned by the `Arc` we
            // keep until after the scene is released, never mutated. The
            // scene holds its own geometry reference after attaching.
            unsafe {
                (api.set_shared_geometry_buffer)(
                    geom,
                    ffi::RTC_BUFFER_TYPE_VERTEX,
                    0,
                    ffi::RTC_FORMAT_FLOAT3,
                    m.padded_positions().as_ptr() as *const c_void,
                    0,
                    std::mem::size_of::<Vec3>(),
                    m.vertex_count(),
                );
                (api.set_shared_geometry_buffer)(
                    geom,
                    ffi::RTC_BUFFER_TYPE_INDEX,
                    0,
                    ffi::RTC_FORMAT_UINT3,
                    m.indices.as_ptr() as *const c_void,
                    0,
                    std::mem::size_of::<[u32; 3]>(),
                    m.triangle_count(),
                );
                (api.commit_geometry)(geom);
                (api.attach_geometry_by_id)(scene.raw, geom, i as u32);
                (api.release_geometry)(geom);
            }
            device.check(&format!("Embree 4 geometry {i}"))?;
        }
        // SAFETY: `scene.raw` is live and every attached geometry committed.
        unsafe { (api.commit_scene)(scene.raw) };
        device.check("Embree 4 scene commit")?;
        Ok(Embree4Accel {
            scene,
            device,
            meshes: Arc::clone(meshes),
            rejected: RejectedRays::default(),
        })
    }

    /// The meshes this scene was built over.
    pub fn meshes(&self) -> &Arc<Vec<Mesh>> {
        &self.meshes
    }

    /// Errors Embree reported after the build (diagnostics only).
    pub fn check_errors(&self) -> Result<(), Error> {
        self.device.check("Embree 4")
    }

    /// Runs `rtcIntersect1` on a ray/hit record of our own (for the layout
    /// test, which fills it with a sentinel and reads which bytes the
    /// library wrote).
    #[doc(hidden)]
    pub fn intersect_raw(&self, rh: &mut ffi::RTCRayHit) {
        let mut args = ffi::RTCIntersectArguments::new();
        // SAFETY: committed scene; `rh` and `args` valid for the call.
        unsafe { (self.scene.api.intersect1)(self.scene.raw, rh, &mut args) };
    }
}

fn make_ray(ray: &Ray, tnear: f32, tfar: f32) -> ffi::RTCRay {
    ffi::RTCRay {
        org_x: ray.o.x,
        org_y: ray.o.y,
        org_z: ray.o.z,
        tnear,
        dir_x: ray.d.x,
        dir_y: ray.d.y,
        dir_z: ray.d.z,
        time: 0.0,
        tfar,
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

fn make_rayhit(ray: &Ray, tnear: f32, tfar: f32) -> ffi::RTCRayHit {
    const NONE: [u32; ffi::RTC_MAX_INSTANCE_LEVEL_COUNT] =
        [ffi::RTC_INVALID_GEOMETRY_ID; ffi::RTC_MAX_INSTANCE_LEVEL_COUNT];
    ffi::RTCRayHit {
        ray: make_ray(ray, tnear, tfar),
        hit: ffi::RTCHit {
            ng_x: 0.0,
            ng_y: 0.0,
            ng_z: 0.0,
            u: 0.0,
            v: 0.0,
            prim_id: ffi::RTC_INVALID_GEOMETRY_ID,
            geom_id: ffi::RTC_INVALID_GEOMETRY_ID,
            inst_id: NONE,
            inst_prim_id: NONE,
        },
    }
}

/// The ray query context of a probe query: Embree hands the filter a
/// pointer to the `RTCRayQueryContext` we passed in the arguments, the
/// first field here (`repr(C)`), so the filter can cast it back.
#[repr(C)]
struct ProbeContext<'a> {
    ctx: ffi::RTCRayQueryContext,
    out: *mut ProbeHits,
    geom: u32,
    _out: PhantomData<&'a mut ProbeHits>,
}

/// The argument filter of [`Accel::hits_on_segment`].
unsafe extern "C" fn probe_filter(args: *const ffi::RTCFilterFunctionNArguments) {
    // SAFETY: Embree passes valid arguments for the duration of the call.
    let args = unsafe { &*args };
    // SAFETY: this filter is only passed with a `ProbeContext`'s context,
    // its first field (same address), alive on `hits_on_segment`'s stack
    // for the whole traversal.
    let pc = unsafe { &*(args.context as *const ProbeContext) };
    // SAFETY: `pc.out` is the `&mut ProbeHits` that `hits_on_segment` holds
    // and does not touch during the synchronous traversal.
    let out = unsafe { &mut *pc.out };
    // SAFETY: `valid`, ray and hit are packets of width `n`.
    unsafe {
        record_and_reject(
            args.valid,
            args.ray as *const c_void,
            args.hit as *const c_void,
            args.n,
            pc.geom,
            out,
        )
    };
}

impl Accel for Embree4Accel {
    fn name(&self) -> &'static str {
        "embree4"
    }

    fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        if !valid_query(ray, tmin, tmax) {
            self.rejected.count();
            return None;
        }
        let mut rh = make_rayhit(ray, tmin, tmax);
        let mut args = ffi::RTCIntersectArguments::new();
        // SAFETY: committed scene (thread-safe queries); `rh` and `args` are
        // valid, aligned and live for the call.
        unsafe { (self.scene.api.intersect1)(self.scene.raw, &mut rh, &mut args) };
        (rh.hit.geom_id != ffi::RTC_INVALID_GEOMETRY_ID).then_some(Hit {
            t: rh.ray.tfar,
            geom: rh.hit.geom_id,
            prim: rh.hit.prim_id,
            u: rh.hit.u,
            v: rh.hit.v,
        })
    }

    fn occluded(&self, ray: &Ray, tmin: f32, tmax: f32) -> bool {
        if !valid_query(ray, tmin, tmax) {
            self.rejected.count();
            return false;
        }
        let mut r = make_ray(ray, tmin, tmax);
        let mut args = ffi::RTCOccludedArguments::new();
        // SAFETY: as in `intersect`.
        unsafe { (self.scene.api.occluded1)(self.scene.raw, &mut r, &mut args) };
        // Embree marks an occluded ray by setting tfar to -inf.
        r.tfar == f32::NEG_INFINITY
    }

    fn hits_on_segment(&self, ray: &Ray, tmax: f32, geom: u32, seed: u32, out: &mut ProbeHits) {
        out.reset(seed);
        if !valid_query(ray, 0.0, tmax) {
            self.rejected.count();
            out.finish();
            return;
        }
        let mut pc = ProbeContext {
            ctx: ffi::RTCRayQueryContext::new(),
            out: out as *mut ProbeHits,
            geom,
            _out: PhantomData,
        };
        let mut args = ffi::RTCIntersectArguments {
            flags: ffi::RTC_RAY_QUERY_FLAG_INCOHERENT
                | ffi::RTC_RAY_QUERY_FLAG_INVOKE_ARGUMENT_FILTER,
            // A pointer to the whole `pc`, so the filter may read the fields
            // after the context through it.
            context: (&mut pc as *mut ProbeContext).cast::<ffi::RTCRayQueryContext>(),
            filter: Some(probe_filter),
            ..ffi::RTCIntersectArguments::new()
        };
        let mut rh = make_rayhit(ray, 0.0, tmax);
        // SAFETY: as in `intersect`; the scene has
        // FILTER_FUNCTION_IN_ARGUMENTS and the flags invoke the filter on
        // every geometry, with `args.context`, the start of `pc`. `out` is
        // not used until the call returns.
        unsafe { (self.scene.api.intersect1)(self.scene.raw, &mut rh, &mut args) };
        out.finish();
    }

    fn rejected_rays(&self) -> u64 {
        self.rejected.get()
    }
    fn traversal(&self) -> Traversal {
        // SAFETY: `self.scene.raw` is a live, committed scene of `api`.
        let flags = unsafe { (self.scene.api.get_scene_flags)(self.scene.raw) };
        if flags & ffi::RTC_SCENE_FLAG_ROBUST != 0 {
            Traversal::Watertight
        } else {
            Traversal::Fast
        }
    }
}
