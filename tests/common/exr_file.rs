//! Reading the EXRs lucent writes, for tests that compare channels: the
//! first layer with its windows, every layer's channels by name, and the
//! whole first layer for tests that rewrite a file through the `exr`
//! crate.

use std::collections::BTreeMap;
use std::path::Path;

use exr::prelude::{AnyChannels, FlatSamples, Image, Layer, ReadChannels, ReadLayers};

/// An EXR's first layer, every channel as flat samples, with its
/// attributes.
pub type FlatLayer = Image<Layer<AnyChannels<FlatSamples>>>;

/// The first layer of the EXR at `path`.
pub fn first_layer(path: &Path) -> FlatLayer {
    exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Each sample's bits (a half's bits widened, a u32 as it is).
pub fn bits(samples: &FlatSamples) -> Vec<u32> {
    match samples {
        FlatSamples::F32(v) => v.iter().map(|x| x.to_bits()).collect(),
        FlatSamples::F16(v) => v.iter().map(|x| x.to_bits() as u32).collect(),
        FlatSamples::U32(v) => v.clone(),
    }
}

/// Each sample's value as a float.
pub fn floats(samples: &FlatSamples) -> Vec<f32> {
    match samples {
        FlatSamples::F32(v) => v.clone(),
        FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
        FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
    }
}

/// Every channel of the first layer of the EXR at `path`, as floats.
pub fn channels(path: &Path) -> BTreeMap<String, Vec<f32>> {
    let image = first_layer(path);
    let list = &image.layer_data.channel_data.list;
    list.iter()
        .map(|c| (c.name.to_string(), floats(&c.sample_data)))
        .collect()
}

/// Every channel of every layer of the EXR at `path`, named
/// `layer.channel`, and its samples' bits, sorted by name.
pub fn all_layers_bits(path: &Path) -> Vec<(String, Vec<u32>)> {
    let image = exr::prelude::read_all_flat_layers_from_file(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut v = Vec::new();
    for layer in &image.layer_data {
        let prefix = layer
            .attributes
            .layer_name
            .as_ref()
            .map(|n| format!("{n}."))
            .unwrap_or_default();
        for ch in &layer.channel_data.list {
            v.push((format!("{prefix}{}", ch.name), bits(&ch.sample_data)));
        }
    }
    v.sort();
    v
}

/// A flat EXR's display window (x0, y0, w, h), data window (x0, y0, w,
/// h) and channels: name, then every sample's bits.
pub struct Exr {
    pub display: (i32, i32, usize, usize),
    pub data: (i32, i32, usize, usize),
    pub channels: Vec<(String, Vec<u32>)>,
}

impl Exr {
    pub fn read(path: &Path) -> Exr {
        let image = first_layer(path);
        let dw = image.attributes.display_window;
        let b = image.layer_data.absolute_bounds();
        let list = &image.layer_data.channel_data.list;
        Exr {
            display: (dw.position.0, dw.position.1, dw.size.0, dw.size.1),
            data: (b.position.0, b.position.1, b.size.0, b.size.1),
            channels: list
                .iter()
                .map(|c| (c.name.to_string(), bits(&c.sample_data)))
                .collect(),
        }
    }

    /// Channel `c`'s sample bits at frame pixel (x, y).
    pub fn at(&self, c: usize, x: i32, y: i32) -> u32 {
        let (x0, y0, w, _) = self.data;
        self.channels[c].1[(y - y0) as usize * w + (x - x0) as usize]
    }

    pub fn names(&self) -> Vec<&str> {
        self.channels.iter().map(|c| c.0.as_str()).collect()
    }
}
