//! The study directory's files read as untrusted input: its results, key
//! and metadata text and its cached images are read only if they are
//! regular files (a FIFO or a device is refused at once, never read),
//! text up to [`MAX_TEXT_BYTES`], an image only at the size the study
//! renders (docs/accuracy.md, "The study").

use std::path::Path;

use lucent::film::Film;
use lucent::scene::regular_file::{open_regular, read_regular_file};

/// The largest study text file read (results.csv of a long study is a few
/// hundred kB).
pub(crate) const MAX_TEXT_BYTES: u64 = 64 << 20;

/// The text of the file at `path`; `Ok(None)` if nothing is there.
pub(crate) fn read_text(path: &Path) -> std::io::Result<Option<String>> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    read_regular_file(path, MAX_TEXT_BYTES).map(Some)
}

/// The cached image at `path` if it is a `width`×`height` image; `Ok(None)`
/// if nothing is there or it has another size.
pub(crate) fn read_film(path: &Path, width: u32, height: u32) -> Result<Option<Film>, String> {
    if std::fs::symlink_metadata(path).is_err() {
        return Ok(None);
    }
    let (file, _) = open_regular(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Film::read_exr_of_size(file, path, width, height).map_err(|e| e.to_string())
}
