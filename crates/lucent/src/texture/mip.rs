//! A texture's MIP pyramid (Williams 1983): level 0 the image, each next
//! level half the size (rounded down, at least 1) by a 2×2 box filter, and
//! the lookup: bilinear within a level, linear between the two levels whose
//! texel size brackets the footprint (`docs/scene-format.md`, "Textures").
//! Lerps are written a + (b − a)·t, so a constant image returns its value
//! bit for bit at every level and position.

use glam::Vec2;

use crate::geometry::Vec3;

/// What a lookup outside [0, 1]² reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane.
    Repeat,
    /// The edge texels extend outwards.
    Clamp,
}

impl Wrap {
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "repeat" => Some(Wrap::Repeat),
            "clamp" => Some(Wrap::Clamp),
            _ => None,
        }
    }

    #[inline]
    fn index(self, i: i64, n: u32) -> usize {
        match self {
            Wrap::Repeat => i.rem_euclid(n as i64) as usize,
            Wrap::Clamp => i.clamp(0, n as i64 - 1) as usize,
        }
    }
}

/// One level: RGB texels, row-major from the top row (v = 1 at the top).
#[derive(Clone, Debug, PartialEq)]
struct Level {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

/// A MIP-mapped RGB texture (linear values).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    levels: Vec<Level>,
    wrap: Wrap,
}

impl Texture {
    /// The pyramid of a `width` × `height` image (`texels` row-major from
    /// the top row; both sizes at least 1).
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>, wrap: Wrap) -> Self {
        assert!(width > 0 && height > 0 && texels.len() == width as usize * height as usize);
        let mut levels = vec![Level {
            width,
            height,
            texels,
        }];
        while let Some(next) = levels.last().and_then(half) {
            levels.push(next);
        }
        Texture { levels, wrap }
    }

    /// The number of levels.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Width and height of level 0.
    pub fn size(&self) -> (u32, u32) {
        (self.levels[0].width, self.levels[0].height)
    }

    /// The bits of level 0's texels (R, G, B per texel, row by row).
    pub fn texel_bits(&self) -> impl ExactSizeIterator<Item = u32> + '_ {
        let l = &self.levels[0];
        (0..l.texels.len() * 3).map(|i| l.texels[i / 3][i % 3].to_bits())
    }

    /// The largest value of each channel over level 0 (the largest any
    /// lookup returns: the levels and the filter average texels).
    pub fn max_texel(&self) -> Vec3 {
        self.levels[0]
            .texels
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |m, &t| m.max(t))
    }

    /// The least and greatest mean of a texel's channels: bounds on what
    /// a filtered lookup's channel mean can be.
    pub fn mean_range(&self) -> (f32, f32) {
        self.levels[0]
            .texels
            .iter()
            .map(|t| (t.x + t.y + t.z) / 3.0)
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), m| {
                (lo.min(m), hi.max(m))
            })
    }

    /// Bytes held by all levels.
    pub fn bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.texels.len() * std::mem::size_of::<Vec3>())
            .sum()
    }

    /// The (fractional) level whose texels are `width` UV units wide:
    /// log2(width · max(w, h)) of level 0, clamped to the pyramid.
    #[inline]
    pub fn level_for(&self, width: f32) -> f32 {
        let (w, h) = self.size();
        let texels = width * w.max(h) as f32;
        let top = (self.levels.len() - 1) as f32;
        if texels > 1.0 {
            texels.log2().min(top)
        } else {
            0.0
        }
    }

    /// The filtered value at `uv` for a footprint `width` UV units wide.
    #[inline]
    pub fn lookup(&self, uv: Vec2, width: f32) -> Vec3 {
        let level = self.level_for(width);
        let lo = level.floor();
        let a = self.bilinear(lo as usize, uv);
        let t = level - lo;
        if t > 0.0 {
            let b = self.bilinear(lo as usize + 1, uv);
            a + (b - a) * t
        } else {
            a
        }
    }

    /// The bilinear value of level `k` at `uv` (texel centres at
    /// ((i + ½)/w, 1 − (j + ½)/h)).
    pub fn bilinear(&self, k: usize, uv: Vec2) -> Vec3 {
        let l = &self.levels[k];
        let x = uv.x * l.width as f32 - 0.5;
        let y = (1.0 - uv.y) * l.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let texel = |i: i64, j: i64| {
            let (i, j) = (self.wrap.index(i, l.width), self.wrap.index(j, l.height));
            l.texels[j * l.width as usize + i]
        };
        let top = texel(x0, y0) + (texel(x0 + 1, y0) - texel(x0, y0)) * fx;
        let bottom = texel(x0, y0 + 1) + (texel(x0 + 1, y0 + 1) - texel(x0, y0 + 1)) * fx;
        top + (bottom - top) * fy
    }
}

/// The next level of `l` (None at 1 × 1): each texel the mean of a 2×2
/// block (an odd last row or column is left out), as ½(½(a + b) + ½(c + d))
/// so equal texels average to themselves exactly.
fn half(l: &Level) -> Option<Level> {
    if l.width == 1 && l.height == 1 {
        return None;
    }
    let (w, h) = ((l.width / 2).max(1), (l.height / 2).max(1));
    let at =
        |i: u32, j: u32| l.texels[(j.min(l.height - 1) * l.width + i.min(l.width - 1)) as usize];
    let mut texels = Vec::with_capacity(w as usize * h as usize);
    for j in 0..h {
        for i in 0..w {
            let (x, y) = (2 * i, 2 * j);
            let row0 = (at(x, y) + at(x + 1, y)) * 0.5;
            let row1 = (at(x, y + 1) + at(x + 1, y + 1)) * 0.5;
            texels.push((row0 + row1) * 0.5);
        }
    }
    Some(Level {
        width: w,
        height: h,
        texels,
    })
}

#[cfg(test)]
#[path = "mip_tests.rs"]
mod tests;
