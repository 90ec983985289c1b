//! The image a rung is judged by: the running mean itself, or, for a
//! configuration that denoises, that mean denoised by Open Image Denoise
//! with its guides (`lucent::denoise`, as `lucent render --denoise` does)
//! and the time the denoise took, which the rung's time includes
//! (docs/accuracy.md, "Denoising").

use std::borrow::Cow;
use std::time::Instant;

use super::running::Guides;
use lucent::denoise::{denoise as oidn, DenoiseInput, DenoiseOptions};
use lucent::film::Film;
use lucent::Error;

/// A rung's image to compare with the reference.
pub(super) struct Judged<'a> {
    pub(super) film: Cow<'a, Film>,
    /// Wall time of the denoise (0 for a raw image).
    pub(super) seconds: f64,
}

impl<'a> Judged<'a> {
    /// The running mean as it is.
    pub(super) fn raw(film: &'a Film) -> Judged<'a> {
        Judged {
            film: Cow::Borrowed(film),
            seconds: 0.0,
        }
    }
}

/// `film` denoised with `guides` on `threads` threads, and how long that
/// took (device set-up, guide prefiltering and the filter's run).
pub(super) fn denoise(
    film: &Film,
    guides: &Guides,
    threads: Option<usize>,
) -> Result<Judged<'static>, Error> {
    let start = Instant::now();
    let pixels = oidn(
        &DenoiseInput {
            width: film.width,
            height: film.height,
            color: &film.pixels,
            albedo: &guides.albedo.pixels,
            normal: &guides.normal.pixels,
        },
        &DenoiseOptions::with_threads(threads),
    )?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(Judged {
        film: Cow::Owned(Film {
            width: film.width,
            height: film.height,
            pixels,
        }),
        seconds,
    })
}

/// Why this study draws no denoised curve, if it cannot: Open Image
/// Denoise is not loadable (the reason names what was tried).
pub(super) fn unavailable() -> Option<String> {
    lucent::denoise::load::api().err().map(|e| e.to_string())
}
