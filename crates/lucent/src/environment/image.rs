//! Reading an HDR image for the environment: OpenEXR (the first RGB(A)
//! layer, any channel type) or Radiance `.hdr`, chosen by the file's
//! extension. Refused with the reason, for the scene loader to report:
//! a file that cannot be read or decoded, another format, an image larger
//! than [`MAX_TEXELS`] (checked from the header, before decoding), and a
//! negative or non-finite texel (named by its column, row and channel).

use std::path::Path;

use crate::geometry::Vec3;

/// The most texels an environment image may have: 8192 × 4096 (about
/// 400 MB of RGB floats and 130 MB of distribution).
pub const MAX_TEXELS: u64 = 1 << 25;

/// An RGB float image, row-major from the top row.
#[derive(Clone, Debug)]
pub struct Texels {
    pub width: u32,
    pub height: u32,
    pub data: Vec<Vec3>,
}

/// Why an image cannot be used.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ImageError {
    #[error("cannot read it: {0}")]
    Unreadable(String),
    #[error(
        "unsupported image format \"{0}\": expected an OpenEXR (.exr) or Radiance (.hdr) file"
    )]
    Unsupported(String),
    #[error(
        "the image is {width}×{height} = {} texels, more than the {MAX_TEXELS} (8192×4096) supported",
        *width as u64 * *height as u64
    )]
    TooLarge { width: u32, height: u32 },
    #[error("the image is empty ({width}×{height})")]
    Empty { width: u32, height: u32 },
    #[error("texel (column {x}, row {y}) has {channel} = {value}: texels must be finite")]
    BadTexel {
        x: u32,
        y: u32,
        channel: &'static str,
        value: f32,
    },
}

/// Reads the image at `path` and checks every texel.
pub fn read(path: &Path) -> Result<Texels, ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    let mut texels = match ext.as_str() {
        "exr" => read_exr(path)?,
        "hdr" => read_hdr(path)?,
        _ => return Err(ImageError::Unsupported(ext)),
    };
    check(&mut texels)?;
    Ok(texels)
}

fn size_ok(width: u32, height: u32) -> Result<(), ImageError> {
    if width == 0 || height == 0 {
        return Err(ImageError::Empty { width, height });
    }
    if width as u64 * height as u64 > MAX_TEXELS {
        return Err(ImageError::TooLarge { width, height });
    }
    Ok(())
}

fn read_exr(path: &Path) -> Result<Texels, ImageError> {
    use exr::prelude::*;
    let unreadable = |e: exr::error::Error| ImageError::Unreadable(e.to_string());
    let meta = MetaData::read_from_file(path, false).map_err(unreadable)?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| ImageError::Unreadable("no image in the file".into()))?;
    let size = header.layer_size;
    size_ok(size.width() as u32, size.height() as u32)?;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| Texels {
            width: res.width() as u32,
            height: res.height() as u32,
            data: vec![Vec3::ZERO; res.width() * res.height()],
        },
        |t: &mut Texels, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            t.data[pos.y() * t.width as usize + pos.x()] = Vec3::new(r, g, b)
        },
    )
    .map_err(unreadable)?;
    Ok(image.layer_data.channel_data.pixels)
}

fn read_hdr(path: &Path) -> Result<Texels, ImageError> {
    use image::codecs::hdr::HdrDecoder;
    let unreadable = |e: &dyn std::fmt::Display| ImageError::Unreadable(e.to_string());
    let file = std::fs::File::open(path).map_err(|e| unreadable(&e))?;
    let decoder = HdrDecoder::new(std::io::BufReader::new(file)).map_err(|e| unreadable(&e))?;
    let meta = decoder.metadata();
    size_ok(meta.width, meta.height)?;
    let img = image::DynamicImage::from_decoder(decoder)
        .map_err(|e| unreadable(&e))?
        .into_rgb32f();
    let (width, height) = img.dimensions();
    let data = img.pixels().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    Ok(Texels {
        width,
        height,
        data,
    })
}

/// Refuses the first non-finite texel; clamps negative channels to 0 (the
/// ringing of lossy compression such as DWAB: light is never negative).
fn check(t: &mut Texels) -> Result<(), ImageError> {
    let width = t.width as usize;
    for (i, c) in t.data.iter_mut().enumerate() {
        for (channel, value) in [("R", c.x), ("G", c.y), ("B", c.z)] {
            if !value.is_finite() {
                return Err(ImageError::BadTexel {
                    x: (i % width) as u32,
                    y: (i / width) as u32,
                    channel,
                    value,
                });
            }
        }
        *c = c.max(Vec3::ZERO);
    }
    Ok(())
}
