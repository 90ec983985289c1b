//! Error of an image against a reference.
//!
//! - RMSE: √(mean over pixels and channels of (I − R)²).
//! - relMSE: mean of (I − R)² / (R² + ε), ε = 0.01 (Rousselle et al. 2011):
//!   relative error that dark pixels cannot blow up.
//! - bias: (Σ I − Σ R) / Σ R over all pixels and channels, a fraction; its
//!   standard error comes from the spread of the per-pixel differences
//!   (pixels are independent, so the mean of n of them has σ/√n). That
//!   standard error includes the reference's own noise, as it should.
//! - fireflies: pixels whose luminance exceeds k × the reference's there
//!   (k = 10 by default), with the reference floored at 0.1 % of its mean
//!   luminance so black reference pixels do not count every speck.

use lucent::film::Film;
use lucent::geometry::Vec3;

pub(crate) const REL_MSE_EPS: f64 = 0.01;
pub(crate) const FIREFLY_FLOOR: f64 = 1e-3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Metrics {
    pub rmse: f64,
    pub rel_mse: f64,
    pub bias: f64,
    pub bias_stderr: f64,
    pub fireflies: u64,
}

/// Why two images cannot be compared.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MetricsError {
    /// The image and the reference differ in size.
    #[error("image is {}x{} but the reference is {}x{}", image.0, image.1, reference.0, reference.1)]
    SizeMismatch {
        /// Width and height of the image.
        image: (u32, u32),
        /// Width and height of the reference.
        reference: (u32, u32),
    },
    /// The images have no pixels.
    #[error("empty image")]
    Empty,
}

fn lum(p: Vec3) -> f64 {
    0.2126 * p.x as f64 + 0.7152 * p.y as f64 + 0.0722 * p.z as f64
}

/// Compares `img` with `reference` (same size); `k` is the firefly factor.
pub fn compare(img: &Film, reference: &Film, k: f64) -> Result<Metrics, MetricsError> {
    if (img.width, img.height) != (reference.width, reference.height) {
        return Err(MetricsError::SizeMismatch {
            image: (img.width, img.height),
            reference: (reference.width, reference.height),
        });
    }
    let n = img.pixels.len();
    if n == 0 {
        return Err(MetricsError::Empty);
    }
    let mean_ref_lum = reference.pixels.iter().map(|&p| lum(p)).sum::<f64>() / n as f64;
    let floor = FIREFLY_FLOOR * mean_ref_lum;
    let (mut se, mut rel, mut sum_i, mut sum_r) = (0.0, 0.0, 0.0, 0.0);
    let (mut e_sum, mut e_sq) = (0.0, 0.0);
    let mut fireflies = 0;
    for (&a, &b) in img.pixels.iter().zip(&reference.pixels) {
        let mut e_pix = 0.0;
        for c in 0..3 {
            let (x, r) = (a[c] as f64, b[c] as f64);
            let d = x - r;
            se += d * d;
            rel += d * d / (r * r + REL_MSE_EPS);
            sum_i += x;
            sum_r += r;
            e_pix += d / 3.0;
        }
        e_sum += e_pix;
        e_sq += e_pix * e_pix;
        if lum(a) > k * lum(b).max(floor) {
            fireflies += 1;
        }
    }
    let m = (3 * n) as f64;
    let mean_e = e_sum / n as f64;
    let var_e = if n > 1 {
        (e_sq - n as f64 * mean_e * mean_e).max(0.0) / (n - 1) as f64
    } else {
        0.0
    };
    let mean_r = sum_r / m;
    let (bias, bias_stderr) = if mean_r > 0.0 {
        ((sum_i - sum_r) / sum_r, (var_e / n as f64).sqrt() / mean_r)
    } else {
        (0.0, 0.0)
    };
    Ok(Metrics {
        rmse: (se / m).sqrt(),
        rel_mse: rel / m,
        bias,
        bias_stderr,
        fireflies,
    })
}

/// log-log interpolation: the time at which a ladder of (seconds, error)
/// points, in increasing time, first reaches `target`; None if it never
/// does (a biased configuration can plateau above it).
pub(crate) fn time_to_reach(points: &[(f64, f64)], target: f64) -> Option<f64> {
    let mut prev: Option<(f64, f64)> = None;
    for &(t, e) in points {
        if e <= target {
            return Some(match prev {
                Some((t0, e0)) if e0 > target && t0 > 0.0 && t > 0.0 && e > 0.0 => {
                    let f = (e0.ln() - target.ln()) / (e0.ln() - e.ln());
                    (t0.ln() + f * (t.ln() - t0.ln())).exp()
                }
                _ => t,
            });
        }
        prev = Some((t, e));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn film(v: &[f32]) -> Film {
        let mut f = Film::new(v.len() as u32, 1);
        for (i, &x) in v.iter().enumerate() {
            f.set(i as u32, 0, Vec3::splat(x));
        }
        f
    }

    #[test]
    fn metrics_of_known_images() {
        let r = film(&[1.0, 1.0, 1.0, 1.0]);
        let i = film(&[1.0, 1.0, 1.0, 21.0]);
        let m = compare(&i, &r, 10.0).unwrap();
        assert!((m.rmse - 10.0).abs() < 1e-12, "{m:?}");
        assert!((m.rel_mse - 100.0 / 1.01).abs() < 1e-9);
        assert!((m.bias - 5.0).abs() < 1e-12);
        assert!((m.bias_stderr - 5.0).abs() < 1e-9); // std of (0,0,0,20) / 2
        assert_eq!(m.fireflies, 1);
        let same = compare(&r, &r, 10.0).unwrap();
        assert_eq!((same.rmse, same.bias, same.fireflies), (0.0, 0.0, 0));
        assert!(compare(&film(&[1.0]), &r, 10.0).is_err());
        // black reference pixels: only values above the floor count
        let dark = film(&[0.0, 0.0, 4.0, 4.0]);
        let m = compare(&film(&[1e-5, 1.0, 4.0, 4.0]), &dark, 10.0).unwrap();
        assert_eq!(m.fireflies, 1);
    }

    #[test]
    fn time_to_reach_interpolates_log_log() {
        let pts = [(1.0, 1.0), (4.0, 0.5), (16.0, 0.25)];
        assert_eq!(time_to_reach(&pts, 2.0), Some(1.0));
        assert!((time_to_reach(&pts, 0.5).unwrap() - 4.0).abs() < 1e-12);
        // halfway in log error between 0.5 and 0.25 → halfway in log time
        assert!((time_to_reach(&pts, 0.5f64.powf(1.5)).unwrap() - 8.0).abs() < 1e-9);
        assert_eq!(time_to_reach(&pts, 0.1), None);
    }
}
