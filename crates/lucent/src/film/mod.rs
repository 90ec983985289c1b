//! The film: one RGB radiance estimate per pixel, and its outputs — a float
//! RGBA OpenEXR for compositing and a tone-mapped sRGB PNG preview. Both are
//! written atomically (a temporary file in the target's directory, then a
//! rename), so a reader never sees a half-written image under the real name;
//! the outputs of one command are committed together ([`commit_all`]), so a
//! failure never leaves an EXR without its PNG.
//!
//! The film also owns every per-pixel sum a render keeps: the beauty's and
//! the passes' exact sums ([`Sums`], [`pass_sums`]), from which the image
//! and the pass layers are made.

pub mod accumulate;
pub mod cryptomatte;
pub mod exr_attributes;
pub mod exr_layers;
pub mod layers;
pub mod pass_layout;
pub mod pass_sums;
pub mod passes;
pub mod region;
pub mod stale;
pub mod sums;
pub mod tonemap;
pub mod variance;

use std::fmt::Display;
use std::fs;
use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::geometry::Vec3;
use crate::interrupt;
pub use sums::Sums;
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
    /// [`Film::new`], failing with a message (a runtime error: exit code 1)
    /// instead of aborting the process when the pixels cannot be allocated.
    pub fn try_new(width: u32, height: u32) -> Result<Self, Error> {
        let n = width as usize * height as usize;
        let mut pixels = Vec::new();
        pixels.try_reserve_exact(n).map_err(|_| {
            out_of_memory(&format!("a {width}×{height} image"), n.saturating_mul(12))
        })?;
        pixels.resize(n, Vec3::ZERO);
        Ok(Film {
            width,
            height,
            pixels,
        })
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
        commit_all(vec![self.stage_exr(path)?])
    }

    /// [`write_exr`](Self::write_exr) to the temporary file only, for
    /// [`commit_all`].
    pub fn stage_exr(&self, path: &Path) -> Result<Staged, Error> {
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
        Staged::write(path, |tmp| image.write().non_parallel().to_unbuffered(tmp))
    }

    /// The EXR at `exr` and its PNG preview beside it
    /// ([`preview_path`]), committed together: both appear, or neither
    /// does and whatever was under the names stays.
    pub fn write_exr_and_preview(
        &self,
        exr: &Path,
        tonemap: ToneMap,
        exposure: f32,
    ) -> Result<(), Error> {
        let a = self.stage_exr(exr)?;
        let b = self.stage_png(&preview_path(exr), tonemap, exposure)?;
        commit_all(vec![a, b])
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

    /// The film of the EXR open as `file` (named `path` in errors) if it is
    /// one RGB(A) layer of `width`×`height` pixels; `None` if its size is
    /// another. The header is read and checked first, so what reading the
    /// pixels allocates comes from `width`×`height`, not from the file.
    pub fn read_exr_of_size(
        file: fs::File,
        path: &Path,
        width: u32,
        height: u32,
    ) -> Result<Option<Film>, Error> {
        use exr::prelude::*;
        use std::io::{BufReader, Seek};
        let bad = |problem: String| crate::error::Error::Read {
            path: path.to_path_buf(),
            problem,
        };
        let meta = exr::meta::MetaData::read_from_buffered(BufReader::new(&file), true)
            .map_err(|e| bad(e.to_string()))?;
        let [h] = &meta.headers[..] else {
            return Err(bad("more than one EXR layer".into()));
        };
        if h.deep || h.channels.list.len() > 4 {
            return Err(bad("not an RGB(A) image".into()));
        }
        if h.layer_size != Vec2(width as usize, height as usize) {
            return Ok(None);
        }
        let mut file = file;
        file.seek(std::io::SeekFrom::Start(0))
            .map_err(|e| bad(e.to_string()))?;
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgba_channels(
                |res, _| Film::new(res.width() as u32, res.height() as u32),
                |film: &mut Film, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                    film.set(pos.x() as u32, pos.y() as u32, Vec3::new(r, g, b))
                },
            )
            .first_valid_layer()
            .all_attributes()
            .from_buffered(BufReader::new(file))
            .map_err(|e| bad(e.to_string()))?;
        Ok(Some(image.layer_data.channel_data.pixels))
    }

    /// Writes an 8-bit sRGB PNG preview through `tonemap` after scaling by
    /// 2^exposure.
    pub fn write_png(&self, path: &Path, tonemap: ToneMap, exposure: f32) -> Result<(), Error> {
        commit_all(vec![self.stage_png(path, tonemap, exposure)?])
    }

    /// [`write_png`](Self::write_png) to the temporary file only, for
    /// [`commit_all`].
    pub fn stage_png(&self, path: &Path, tonemap: ToneMap, exposure: f32) -> Result<Staged, Error> {
        let scale = exposure.exp2();
        let mut buf = Vec::new();
        buf.try_reserve_exact(self.pixels.len() * 3)
            .map_err(|_| out_of_memory("the PNG preview", self.pixels.len().saturating_mul(3)))?;
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
        Staged::write(path, |tmp| write_png(&img, tmp))
    }
}

/// Encodes `img` as PNG into `file`.
pub fn write_png(img: &image::RgbImage, file: &mut fs::File) -> Result<(), image::ImageError> {
    let mut w = std::io::BufWriter::new(file);
    img.write_to(&mut w, image::ImageFormat::Png)?;
    Ok(std::io::Write::flush(&mut w)?)
}

/// The error of an allocation that failed: what it was for and its size.
pub(crate) fn out_of_memory(what: &str, bytes: usize) -> Error {
    Error::Runtime(format!(
        "out of memory: cannot allocate {} MB for {what}",
        bytes.div_ceil(1 << 20)
    ))
}

/// Runs `write` on a temporary file next to `path` ([`Staged::write`]),
/// then renames it into place; on any failure the temporary file is
/// removed and nothing appears under `path`. `write` reports its failure as
/// any displayable error; the error names `path` and carries that text.
pub fn write_atomically<E: Display>(
    path: &Path,
    write: impl FnOnce(&mut fs::File) -> Result<(), E>,
) -> Result<(), Error> {
    commit_all(vec![Staged::write(path, write)?])
}

/// An output written in full to a temporary file next to its path, not yet
/// under its name: [`commit_all`] moves it there together with the other
/// outputs of the same command. Dropped uncommitted, the temporary file is
/// removed.
#[must_use = "a staged output appears only when committed"]
#[derive(Debug)]
pub struct Staged {
    tmp: PathBuf,
    path: PathBuf,
}

impl Staged {
    /// Runs `write` on a temporary file created for it beside `path`; on
    /// failure the temporary file is removed and the error names `path`.
    ///
    /// The temporary file is created exclusively (`O_CREAT|O_EXCL`: a file
    /// or symlink already under its name is never opened, followed or
    /// replaced) under a short name ([`temporary_path`]), and `write` gets the
    /// open file, never a path that could be swapped under it.
    pub fn write<E: Display>(
        path: &Path,
        write: impl FnOnce(&mut fs::File) -> Result<(), E>,
    ) -> Result<Staged, Error> {
        // what a killed process left of this output (SIGKILL, `stale`)
        stale::clean(path);
        let tmp = temp_path(path);
        let create = || {
            fs::OpenOptions::new()
                .write(true)
                .read(true)
                .create_new(true)
                .open(&tmp)
        };
        let mut file = interrupt::create_temporary(&tmp, create).map_err(|e| Error::Write {
            path: path.to_path_buf(),
            problem: match e.kind() {
                std::io::ErrorKind::AlreadyExists => format!(
                    "its temporary file {} is in the way (lucent did not create it: \
                         move it away)",
                    tmp.display()
                ),
                _ => format!("cannot create its temporary file {}: {e}", tmp.display()),
            },
        })?;
        let staged = Staged {
            tmp,
            path: path.to_path_buf(),
        };
        // on failure, dropping `staged` removes the temporary file
        write(&mut file).map_err(|problem| Error::Write {
            path: path.to_path_buf(),
            problem: problem.to_string(),
        })?;
        Ok(staged)
    }

    /// Where the output goes.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        // gone already once committed
        let _ = fs::remove_file(&self.tmp);
        interrupt::unregister_temporary(&self.tmp);
    }
}

/// Moves every staged output under its name, all or none: the outputs of
/// one command (an EXR and its PNG preview) appear together, or the
/// directory is left as it was. A destination that is a directory (or
/// otherwise cannot be replaced by a file) fails the whole commit before
/// anything moves. Files already under the names are set aside first and
/// put back if a later rename fails; each rename on its own is atomic.
///
/// After a signal ([`interrupt::requested`]) nothing is committed: the
/// temporary files are removed and the error is [`Error::Interrupted`].
pub fn commit_all(files: Vec<Staged>) -> Result<(), Error> {
    if let Some(sig) = interrupt::requested() {
        return Err(Error::Interrupted(sig));
    }
    commit_even_if_interrupted(files)
}

/// [`commit_all`] even after a signal: for the one output an interrupted
/// command is meant to leave, the record of its finished work (a render's
/// finished samples, `crate::farm`). A second signal still removes the
/// temporary files and exits.
pub fn commit_even_if_interrupted(files: Vec<Staged>) -> Result<(), Error> {
    let write_err = |path: &Path, problem: String| Error::Write {
        path: path.to_path_buf(),
        problem,
    };
    for f in &files {
        if let Ok(meta) = fs::symlink_metadata(&f.path) {
            if meta.is_dir() {
                return Err(write_err(&f.path, "it is a directory".into()));
            }
        }
    }
    // (destination, where its previous file was set aside)
    let mut done: Vec<(&Path, Option<PathBuf>)> = Vec::new();
    let last = files.len().saturating_sub(1);
    for (i, f) in files.iter().enumerate() {
        // The last rename needs no way back: if it fails, it changed nothing.
        let mut aside = None;
        if i < last && fs::symlink_metadata(&f.path).is_ok() {
            let old = old_path(&f.path);
            if let Err(e) = fs::rename(&f.path, &old) {
                roll_back(done);
                return Err(write_err(&f.path, e.to_string()));
            }
            aside = Some(old);
        }
        if let Err(e) = fs::rename(&f.tmp, &f.path) {
            if let Some(old) = &aside {
                let _ = fs::rename(old, &f.path);
            }
            roll_back(done);
            return Err(write_err(&f.path, e.to_string()));
        }
        done.push((&f.path, aside));
    }
    for (_, aside) in done {
        if let Some(old) = aside {
            let _ = fs::remove_file(old);
        }
    }
    Ok(())
}

/// Undoes committed renames, last first: removes the new file and puts the
/// previous one back.
fn roll_back(done: Vec<(&Path, Option<PathBuf>)>) {
    for (path, aside) in done.into_iter().rev() {
        let _ = fs::remove_file(path);
        if let Some(old) = aside {
            let _ = fs::rename(old, path);
        }
    }
}

/// [`write_atomically`] under the name the tools (plots, study, bench) call
/// it by: a failed write is an [`Error::Write`] (`cannot write PATH: …`),
/// a pending signal an [`Error::Interrupted`].
pub fn atomic_write<E: Display>(
    path: &Path,
    write: impl FnOnce(&mut fs::File) -> Result<(), E>,
) -> Result<(), Error> {
    write_atomically(path, write)
}

/// The temporary file of `path`: `.lu<key>.<pid>.tmp` ([`stale::key`]),
/// at most 26 bytes whatever the output's name, so any name that fits the
/// file system has a temporary name that fits too.
fn temp_path(path: &Path) -> PathBuf {
    temporary_path(path, std::process::id())
}

/// The temporary file process `pid` writes `path` to:
/// `.lu<key>.<pid>.tmp` (see [`stale`]).
pub fn temporary_path(path: &Path, pid: u32) -> PathBuf {
    path.with_file_name(format!(".lu{}.{pid}.tmp", stale::key(path)))
}

/// Where [`commit_all`] sets a file it replaces aside until all renames
/// succeeded: `.lu<key>.<pid>.old.tmp`.
fn old_path(path: &Path) -> PathBuf {
    set_aside_path(path, std::process::id())
}

/// Where process `pid` sets the file under `path` aside while it commits:
/// `.lu<key>.<pid>.old.tmp`.
pub fn set_aside_path(path: &Path, pid: u32) -> PathBuf {
    path.with_file_name(format!(".lu{}.{pid}.old.tmp", stale::key(path)))
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
    fn a_failed_commit_puts_every_output_back_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("a.png"));
        fs::write(&a, b"old a").unwrap();
        let write = |text: &'static [u8]| {
            move |tmp: &mut fs::File| {
                std::io::Write::write_all(tmp, text).map_err(|e| e.to_string())
            }
        };
        let sa = Staged::write(&a, write(b"new a")).unwrap();
        let sb = Staged::write(&b, write(b"new b")).unwrap();
        // the second rename fails after the first succeeded
        fs::remove_file(&sb.tmp).unwrap();
        let e = commit_all(vec![sa, sb]).unwrap_err();
        assert!(e.to_string().contains("a.png"), "{e}");
        assert_eq!(fs::read(&a).unwrap(), b"old a");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
        // a destination that is a directory fails before anything moves
        fs::create_dir(&b).unwrap();
        let sa = Staged::write(&a, write(b"new a")).unwrap();
        let sb = Staged::write(&b, write(b"new b")).unwrap();
        let e = commit_all(vec![sa, sb]).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
        assert_eq!(fs::read(&a).unwrap(), b"old a");
        assert!(b.is_dir());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
        // and when all succeed, both are replaced and nothing else remains
        fs::remove_dir(&b).unwrap();
        let sa = Staged::write(&a, write(b"new a")).unwrap();
        let sb = Staged::write(&b, write(b"new b")).unwrap();
        commit_all(vec![sa, sb]).unwrap();
        assert_eq!(fs::read(&a).unwrap(), b"new a");
        assert_eq!(fs::read(&b).unwrap(), b"new b");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn failed_write_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("missing-dir").join("a.exr");
        assert!(Film::new(2, 2).write_exr(&p).is_err());
        assert!(!p.exists());
        let p2 = dir.path().join("b.exr");
        let r = atomic_write(&p2, |tmp| {
            std::io::Write::write_all(tmp, b"partial").unwrap();
            Err("simulated failure".to_string())
        });
        assert!(r.is_err() && !p2.exists());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
