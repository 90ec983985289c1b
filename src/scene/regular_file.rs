//! Reading the user's input files (the scene, its OBJ meshes) only when
//! they are regular files, so that a FIFO or a device named as a scene fails
//! at once instead of blocking the process.

use std::path::Path;

/// Reads a text file that must be a regular file (symlinks followed): a
/// FIFO, a character device such as `/dev/zero` or a socket would block or
/// never end, and a directory cannot be read, so each is refused before it
/// is opened, by what it is ("not a regular file: it is a FIFO").
pub fn read_regular_file(path: &Path) -> std::io::Result<String> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("not a regular file: it is {}", file_kind(&meta.file_type())),
        ));
    }
    std::fs::read_to_string(path)
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
