//! The passes of a multi-layer output, as the renderer hands them to the
//! file writer: named layers of per-pixel values, and per-pixel coverage of
//! named things (objects, materials) for ID mattes.
//!
//! This is the one boundary between what the integrator measures (light
//! paths, light groups, data and noise passes; `crate::integrator`) and how
//! it is stored (channel names, precision, compression, ID-matte encoding;
//! the EXR writer in `crate::film`). Neither side knows the other's
//! internals.

/// What a layer's values are, which decides how they may be stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerKind {
    /// Radiance (beauty, light paths, light groups): may be stored as half
    /// floats when asked.
    Light,
    /// Measured data (albedo, normal, position, depth, sample count,
    /// variance): always 32-bit float, since half would destroy it (depth
    /// and position lose metres at half's 11-bit mantissa).
    Data,
    /// Integer identifiers carried in float channels (object and material
    /// IDs): always 32-bit float, holding the integer exactly (< 2^24).
    Id,
}

/// One pass: `name` is the layer (e.g. `diffuse_direct`), `channels` its
/// channel suffixes in order (e.g. `["R", "G", "B"]`, `["Z"]`), `values`
/// the pixels row-major, top row first, channels interleaved:
/// `values[(y * width + x) * channels.len() + c]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    pub name: String,
    pub channels: Vec<String>,
    pub kind: LayerKind,
    pub values: Vec<f32>,
}

impl Layer {
    /// The value of channel `c` at pixel index `pixel` (= y · width + x).
    pub fn get(&self, pixel: usize, c: usize) -> f32 {
        self.values[pixel * self.channels.len() + c]
    }
}

/// Per-pixel coverage of named things, for ID mattes: `names[i]` is the
/// name of thing `i` (an object or material name as the scene gives it),
/// and `pixels[p]` lists `(i, fraction)` for every thing seen in pixel `p`,
/// the fractions of the pixel's samples whose first visible hit was thing
/// `i` (they sum to 1 where every sample hit something, less where some
/// saw only the background).
#[derive(Clone, Debug, PartialEq)]
pub struct Coverage {
    /// What is matted: `"object"` or `"material"`.
    pub kind: String,
    pub names: Vec<String>,
    pub pixels: Vec<Vec<(u32, f32)>>,
}
