//! One run of OIDN's `RT` filter over a float RGB beauty with albedo and
//! normal guides: a CPU device with the thread count asked for, the images
//! shared with OIDN in place (`float3`, 12-byte pixels, rows top first,
//! strides given explicitly), `hdr` on, and the guides either prefiltered
//! by OIDN's own filter (`cleanAux`) or passed as they are
//! (docs/output.md, "Denoising").

use std::ffi::{c_void, CString};

use super::ffi::*;
use super::load::{api, last_error, Api};
use crate::error::Error;
use crate::geometry::Vec3;

// OIDN reads `float3` pixels of 12 bytes: glam's Vec3 is three packed f32.
const _: () = assert!(std::mem::size_of::<Vec3>() == 12 && std::mem::align_of::<Vec3>() == 4);

/// The images a denoise reads: row-major, top row first, `width × height`
/// pixels each.
#[derive(Clone, Copy, Debug)]
pub struct DenoiseInput<'a> {
    pub width: u32,
    pub height: u32,
    /// Linear radiance (HDR).
    pub color: &'a [Vec3],
    /// Albedo of the first non-specular hit, in [0, 1].
    pub albedo: &'a [Vec3],
    /// Shading normal of that hit, components in [-1, 1] (any space).
    pub normal: &'a [Vec3],
}

/// How a denoise runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DenoiseOptions {
    /// OIDN's worker threads (None: all cores).
    pub threads: Option<usize>,
    /// Denoise the guides first and tell OIDN they are clean (`cleanAux`);
    /// otherwise OIDN takes them as noisy.
    pub prefilter_guides: bool,
    /// Denoise each light layer (light paths, light groups) too, with the
    /// beauty's guides (`--denoise-layers`).
    pub layers: bool,
    /// OIDN's `maxMemoryMB`: about this much scratch memory per filter,
    /// which OIDN keeps by denoising the image in overlapping tiles (None:
    /// OIDN's own choice).
    pub max_memory_mb: Option<u32>,
}

impl DenoiseOptions {
    /// How the commands denoise: on `threads` threads, the guides
    /// prefiltered (measured best on lucent's guides: docs/accuracy.md,
    /// "Denoising").
    pub fn with_threads(threads: Option<usize>) -> Self {
        DenoiseOptions {
            threads,
            prefilter_guides: true,
            layers: false,
            max_memory_mb: None,
        }
    }
}

/// The denoised beauty: non-negative and finite (OIDN's rare negative or
/// non-finite outputs become 0).
pub fn denoise(input: &DenoiseInput, opts: &DenoiseOptions) -> Result<Vec<Vec3>, Error> {
    let mut out = denoise_with(input, &[], opts)?;
    Ok(out.swap_remove(0))
}

/// The beauty and each image of `more` (the frame's light layers, of its
/// size) denoised with the same guides, prefiltered once: the beauty
/// first, then `more` in order; each non-negative and finite.
pub fn denoise_with(
    input: &DenoiseInput,
    more: &[&[Vec3]],
    opts: &DenoiseOptions,
) -> Result<Vec<Vec<Vec3>>, Error> {
    check(input)?;
    for (i, img) in more.iter().enumerate() {
        check_image(&format!("light layer {i}"), img, input)?;
    }
    let api = api()?;
    let device = Device::new(api, opts.threads)?;
    let (mut albedo, mut normal) = (input.albedo.to_vec(), input.normal.to_vec());
    let size = (input.width as usize, input.height as usize);
    if opts.prefilter_guides {
        for (name, guide) in [("albedo", &mut albedo), ("normal", &mut normal)] {
            let f = device.filter_capped(opts.max_memory_mb)?;
            let p = guide.as_mut_ptr().cast::<c_void>();
            f.image(name, p, size);
            f.image("output", p, size);
            device.run(&f, "prefiltering a guide")?;
        }
    }
    let mut outs = Vec::with_capacity(1 + more.len());
    for color in std::iter::once(input.color).chain(more.iter().copied()) {
        let mut out = vec![Vec3::ZERO; color.len()];
        let f = device.filter_capped(opts.max_memory_mb)?;
        f.image("color", color.as_ptr().cast_mut().cast(), size);
        f.image("albedo", albedo.as_mut_ptr().cast(), size);
        f.image("normal", normal.as_mut_ptr().cast(), size);
        f.image("output", out.as_mut_ptr().cast(), size);
        f.flag("hdr", true);
        f.flag("cleanAux", opts.prefilter_guides);
        device.run(&f, "denoising")?;
        drop(f);
        for p in &mut out {
            *p = sanitized(*p);
        }
        outs.push(out);
    }
    Ok(outs)
}

/// A pixel of OIDN's output made non-negative and finite: a negative or
/// non-finite channel becomes 0 (light values in outputs never are).
fn sanitized(p: Vec3) -> Vec3 {
    p.to_array()
        .map(|c| if c.is_finite() { c.max(0.0) } else { 0.0 })
        .into()
}

/// Sizes that agree and finite inputs: OIDN would read out of bounds on
/// the one and spread NaN over a neighbourhood on the other.
fn check(input: &DenoiseInput) -> Result<(), Error> {
    let n = input.width as usize * input.height as usize;
    if n == 0 {
        return Err(Error::Input("cannot denoise an empty image".into()));
    }
    for (name, img) in [
        ("beauty", input.color),
        ("albedo", input.albedo),
        ("normal", input.normal),
    ] {
        check_image(name, img, input)?;
    }
    Ok(())
}

/// One image of the frame's size, finite.
fn check_image(name: &str, img: &[Vec3], input: &DenoiseInput) -> Result<(), Error> {
    let n = input.width as usize * input.height as usize;
    if img.len() != n {
        return Err(Error::Input(format!(
            "the {name} has {} pixels, not the {}×{} = {n} of the frame",
            img.len(),
            input.width,
            input.height
        )));
    }
    if let Some(i) = img.iter().position(|p| !p.is_finite()) {
        let (x, y) = (i % input.width as usize, i / input.width as usize);
        return Err(Error::Input(format!(
            "the {name} is not finite at pixel ({x}, {y}): {}",
            img[i]
        )));
    }
    Ok(())
}

/// An OIDN CPU device, committed, released on drop.
struct Device {
    api: &'static Api,
    raw: OIDNDevice,
}

impl Device {
    fn new(api: &'static Api, threads: Option<usize>) -> Result<Device, Error> {
        // SAFETY: creating a device has no preconditions.
        let raw = unsafe { (api.new_device)(OIDN_DEVICE_TYPE_CPU) };
        if raw.is_null() {
            let (code, msg) = last_error(api, raw);
            return Err(failure("creating a CPU device", code, &msg));
        }
        let d = Device { api, raw };
        if let Some(n) = threads {
            let key = CString::new("numThreads").expect("no NUL");
            let n = i32::try_from(n).unwrap_or(i32::MAX);
            // SAFETY: a live, uncommitted device; a NUL-terminated name.
            unsafe { (api.set_device_int)(raw, key.as_ptr(), n) };
        }
        // SAFETY: a live device.
        unsafe { (api.commit_device)(raw) };
        d.check("setting up the device")?;
        Ok(d)
    }

    /// The error OIDN stored during `what`, if any.
    fn check(&self, what: &str) -> Result<(), Error> {
        match last_error(self.api, self.raw) {
            (OIDN_ERROR_NONE, _) => Ok(()),
            (code, msg) => Err(failure(what, code, &msg)),
        }
    }

    /// A new `RT` filter on this device, its scratch memory capped at
    /// `max_memory_mb` when that is given.
    fn filter_capped(&self, max_memory_mb: Option<u32>) -> Result<Filter<'_>, Error> {
        let f = self.filter()?;
        if let Some(mb) = max_memory_mb {
            f.int("maxMemoryMB", i32::try_from(mb).unwrap_or(i32::MAX));
        }
        Ok(f)
    }

    /// A new `RT` filter on this device.
    fn filter(&self) -> Result<Filter<'_>, Error> {
        let ty = CString::new("RT").expect("no NUL");
        // SAFETY: a live, committed device; a NUL-terminated type name.
        let raw = unsafe { (self.api.new_filter)(self.raw, ty.as_ptr()) };
        self.check("creating the RT filter")?;
        if raw.is_null() {
            return Err(Error::Runtime("OIDN gave no RT filter".into()));
        }
        Ok(Filter { device: self, raw })
    }

    /// Commits and executes `f` (synchronously), checking for errors.
    fn run(&self, f: &Filter, what: &str) -> Result<(), Error> {
        // SAFETY: a live filter whose images point at buffers the caller
        // keeps alive and unaliased until this returns.
        unsafe { (self.api.commit_filter)(f.raw) };
        self.check(what)?;
        // SAFETY: as above; oidnExecuteFilter returns when it is done.
        unsafe { (self.api.execute_filter)(f.raw) };
        self.check(what)
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: we own the one reference; every filter borrows `self` and
        // so was released first.
        unsafe { (self.api.release_device)(self.raw) };
    }
}

/// An OIDN filter, released on drop.
struct Filter<'d> {
    device: &'d Device,
    raw: OIDNFilter,
}

impl Filter<'_> {
    /// Shares the `float3` image at `ptr` (`size.0 × size.1` pixels, rows
    /// packed) as the filter's image `name`.
    fn image(&self, name: &str, ptr: *mut c_void, size: (usize, usize)) {
        let key = CString::new(name).expect("no NUL");
        let pixel = std::mem::size_of::<Vec3>();
        // SAFETY: `ptr` points at `size.0 * size.1` Vec3s that the caller
        // keeps alive until the filter has run (checked lengths); OIDN only
        // records the pointer here.
        unsafe {
            (self.device.api.set_shared_filter_image)(
                self.raw,
                key.as_ptr(),
                ptr,
                OIDN_FORMAT_FLOAT3,
                size.0,
                size.1,
                0,
                pixel,
                pixel * size.0,
            )
        };
    }

    fn flag(&self, name: &str, on: bool) {
        let key = CString::new(name).expect("no NUL");
        // SAFETY: a live filter; a NUL-terminated name.
        unsafe { (self.device.api.set_filter_bool)(self.raw, key.as_ptr(), on) };
    }

    fn int(&self, name: &str, v: i32) {
        let key = CString::new(name).expect("no NUL");
        // SAFETY: a live filter; a NUL-terminated name.
        unsafe { (self.device.api.set_filter_int)(self.raw, key.as_ptr(), v) };
    }
}

impl Drop for Filter<'_> {
    fn drop(&mut self) {
        // SAFETY: we own the one reference to this filter.
        unsafe { (self.device.api.release_filter)(self.raw) };
    }
}

/// An OIDN failure: out of memory and unsupported hardware are named.
fn failure(what: &str, code: OIDNError, msg: &str) -> Error {
    Error::Runtime(format!(
        "Open Image Denoise failed {what}: {msg} ({})",
        error_name(code)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn negative_and_non_finite_outputs_become_zero_and_the_rest_stays() {
        let p = sanitized(Vec3::new(-1e-3, f32::NAN, 0.25));
        assert_eq!(p.to_array(), [0.0, 0.0, 0.25]);
        let p = sanitized(Vec3::new(f32::INFINITY, f32::NEG_INFINITY, 7.0));
        assert_eq!(p.to_array(), [0.0, 0.0, 7.0]);
    }

    #[test]
    fn mismatched_sizes_and_nan_are_refused_before_oidn_is_called() {
        let input = |color: &'static [Vec3]| DenoiseInput {
            width: 2,
            height: 2,
            color,
            albedo: &[Vec3::ONE; 4],
            normal: &[Vec3::ONE; 4],
        };
        let e = check(&input(&[Vec3::ONE; 3])).unwrap_err().to_string();
        assert!(
            e.contains("the beauty has 3 pixels, not the 2×2 = 4"),
            "{e}"
        );
        static NAN: [Vec3; 4] = [
            Vec3::ONE,
            Vec3::ONE,
            Vec3::ONE,
            Vec3::new(0.0, f32::NAN, 0.0),
        ];
        let e = check(&input(&NAN)).unwrap_err().to_string();
        assert!(
            e.contains("the beauty is not finite at pixel (1, 1)"),
            "{e}"
        );
        assert!(check(&input(&[Vec3::ONE; 4])).is_ok());
    }
}
