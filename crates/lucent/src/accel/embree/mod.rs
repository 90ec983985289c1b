//! The Embree 3 backend: [`EmbreeAccel`] answers the [`Accel`] queries with
//! Intel's Embree through our own minimal bindings ([`ffi`]).
//!
//! Embree shares the meshes' vertex and index buffers instead of copying
//! them (hence the padding vertex in [`Mesh`]); geometry ids are the mesh
//! indices, so hits need no translation. The scene is built `ROBUST` (a
//! watertight triangle test, so probe rays do not slip through shared edges)
//! unless asked for [`Traversal::Fast`], and always with
//! `CONTEXT_FILTER_FUNCTION`, which lets [`Accel::hits_on_segment`]
//! gather every hit of a segment in one traversal: a filter records each
//! candidate and rejects it, so the ray's interval never shrinks.

#[doc(hidden)]
pub mod ffi;

use std::ffi::{c_void, CString};
use std::marker::PhantomData;
use std::ptr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

use super::embree_shared::{
    check_shareable, error_name, on_device_error, record_and_reject, ErrorSink,
};
use super::{valid_query, Accel, Hit, ProbeHits, RejectedRays, Traversal};
use crate::error::Error;
use crate::geometry::{Mesh, Ray, Vec3};

static LIVE_DEVICES: AtomicUsize = AtomicUsize::new(0);
static LIVE_SCENES: AtomicUsize = AtomicUsize::new(0);

/// How many Embree devices and scenes this process currently holds
/// (devices, scenes): the leak check of `tests/embree_lifetime.rs`.
#[doc(hidden)]
pub fn live_objects() -> (usize, usize) {
    (
        LIVE_DEVICES.load(Ordering::SeqCst),
        LIVE_SCENES.load(Ordering::SeqCst),
    )
}

/// The version of the Embree library lucent runs against, e.g. "3.13.5"
/// (asked from the library, not the headers we compiled with).
pub fn version() -> String {
    static VERSION: OnceLock<String> = OnceLock::new();
    VERSION
        .get_or_init(|| match Device::new(Some(1)) {
            Ok(d) => {
                let p = |prop| d.property(prop);
                format!(
                    "{}.{}.{}",
                    p(ffi::RTC_DEVICE_PROPERTY_VERSION_MAJOR),
                    p(ffi::RTC_DEVICE_PROPERTY_VERSION_MINOR),
                    p(ffi::RTC_DEVICE_PROPERTY_VERSION_PATCH)
                )
            }
            Err(e) => format!("unavailable ({e})"),
        })
        .clone()
}

/// An owned `RTCDevice`, released on drop.
struct Device {
    raw: ffi::RTCDevice,
    // Boxed so its address, handed to Embree as the callback's user pointer,
    // stays put when the `Device` moves.
    errors: Box<ErrorSink>,
}

impl Device {
    /// A device whose builds use at most `threads` threads (Embree's own
    /// TBB pool, which does not know about rayon); `None`: Embree's
    /// default, all hardware threads.
    fn new(threads: Option<usize>) -> Result<Device, Error> {
        let config = match threads {
            Some(n) => format!("threads={}", n.max(1)),
            None => String::new(),
        };
        let config = CString::new(config).expect("no NUL");
        // SAFETY: `config` is a NUL-terminated string alive for the call.
        let raw = unsafe { ffi::rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: with a null device, rtcGetDeviceError returns the error
            // of the failed rtcNewDevice on this thread.
            let code = unsafe { ffi::rtcGetDeviceError(ptr::null_mut()) };
            return Err(super::embree_shared::backend_error(
                format!("Embree: rtcNewDevice failed: {} ({code})", error_name(code)),
                code,
            ));
        }
        LIVE_DEVICES.fetch_add(1, Ordering::SeqCst);
        let dev = Device {
            raw,
            errors: Box::default(),
        };
        // SAFETY: `raw` is a live device; the user pointer is the boxed sink,
        // which outlives the callback registration (see `Drop`).
        unsafe {
            ffi::rtcSetDeviceErrorFunction(
                raw,
                Some(on_device_error),
                &*dev.errors as *const ErrorSink as *mut c_void,
            )
        };
        Ok(dev)
    }

    fn property(&self, prop: ffi::RTCDeviceProperty) -> isize {
        // SAFETY: `self.raw` is a live device; unknown properties only set an
        // error code.
        unsafe { ffi::rtcGetDeviceProperty(self.raw, prop) }
    }

    /// Fails with the errors reported since the last check, if any; `what`
    /// names the step for the message.
    fn check(&self, what: &str) -> Result<(), Error> {
        // SAFETY: `self.raw` is a live device. Reading the code also clears it.
        let code = unsafe { ffi::rtcGetDeviceError(self.raw) };
        self.errors.take(code, what)
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: `self.raw` is a live device we own one reference to.
        // Embree keeps the device alive while scenes reference it, so
        // uninstall the callback first: after this the sink may be freed.
        unsafe {
            ffi::rtcSetDeviceErrorFunction(self.raw, None, ptr::null_mut());
            ffi::rtcReleaseDevice(self.raw);
        }
        LIVE_DEVICES.fetch_sub(1, Ordering::SeqCst);
    }
}

/// An owned `RTCScene`, released on drop.
struct Scene {
    raw: ffi::RTCScene,
}

impl Drop for Scene {
    fn drop(&mut self) {
        // SAFETY: `self.raw` is a live scene we own one reference to.
        unsafe { ffi::rtcReleaseScene(self.raw) };
        LIVE_SCENES.fetch_sub(1, Ordering::SeqCst);
    }
}

/// The Embree backend over a set of meshes (geometry id = mesh index).
pub struct EmbreeAccel {
    // Field order is drop order: the scene goes before the device it was
    // created on, and both before the meshes whose buffers Embree shares.
    scene: Scene,
    device: Device,
    meshes: Arc<Vec<Mesh>>,
    /// Queries refused by [`valid_query`] before they reached Embree
    /// (whose `ray.valid()` assertion would abort the process).
    rejected: RejectedRays,
}

// SAFETY: after `build` commits the scene, nothing modifies it: `&self`
// methods only call rtcIntersect1/rtcOccluded1, which Embree documents as
// thread-safe on a committed scene, each with its own stack-allocated
// context and ray. The shared buffers belong to the `Arc<Vec<Mesh>>` we hold,
// which is immutable through a shared reference. The error sink is a Mutex.
// Dropping (rtcRelease*) needs `&mut self`, so it never races a query, and
// Embree objects may be released from any thread.
unsafe impl Send for EmbreeAccel {}
// SAFETY: see `Send` above.
unsafe impl Sync for EmbreeAccel {}

/// `RTC_SCENE_FLAG_ROBUST` for a watertight traversal, else no flag.
fn robust_flag(traversal: Traversal) -> ffi::RTCSceneFlags {
    match traversal {
        Traversal::Watertight => ffi::RTC_SCENE_FLAG_ROBUST,
        Traversal::Fast => ffi::RTC_SCENE_FLAG_NONE,
    }
}

impl EmbreeAccel {
    /// Builds and commits an Embree scene over `meshes`, sharing their
    /// buffers; called inside a rayon pool, the build uses that many
    /// threads. Fails (without leaking) if Embree reports any error or if a
    /// mesh cannot be shared safely (index out of range, too many elements).
    pub fn build(meshes: &Arc<Vec<Mesh>>) -> Result<EmbreeAccel, Error> {
        Self::build_with(meshes, Traversal::Watertight)
    }

    /// [`build`](Self::build) with the given [`Traversal`]: `ROBUST` for
    /// `Watertight`, Embree's default arithmetic for `Fast`.
    pub fn build_with(meshes: &Arc<Vec<Mesh>>, traversal: Traversal) -> Result<EmbreeAccel, Error> {
        check_shareable(meshes)?;

        // Inside a rayon pool, build with as many threads as it has (so a
        // one-thread pool means a one-thread build, as for our BVH). Outside
        // any pool, Embree's default (all cores): asking rayon there would
        // start its global pool as a side effect.
        let threads = rayon::current_thread_index().map(|_| rayon::current_num_threads());
        let device = Device::new(threads)?;
        if device.property(ffi::RTC_DEVICE_PROPERTY_TRIANGLE_GEOMETRY_SUPPORTED) == 0
            || device.property(ffi::RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) == 0
        {
            return Err(Error::Backend(
                "Embree: this library was built without triangle or filter-function support".into(),
            ));
        }
        device.check("Embree device")?;

        // SAFETY: `device.raw` is a live device.
        let raw = unsafe { ffi::rtcNewScene(device.raw) };
        if raw.is_null() {
            return Err(device
                .check("rtcNewScene")
                .err()
                .unwrap_or_else(|| Error::Backend("rtcNewScene returned null".into())));
        }
        LIVE_SCENES.fetch_add(1, Ordering::SeqCst);
        let scene = Scene { raw };
        // SAFETY: `scene.raw` is a live, uncommitted scene. MEDIUM quality is
        // Embree's binned SAH builder; HIGH adds spatial splits, which put a
        // triangle in several leaves and make filters run more than once per
        // hit (ProbeHits dedupes, but it would cost time).
        unsafe {
            ffi::rtcSetSceneFlags(
                scene.raw,
                robust_flag(traversal) | ffi::RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION,
            );
            ffi::rtcSetSceneBuildQuality(scene.raw, ffi::RTC_BUILD_QUALITY_MEDIUM);
        }

        for (i, m) in meshes.iter().enumerate() {
            if m.triangle_count() == 0 {
                // Nothing to hit; ids of later meshes are unaffected because
                // we attach by id.
                continue;
            }
            // SAFETY: `device.raw` is live.
            let geom = unsafe { ffi::rtcNewGeometry(device.raw, ffi::RTC_GEOMETRY_TYPE_TRIANGLE) };
            if geom.is_null() {
                return Err(device
                    .check("rtcNewGeometry")
                    .err()
                    .unwrap_or_else(|| Error::Backend("rtcNewGeometry returned null".into())));
            }
            // SAFETY: `geom` is a live geometry. The vertex buffer is
            // `vertex_count` tightly packed 12-byte f32 triples followed by
            // one more element, so Embree's 16-byte loads of the last vertex
            // stay in bounds; the index buffer is `triangle_count` u32
            // triples, all in range (checked above). Both are owned by the
            // `Arc` that `EmbreeAccel` keeps until after the scene is
            // released, and are never mutated through it. We release our
            // geometry reference right after attaching: the scene holds its
            // own.
            unsafe {
                ffi::rtcSetSharedGeometryBuffer(
                    geom,
                    ffi::RTC_BUFFER_TYPE_VERTEX,
                    0,
                    ffi::RTC_FORMAT_FLOAT3,
                    m.padded_positions().as_ptr() as *const c_void,
                    0,
                    std::mem::size_of::<Vec3>(),
                    m.vertex_count(),
                );
                ffi::rtcSetSharedGeometryBuffer(
                    geom,
                    ffi::RTC_BUFFER_TYPE_INDEX,
                    0,
                    ffi::RTC_FORMAT_UINT3,
                    m.indices.as_ptr() as *const c_void,
                    0,
                    std::mem::size_of::<[u32; 3]>(),
                    m.triangle_count(),
                );
                ffi::rtcCommitGeometry(geom);
                ffi::rtcAttachGeometryByID(scene.raw, geom, i as u32);
                ffi::rtcReleaseGeometry(geom);
            }
            device.check(&format!("Embree geometry {i}"))?;
        }

        // SAFETY: `scene.raw` is live and every attached geometry committed.
        unsafe { ffi::rtcCommitScene(scene.raw) };
        device.check("Embree scene commit")?;

        Ok(EmbreeAccel {
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

    /// Errors Embree reported after the build (queries do not report
    /// errors, so this is only for diagnostics).
    pub fn check_errors(&self) -> Result<(), Error> {
        self.device.check("Embree")
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
            inst_id: [ffi::RTC_INVALID_GEOMETRY_ID; ffi::RTC_MAX_INSTANCE_LEVEL_COUNT],
        },
    }
}

/// The context of a probe query. Embree hands the filter a pointer to the
/// `RTCIntersectContext` we passed, which is the first field here (and
/// `repr(C)`), so the filter can cast it back to reach the rest.
#[repr(C)]
struct ProbeContext<'a> {
    ctx: ffi::RTCIntersectContext,
    out: *mut ProbeHits,
    geom: u32,
    _out: PhantomData<&'a mut ProbeHits>,
}

/// The filter of [`Accel::hits_on_segment`]: records candidates on the
/// wanted mesh and rejects every candidate, so traversal goes on over the
/// whole segment with `tfar` unchanged.
unsafe extern "C" fn probe_filter(args: *const ffi::RTCFilterFunctionNArguments) {
    // SAFETY: Embree passes valid arguments for the duration of the call.
    let args = unsafe { &*args };
    // SAFETY: this filter is only installed in a `ProbeContext`, whose first
    // field is the context Embree passes back (repr(C): same address); the
    // context lives on `hits_on_segment`'s stack for the whole traversal.
    let pc = unsafe { &*(args.context as *const ProbeContext) };
    // SAFETY: `pc.out` comes from the `&mut ProbeHits` that
    // `hits_on_segment` holds and does not touch during the traversal, and
    // the filter runs synchronously on the calling thread, so this is the
    // only live reference.
    let out = unsafe { &mut *pc.out };
    // SAFETY: Embree passes `valid`, ray and hit packets of width `n` (for
    // rtcIntersect1, n = 1 and they are a plain RTCRayHit).
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

impl Accel for EmbreeAccel {
    fn name(&self) -> &'static str {
        "embree3"
    }

    fn intersect(&self, ray: &Ray, tmin: f32, tmax: f32) -> Option<Hit> {
        if !valid_query(ray, tmin, tmax) {
            self.rejected.count();
            return None;
        }
        let mut ctx = ffi::RTCIntersectContext::new();
        let mut rh = make_rayhit(ray, tmin, tmax);
        // SAFETY: the scene is committed (thread-safe queries); ctx and rh
        // are valid, properly aligned, and live for the call.
        unsafe { ffi::rtcIntersect1(self.scene.raw, &mut ctx, &mut rh) };
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
        let mut ctx = ffi::RTCIntersectContext::new();
        let mut r = make_ray(ray, tmin, tmax);
        // SAFETY: as in `intersect`.
        unsafe { ffi::rtcOccluded1(self.scene.raw, &mut ctx, &mut r) };
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
            ctx: ffi::RTCIntersectContext {
                filter: Some(probe_filter),
                ..ffi::RTCIntersectContext::new()
            },
            out: out as *mut ProbeHits,
            geom,
            _out: PhantomData,
        };
        let mut rh = make_rayhit(ray, 0.0, tmax);
        // A pointer to the whole `pc` (not just `pc.ctx`), so the filter may
        // read the fields after the context through it.
        let ctx = (&mut pc as *mut ProbeContext).cast::<ffi::RTCIntersectContext>();
        // SAFETY: as in `intersect`; the scene has CONTEXT_FILTER_FUNCTION so
        // Embree calls `probe_filter` with `ctx`, the start of `pc` (see
        // `probe_filter`). `out` is not used until the call returns.
        unsafe { ffi::rtcIntersect1(self.scene.raw, ctx, &mut rh) };
        out.finish();
    }

    fn rejected_rays(&self) -> u64 {
        self.rejected.get()
    }
    fn traversal(&self) -> Traversal {
        // SAFETY: `self.scene.raw` is a live, committed scene.
        let flags = unsafe { ffi::rtcGetSceneFlags(self.scene.raw) };
        if flags & ffi::RTC_SCENE_FLAG_ROBUST != 0 {
            Traversal::Watertight
        } else {
            Traversal::Fast
        }
    }
}
