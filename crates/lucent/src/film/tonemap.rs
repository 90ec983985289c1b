//! Tone mapping for the PNG preview: linear radiance → display [0, 1],
//! then the sRGB transfer curve (IEC 61966-2-1). The EXR stays linear.

use crate::geometry::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ToneMap {
    /// Clip each channel to [0, 1].
    Clamp,
    /// The ACES filmic curve fit of Narkowicz (2015): a soft shoulder so
    /// bright lights keep detail instead of clipping.
    Filmic,
}

impl ToneMap {
    pub fn apply(self, c: Vec3) -> Vec3 {
        let c = c.max(Vec3::ZERO);
        match self {
            ToneMap::Clamp => c.min(Vec3::ONE),
            ToneMap::Filmic => {
                let (a, b, cc, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
                ((c * (c * a + b)) / (c * (c * cc + d) + e)).clamp(Vec3::ZERO, Vec3::ONE)
            }
        }
    }
}

/// The sRGB opto-electronic transfer function on [0, 1]; NaN maps to 0.
pub(crate) fn srgb_encode(v: f32) -> f32 {
    if v.is_nan() {
        return 0.0;
    }
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_are_monotone_and_bounded() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.5) - 0.735_356_7).abs() < 1e-5);
        let mut prev = -1.0;
        for i in 0..1000 {
            let x = i as f32 * 0.02;
            let y = ToneMap::Filmic.apply(Vec3::splat(x)).x;
            assert!((0.0..=1.0).contains(&y) && y >= prev);
            prev = y;
        }
        assert_eq!(
            ToneMap::Clamp.apply(Vec3::new(2.0, -1.0, 0.5)),
            Vec3::new(1.0, 0.0, 0.5)
        );
    }
}
