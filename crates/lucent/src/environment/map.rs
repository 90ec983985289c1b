//! A latitude-longitude environment map: radiance per texel, constant over
//! each texel, importance-sampled by a piecewise-constant distribution
//! over the image weighted by luminance × sin θ (the solid angle of the
//! texel's row), so directions are drawn nearly in proportion to the
//! radiance they bring (`docs/scene-format.md`, "`[environment]`").
//!
//! Map space: +y is up (v = 0 the zenith, v = 1 the nadir); u = ½ looks
//! along −z and u increases towards +x, so u = φ/2π + ½ with
//! φ = atan2(x, −z). The map is turned by `rotation` about +y.

use std::f32::consts::PI;
use std::fmt;

use super::distribution::Distribution2D;
use super::image::Texels;
use crate::geometry::Vec3;
use crate::sampling::luminance;

/// An environment map ready to render: texels scaled by the intensity,
/// the rotation and the sampling distribution.
#[derive(Clone)]
pub struct EnvMap {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
    /// cos and sin of the rotation about +y (map → world).
    cos_r: f32,
    sin_r: f32,
    dist: Distribution2D,
}

/// A direction sampled towards the environment.
#[derive(Clone, Copy, Debug)]
pub struct EnvSample {
    /// Unit world direction towards the environment.
    pub wi: Vec3,
    pub radiance: Vec3,
    /// Solid-angle density.
    pub pdf: f32,
}

impl fmt::Debug for EnvMap {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "EnvMap({}×{})", self.width, self.height)
    }
}

impl EnvMap {
    /// The map of `texels` × `scale`, turned by `rotation_deg` about +y.
    pub fn new(texels: Texels, scale: f32, rotation_deg: f32) -> Self {
        let (width, height) = (texels.width as usize, texels.height as usize);
        let texels: Vec<Vec3> = texels.data.into_iter().map(|t| t * scale).collect();
        let mut func = Vec::with_capacity(texels.len());
        for v in 0..height {
            let sin_theta = (PI * (v as f32 + 0.5) / height as f32).sin();
            for t in &texels[v * width..(v + 1) * width] {
                func.push(luminance(*t).max(t.max_element() * 1e-3) * sin_theta);
            }
        }
        let (sin_r, cos_r) = rotation_deg.to_radians().sin_cos();
        EnvMap {
            width,
            height,
            texels,
            cos_r,
            sin_r,
            dist: Distribution2D::new(&func, width, height),
        }
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// World direction to map space (the inverse rotation).
    #[inline]
    fn to_map(&self, d: Vec3) -> Vec3 {
        Vec3::new(
            self.cos_r * d.x - self.sin_r * d.z,
            d.y,
            self.sin_r * d.x + self.cos_r * d.z,
        )
    }

    /// Map direction to world space.
    #[inline]
    fn to_world(&self, m: Vec3) -> Vec3 {
        Vec3::new(
            self.cos_r * m.x + self.sin_r * m.z,
            m.y,
            -self.sin_r * m.x + self.cos_r * m.z,
        )
    }

    /// The image coordinates of unit world direction `d`, in [0, 1]², and
    /// sin θ there.
    #[inline]
    fn uv(&self, d: Vec3) -> ([f32; 2], f32) {
        let m = self.to_map(d);
        // sin θ from x and z, not √(1 − y²): accurate near the poles.
        let sin_theta = (m.x * m.x + m.z * m.z).sqrt();
        let u = 0.5 + m.x.atan2(-m.z) / (2.0 * PI);
        let v = sin_theta.atan2(m.y) / PI;
        ([u.clamp(0.0, 1.0), v.clamp(0.0, 1.0)], sin_theta)
    }

    #[inline]
    fn texel(&self, uv: [f32; 2]) -> Vec3 {
        let x = ((uv[0] * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv[1] * self.height as f32) as usize).min(self.height - 1);
        self.texels[y * self.width + x]
    }

    /// The radiance arriving from unit world direction `d`.
    #[inline]
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.texel(self.uv(d).0)
    }

    /// The solid-angle density with which [`sample`](Self::sample) draws
    /// unit direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        let (uv, sin_theta) = self.uv(d);
        if sin_theta <= 0.0 {
            return 0.0;
        }
        self.dist.pdf(uv) / (2.0 * PI * PI * sin_theta)
    }

    /// A direction drawn from two uniform numbers; None at a pole.
    #[inline]
    pub fn sample(&self, u: [f32; 2]) -> Option<EnvSample> {
        let s = self.dist.sample(u);
        let theta = PI * s.uv[1];
        let phi = 2.0 * PI * (s.uv[0] - 0.5);
        let (sin_t, cos_t) = theta.sin_cos();
        let (sin_p, cos_p) = phi.sin_cos();
        if sin_t <= 0.0 || s.pdf <= 0.0 {
            return None;
        }
        let m = Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p);
        Some(EnvSample {
            wi: self.to_world(m),
            radiance: self.texel(s.uv),
            pdf: s.pdf / (2.0 * PI * PI * sin_t),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 16 × 8 map of uneven texels (one bright, some black), turned.
    fn uneven(rotation: f32) -> EnvMap {
        let (w, h) = (16u32, 8u32);
        let data = (0..w * h)
            .map(|i| {
                let x = (i.wrapping_mul(2654435761u32) >> 8) as f32 / (1u32 << 24) as f32;
                let v = if i % 7 == 0 { 0.0 } else { x * 3.0 };
                if i == 37 {
                    Vec3::new(40.0, 30.0, 20.0)
                } else {
                    Vec3::new(v, 0.5 * v, 0.25 * v)
                }
            })
            .collect();
        let t = Texels {
            width: w,
            height: h,
            data,
        };
        EnvMap::new(t, 1.0, rotation)
    }

    fn halton(i: u32, base: u32) -> f32 {
        let (mut f, mut r, mut i) = (1.0f64, 0.0f64, i);
        while i > 0 {
            f /= base as f64;
            r += f * (i % base) as f64;
            i /= base;
        }
        r as f32
    }

    /// Pearson's χ² of the texels the sampled directions fall in against
    /// the counts the map's luminance × sin θ weights predict (catches a
    /// sampler whose directions do not follow the distribution, e.g. a
    /// wrong row/column mapping or rotation applied the wrong way round),
    /// and each sample's pdf against `pdf` of its direction (the density
    /// the escaping ray's MIS weight reads: unequal, the weights of light
    /// and lobe sampling would not sum to one).
    #[test]
    fn sampled_directions_follow_the_luminance_pdf() {
        let m = uneven(70.0);
        let n = 200_000u32;
        let mut counts = vec![0f64; m.width * m.height];
        let mut at_pole = 0;
        for i in 0..n {
            // Only u = (·, 0) lands exactly on the zenith (sin θ = 0).
            let Some(s) = m.sample([halton(i, 2), halton(i, 3)]) else {
                at_pole += 1;
                continue;
            };
            assert!((s.wi.length() - 1.0).abs() < 1e-5);
            let p = m.pdf(s.wi);
            assert!((p - s.pdf).abs() <= 2e-3 * s.pdf, "{p} vs {}", s.pdf);
            assert_eq!(m.radiance(s.wi), s.radiance);
            let (uv, _) = m.uv(s.wi);
            let x = ((uv[0] * m.width as f32) as usize).min(m.width - 1);
            let y = ((uv[1] * m.height as f32) as usize).min(m.height - 1);
            counts[y * m.width + x] += 1.0;
        }
        let weight = |i: usize| {
            let t = m.texels[i];
            let sin_t = (PI * ((i / m.width) as f32 + 0.5) / m.height as f32).sin();
            (luminance(t).max(t.max_element() * 1e-3) * sin_t) as f64
        };
        assert!(at_pole <= 1, "{at_pole} samples at a pole");
        let total: f64 = (0..counts.len()).map(weight).sum();
        let (mut chi2, mut dof) = (0.0, 0);
        for (i, c) in counts.iter().enumerate() {
            let e = (n - at_pole) as f64 * weight(i) / total;
            if e == 0.0 {
                assert_eq!(*c, 0.0, "texel {i} sampled with weight 0");
                continue;
            }
            chi2 += (c - e) * (c - e) / e;
            dof += 1;
        }
        // Quasi-random numbers put χ² far below its dof; a wrong cell
        // mapping puts it in the thousands.
        assert!(chi2 < dof as f64, "χ² = {chi2} over {dof} cells");
    }

    /// ∫ pdf dω = 1 over the sphere (Monte Carlo with uniform directions):
    /// catches a Jacobian other than 1/(2π² sin θ).
    #[test]
    fn pdf_integrates_to_one() {
        let m = uneven(-25.0);
        let n = 400_000u32;
        let mut sum = 0.0f64;
        for i in 0..n {
            let z = 1.0 - 2.0 * halton(i, 2);
            let phi = 2.0 * PI * halton(i, 3);
            let r = (1.0 - z * z).max(0.0).sqrt();
            let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
            sum += m.pdf(d) as f64 * 4.0 * std::f64::consts::PI;
        }
        let mean = sum / n as f64;
        assert!((mean - 1.0).abs() < 0.01, "∫ pdf = {mean}");
    }

    /// The rotation turns the map about +y by the right-hand rule
    /// (counter-clockwise seen from above): after 90° the texel seen along
    /// −z is seen along −x (catches the inverse rotation used for lookup).
    #[test]
    fn rotation_turns_the_map_about_up() {
        let m0 = uneven(0.0);
        let m90 = uneven(90.0);
        for d in [Vec3::new(0.0, 0.3, -1.0), Vec3::new(0.7, -0.2, 0.4)] {
            let d = d.normalize();
            // Ry(90°) maps (x, y, z) to (z, y, −x).
            let turned = Vec3::new(d.z, d.y, -d.x);
            assert_eq!(m0.radiance(d), m90.radiance(turned));
        }
    }
}
