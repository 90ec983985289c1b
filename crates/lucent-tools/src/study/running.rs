//! A configuration's running mean along the ladder: the beauty of every
//! sample rendered so far, the guides a denoise reads (albedo and normal)
//! when the configuration denoises, and the render time they took; kept
//! in the state directory after each rung so a study resumes from it
//! (docs/accuracy.md, "How a study works").

use std::fs;
use std::path::{Path, PathBuf};

use super::input_file::read_film;
use super::runtime;
use lucent::denoise::frame::GUIDES;
use lucent::film::layers::Layer;
use lucent::film::Film;
use lucent::geometry::Vec3;
use lucent::Error;

/// The means of a denoise's guides over the samples rendered so far.
#[derive(Clone, Debug)]
pub(super) struct Guides {
    pub(super) albedo: Film,
    pub(super) normal: Film,
}

impl Guides {
    /// The guides among a render's `layers` (its `albedo` and `N` passes).
    pub(super) fn from_layers(layers: &[Layer], width: u32, height: u32) -> Result<Guides, Error> {
        let film = |name: &str| -> Result<Film, Error> {
            let l = layers
                .iter()
                .find(|l| l.name == name && l.channels.len() == 3)
                .ok_or_else(|| Error::Runtime(format!("the render has no {name} pass")))?;
            let pixels = l
                .values
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2]))
                .collect();
            Ok(Film {
                width,
                height,
                pixels,
            })
        };
        Ok(Guides {
            albedo: film(GUIDES[0].0)?,
            normal: film(GUIDES[1].0)?,
        })
    }
}

/// Samples `0..n` of a configuration, as far as they are rendered.
#[derive(Clone, Debug)]
pub(super) struct Running {
    pub(super) film: Film,
    /// Present when the configuration denoises.
    pub(super) guides: Option<Guides>,
    /// Wall time of the renders of all these samples (no denoise).
    pub(super) seconds: f64,
}

/// Mixes `b` (the mean of samples `a_n..n`) into `a` (the mean of samples
/// `0..a_n`): mean_n = (a_n/n)·a + ((n − a_n)/n)·b, each channel in f64.
fn mix(a: &mut Film, b: &Film, a_n: u32, n: u32) {
    let (wa, wb) = (a_n as f64 / n as f64, (n - a_n) as f64 / n as f64);
    for (p, q) in a.pixels.iter_mut().zip(&b.pixels) {
        let m = |x: f32, y: f32| (wa * x as f64 + wb * y as f64) as f32;
        *p = Vec3::new(m(p.x, q.x), m(p.y, q.y), m(p.z, q.z));
    }
}

impl Running {
    /// The running mean of samples `0..n` from this one of `0..prev_n` and
    /// `chunk`, the mean of samples `prev_n..n`.
    pub(super) fn extended(mut self, chunk: Running, prev_n: u32, n: u32) -> Running {
        mix(&mut self.film, &chunk.film, prev_n, n);
        if let (Some(g), Some(c)) = (&mut self.guides, &chunk.guides) {
            mix(&mut g.albedo, &c.albedo, prev_n, n);
            mix(&mut g.normal, &c.normal, prev_n, n);
        }
        self.seconds += chunk.seconds;
        self
    }

    /// Keeps this mean (of `n` samples) in the state directory `dir`,
    /// removing the one of `prev_n` samples.
    pub(super) fn save(&self, dir: &Path, config: &str, n: u32, prev_n: u32) -> Result<(), Error> {
        let files = state_files(dir, config, n);
        self.film.write_exr(&files[0]).map_err(runtime)?;
        if let Some(g) = &self.guides {
            g.albedo.write_exr(&files[1]).map_err(runtime)?;
            g.normal.write_exr(&files[2]).map_err(runtime)?;
        }
        if prev_n > 0 {
            for f in state_files(dir, config, prev_n) {
                let _ = fs::remove_file(f);
            }
        }
        Ok(())
    }

    /// The mean of `n` samples kept in `dir`, if it is there at this size
    /// (with its guides when `guides`); `seconds` is the render time
    /// recorded for it.
    pub(super) fn load(
        dir: &Path,
        config: &str,
        n: u32,
        (width, height): (u32, u32),
        guides: bool,
        seconds: f64,
    ) -> Option<Running> {
        let files = state_files(dir, config, n);
        let read = |p: &PathBuf| read_film(p, width, height).ok().flatten();
        let film = read(&files[0])?;
        let guides = if guides {
            Some(Guides {
                albedo: read(&files[1])?,
                normal: read(&files[2])?,
            })
        } else {
            None
        };
        Some(Running {
            film,
            guides,
            seconds,
        })
    }
}

/// Where the running mean of `config` after `spp` samples is kept: the
/// beauty, then the albedo and normal guides.
pub(super) fn state_files(dir: &Path, config: &str, spp: u32) -> [PathBuf; 3] {
    let name = |suffix: &str| {
        dir.join("state")
            .join(format!("{}-{spp}{suffix}.exr", slug(config)))
    };
    [name(""), name("-albedo"), name("-normal")]
}

/// A configuration name as a file name: "radius=table:16" → "radius_table_16".
pub fn slug(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect()
}
