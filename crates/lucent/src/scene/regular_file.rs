//! Reading the user's input files (the scene, its OBJ meshes) only when
//! they are regular files, so that a FIFO or a device named as a scene fails
//! at once instead of blocking the process; and text that is not UTF-8
//! reported at its line and column rather than as a bare "stream did not
//! contain valid UTF-8".

use std::fmt;
use std::path::Path;

/// Reads a text file that must be a regular file (symlinks followed): a
/// FIFO, a character device such as `/dev/zero` or a socket would block or
/// never end, and a directory cannot be read, so each is refused before it
/// is opened, by what it is ("not a regular file: it is a FIFO").
///
/// Text that is not UTF-8 fails with `NotUtf8`'s message (line, column,
/// byte); a leading UTF-8 byte-order mark is dropped.
pub fn read_regular_file(path: &Path, max_bytes: u64) -> std::io::Result<String> {
    let mut text = utf8_text(read_regular_bytes(path, max_bytes)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string()))?;
    // a byte-order mark is not text (it would hide the first statement)
    if text.starts_with('\u{feff}') {
        text.replace_range(..'\u{feff}'.len_utf8(), "");
    }
    Ok(text)
}

/// The bytes of a file that must be a regular file (see
/// [`read_regular_file`]) of at most `max_bytes`: a larger one is refused
/// before it is read, so its size (and what parsing it would allocate) is
/// bounded.
pub(crate) fn read_regular_bytes(path: &Path, max_bytes: u64) -> std::io::Result<Vec<u8>> {
    let (file, len) = open_regular(path)?;
    if len > max_bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "the file is {len} bytes, more than the {max_bytes} supported (see \"Supported \
                 ranges\" in docs/scene-format.md)"
            ),
        ));
    }
    // take no more than the bound even if the file grows meanwhile
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut std::io::Read::take(file, max_bytes + 1), &mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("the file grew past the {max_bytes} bytes supported while being read"),
        ));
    }
    Ok(bytes)
}

/// Where text stops being UTF-8: the 1-based line and column (in
/// characters) of the first invalid byte, and that byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NotUtf8 {
    pub line: usize,
    pub column: usize,
    pub byte: u8,
}

impl fmt::Display for NotUtf8 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "not UTF-8 text: byte {:#04x} at line {}, column {} is not valid UTF-8",
            self.byte, self.line, self.column
        )
    }
}

/// `bytes` as a `String`, or where they stop being UTF-8.
pub(crate) fn utf8_text(bytes: Vec<u8>) -> Result<String, NotUtf8> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        // the valid prefix is UTF-8: count its lines and characters
        let valid = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
        let line_start = valid.rfind('\n').map_or(0, |i| i + 1);
        NotUtf8 {
            line: valid.matches('\n').count() + 1,
            column: valid[line_start..].chars().count() + 1,
            byte: bytes[at],
        }
    })
}

/// Opens a file for reading only if it is a regular file (symlinks
/// followed), with its length. The file is opened without blocking (a FIFO
/// with no writer opens at once) and checked by what was opened, so a file
/// swapped after a check cannot slip through; a FIFO, a device, a socket or
/// a directory is refused by what it is.
pub fn open_regular(path: &Path) -> std::io::Result<(std::fs::File, u64)> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        // no effect on a regular file's reads
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("not a regular file: it is {}", file_kind(&meta.file_type())),
        ));
    }
    Ok((file, meta.len()))
}

/// What a file that is not a regular file is, for messages.
fn file_kind(t: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "a special file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_utf8_is_located_by_line_and_column() {
        assert_eq!(
            utf8_text(b"a\n\xce\xb7 = 1".to_vec()).unwrap(),
            "a\n\u{3b7} = 1"
        );
        let e = utf8_text(b"a = 1\n# \xce\xb7 \xff\n".to_vec()).unwrap_err();
        assert_eq!(
            e,
            NotUtf8 {
                line: 2,
                column: 5,
                byte: 0xff
            }
        );
        assert_eq!(
            e.to_string(),
            "not UTF-8 text: byte 0xff at line 2, column 5 is not valid UTF-8"
        );
        // a sequence cut short at the end of the file
        let e = utf8_text(b"x\xe2\x82".to_vec()).unwrap_err();
        assert_eq!((e.line, e.column, e.byte), (1, 2, 0xe2));
    }
}
