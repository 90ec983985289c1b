//! Helpers shared by the scene-level tests (each test binary compiles
//! this module and uses what it needs).
#![allow(dead_code)]

use lucent::accel::Backend;
use lucent::film::Film;

pub mod brute;
pub mod exr_file;
pub mod scene;

/// The backends this build has: our BVH always, Embree with the `embree`
/// feature (a build without it must not pretend to test it).
pub fn backends() -> Vec<Backend> {
    let mut b = vec![Backend::Bvh];
    if cfg!(feature = "embree") {
        b.push(Backend::Embree);
    }
    b
}

/// Per channel: the mean over the pixels and its standard error, treating
/// the pixels as independent estimates of the same value (uniformly lit
/// test scenes).
pub fn mean_se(film: &Film) -> ([f64; 3], [f64; 3]) {
    let n = film.pixels.len() as f64;
    let mut mean = [0.0; 3];
    let mut se = [0.0; 3];
    for c in 0..3 {
        let m = film.pixels.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        let var = film
            .pixels
            .iter()
            .map(|p| (p[c] as f64 - m).powi(2))
            .sum::<f64>()
            / (n - 1.0);
        mean[c] = m;
        se[c] = (var / n).sqrt();
    }
    (mean, se)
}
