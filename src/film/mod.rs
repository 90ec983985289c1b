//! The film: one RGB radiance estimate per pixel, and its outputs — a float
//! RGBA OpenEXR for compositing and a tone-mapped sRGB PNG preview. Both are
//! written atomically (a temporary file in the target's directory, then a
//! rename), so a reader never sees a half-written image under the real name.

pub mod tonemap;

use std::fs;
use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::geometry::Vec3;
pub use tonemap::ToneMap;

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Row-major, top row first.
    pub pixels: Vec<Vec3>,
}

impl Film {
    pub fn new(width: u32, height: u32) -> Self {
        Film {
            width,
            height,
            pixels: vec![Vec3::ZERO; width as usize * height as usize],
        }
    }
    pub fn get(&self, x: u32, y: u32) -> Vec3 {
        self.pixels[(y * self.width + x) as usize]
    }
    pub fn set(&mut self, x: u32, y: u32, v: Vec3) {
        self.pixels[(y * self.width + x) as usize] = v;
    }

    /// Writes a float (f32) RGBA OpenEXR, alpha = 1, ZIP-compressed scan
    /// lines. Blocks are compressed and written sequentially in increasing
    /// line order: the exr crate's parallel writer emits blocks in the order
    /// they finish, which would make the file's bytes (not its pixels)
    /// differ from run to run.
    pub fn write_exr(&self, path: &Path) -> Result<(), Error> {
        use exr::prelude::*;
        let w = self.width as usize;
        let channels = SpecificChannels::rgba(|pos: Vec2<usize>| {
            let p = self.pixels[pos.y() * w + pos.x()];
            (p.x, p.y, p.z, 1.0f32)
        });
        let encoding = Encoding {
            compression: Compression::ZIP16,
            blocks: Blocks::ScanLines,
            line_order: LineOrder::Increasing,
        };
        let image = Image::from_encoded_channels((w, self.height as usize), encoding, channels);
        write_atomically(path, |tmp| {
            image
                .write()
                .non_parallel()
                .to_file(tmp)
                .map_err(|e| e.to_string())
        })
    }

    /// Reads an RGBA/RGB float OpenEXR written by [`write_exr`](Self::write_exr)
    /// (or any RGB EXR), for tests, merging and studies.
    pub fn read_exr(path: &Path) -> Result<Film, Error> {
        use exr::prelude::*;
        let image = read_first_rgba_layer_from_file(
            path,
            |res, _| Film::new(res.width() as u32, res.height() as u32),
            |film: &mut Film, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                film.set(pos.x() as u32, pos.y() as u32, Vec3::new(r, g, b))
            },
        )
        .map_err(|e| crate::error::Error::Read {
            path: path.to_path_buf(),
            problem: e.to_string(),
        })?;
        Ok(image.layer_data.channel_data.pixels)
    }

    /// Writes an 8-bit sRGB PNG preview through `tonemap` after scaling by
    /// 2^exposure.
    pub fn write_png(&self, path: &Path, tonemap: ToneMap, exposure: f32) -> Result<(), Error> {
        let scale = exposure.exp2();
        let mut buf = Vec::with_capacity(self.pixels.len() * 3);
        for p in &self.pixels {
            let c = tonemap.apply(*p * scale);
            for v in [c.x, c.y, c.z] {
                buf.push((tonemap::srgb_encode(v) * 255.0 + 0.5).clamp(0.0, 255.0) as u8);
            }
        }
        let img = image::RgbImage::from_raw(self.width, self.height, buf).ok_or_else(|| {
            Error::Write {
                path: path.to_path_buf(),
                problem: "bad film size".into(),
            }
        })?;
        write_atomically(path, |tmp| {
            img.save_with_format(tmp, image::ImageFormat::Png)
                .map_err(|e| e.to_string())
        })
    }
}

/// Runs `write` on a temporary path next to `path`, then renames it into
/// place; on any failure the temporary file is removed and nothing appears
/// under `path`. `write` reports its failure as a message; the error names
/// `path`.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), Error> {
    let tmp = temp_path(path);
    let result = write(&tmp).and_then(|()| fs::rename(&tmp, path).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = fs::remove_file(&tmp);
    }
    result.map_err(|problem| Error::Write {
        path: path.to_path_buf(),
        problem,
    })
}

/// [`write_atomically`] with the error as its message (`cannot write PATH:
/// …`), for the tools (plots, study, bench) that still report strings.
pub fn atomic_write(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), String> {
    write_atomically(path, write).map_err(String::from)
}

fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.tmp", std::process::id()))
}

/// The PNG preview's path beside an EXR path: same stem, `.png`.
pub fn preview_path(exr: &Path) -> PathBuf {
    exr.with_extension("png")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trips_exactly_and_png_is_written() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = Film::new(3, 2);
        f.set(0, 0, Vec3::new(0.25, 1e-7, 123.5));
        f.set(2, 1, Vec3::new(3.0, 0.5, 0.0));
        let p = dir.path().join("a.exr");
        f.write_exr(&p).unwrap();
        assert_eq!(Film::read_exr(&p).unwrap(), f);
        let png = preview_path(&p);
        f.write_png(&png, ToneMap::Clamp, 0.0).unwrap();
        let img = image::open(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (3, 2));
        assert_eq!(img.get_pixel(2, 1).0, [255, 188, 0]); // sRGB(0.5) = 0.7354
                                                          // no temporary files left behind
        let names: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing-dir").join("a.exr");
        assert!(Film::new(2, 2).write_exr(&p).is_err());
        assert!(!p.exists());
        let p2 = dir.path().join("b.exr");
        let r = atomic_write(&p2, |tmp| {
            fs::write(tmp, b"partial").unwrap();
            Err("simulated failure".into())
        });
        assert!(r.is_err() && !p2.exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
