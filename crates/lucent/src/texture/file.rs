//! Reading a texture image: PNG (8 or 16 bits) or JPEG (8 bits), grey or
//! colour, alpha ignored, decoded from sRGB or read as stored per the
//! texture's colour space; or a floating-point OpenEXR / Radiance `.hdr` image (linear by
//! definition: read as stored, [`crate::environment::image`]). Refused with
//! the reason, for the scene loader to report: another format, an image
//! larger than [`MAX_TEXELS`] (from the header, before decoding), a file
//! that cannot be decoded, a non-finite texel.

use std::path::Path;

use crate::environment::image::{self as hdr_image, ImageError, Texels};
use crate::geometry::Vec3;

use super::{srgb_to_linear, ColorSpace};

/// The most texels a texture may have (the environment image's limit).
pub const MAX_TEXELS: u64 = hdr_image::MAX_TEXELS;

/// The image formats a texture may be, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Jpeg,
    /// OpenEXR or Radiance `.hdr`.
    Float,
}

/// Why a texture file cannot be used.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum TextureError {
    #[error(
        "unsupported texture format \"{0}\": expected PNG (.png), JPEG (.jpg, .jpeg), OpenEXR \
         (.exr) or Radiance (.hdr)"
    )]
    Unsupported(String),
    #[error(transparent)]
    Image(#[from] ImageError),
}

/// The format of `path` by its extension, or the refusal naming it.
pub fn format_of(path: &Path) -> Result<Format, TextureError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "png" => Ok(Format::Png),
        "jpg" | "jpeg" => Ok(Format::Jpeg),
        "exr" | "hdr" => Ok(Format::Float),
        _ => Err(TextureError::Unsupported(ext)),
    }
}

/// Decodes the PNG or JPEG file's `bytes` (`format`) into linear texels.
pub fn read_integer_image(
    bytes: &[u8],
    format: Format,
    space: ColorSpace,
) -> Result<Texels, ImageError> {
    let unreadable = |e: &dyn std::fmt::Display| ImageError::Unreadable(e.to_string());
    let cursor = std::io::Cursor::new(bytes);
    match format {
        Format::Png => decode(
            image::codecs::png::PngDecoder::new(cursor).map_err(|e| unreadable(&e))?,
            space,
        ),
        Format::Jpeg => decode(
            image::codecs::jpeg::JpegDecoder::new(cursor).map_err(|e| unreadable(&e))?,
            space,
        ),
        Format::Float => Err(ImageError::Unreadable("not an 8- or 16-bit image".into())),
    }
}

/// The texels of `decoder`'s image, its size checked before decoding.
fn decode(decoder: impl image::ImageDecoder, space: ColorSpace) -> Result<Texels, ImageError> {
    let unreadable = |e: &dyn std::fmt::Display| ImageError::Unreadable(e.to_string());
    let (width, height) = decoder.dimensions();
    if width == 0 || height == 0 {
        return Err(ImageError::Empty { width, height });
    }
    if width as u64 * height as u64 > MAX_TEXELS {
        return Err(ImageError::TooLarge { width, height });
    }
    let img = image::DynamicImage::from_decoder(decoder)
        .map_err(|e| unreadable(&e))?
        .into_rgb32f();
    let decode = |c: f32| match space {
        ColorSpace::Srgb => srgb_to_linear(c),
        ColorSpace::Linear => c,
    };
    let data = img
        .pixels()
        .map(|p| Vec3::new(decode(p[0]), decode(p[1]), decode(p[2])))
        .collect();
    Ok(Texels {
        width,
        height,
        data,
    })
}

/// Reads the OpenEXR or `.hdr` image at `path` (checked: finite texels).
pub fn read_float(path: &Path) -> Result<Texels, ImageError> {
    hdr_image::read(path)
}
