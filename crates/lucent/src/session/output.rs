//! Where a render or a merge writes: an `.exr` path (not ending in `/`)
//! in an existing directory that is not append-only, and not one of the
//! command's inputs.

use std::path::Path;

use crate::error::Error;

/// An output path that ends in `.exr` and lies in an existing directory.
pub fn check_exr_output(output: &Path) -> Result<(), Error> {
    if output.as_os_str().as_encoded_bytes().ends_with(b"/") {
        return Err(Error::Argument {
            argument: format!("output {}", output.display()),
            problem: "expected a file path ending in .exr, not a directory path ending in /".into(),
        });
    }
    if output
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        != Some("exr".into())
    {
        return Err(Error::Argument {
            argument: format!("output {}", output.display()),
            problem: "expected a path ending in .exr".into(),
        });
    }
    let dir = output
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return Err(Error::Argument {
            argument: format!("output directory {}", dir.display()),
            problem: "does not exist".into(),
        });
    }
    if append_only(dir) {
        return Err(Error::Argument {
            argument: format!("output directory {}", dir.display()),
            problem: "is append-only (chattr +a): an output written there could not be \
                      renamed into place, nor its temporary file removed"
                .into(),
        });
    }
    Ok(())
}

/// Whether the directory `dir` has the append-only attribute (Linux; false
/// where it cannot be read).
fn append_only(dir: &Path) -> bool {
    #[cfg(target_os = "linux")]
    {
        use std::os::fd::AsRawFd;
        /// FS_APPEND_FL of linux/fs.h.
        const APPEND: libc::c_long = 0x20;
        let Ok(d) = std::fs::File::open(dir) else {
            return false;
        };
        let mut flags: libc::c_long = 0;
        // SAFETY: `d` is an open descriptor for the call's duration, and
        // FS_IOC_GETFLAGS writes one long to the pointer it is given.
        let r = unsafe { libc::ioctl(d.as_raw_fd(), libc::FS_IOC_GETFLAGS, &mut flags) };
        r == 0 && flags & APPEND != 0
    }
    #[cfg(not(target_os = "linux"))]
    {
        let _ = dir;
        false
    }
}

/// Refuses an output (or its preview) that is one of `inputs`: writing it
/// would replace an input the command reads.
pub fn check_not_an_input(outputs: &[&Path], inputs: &[std::path::PathBuf]) -> Result<(), Error> {
    for out in outputs {
        let Ok(o) = std::fs::metadata(out) else {
            continue;
        };
        for input in inputs {
            if std::fs::metadata(input).is_ok_and(|i| same_file(&o, &i)) {
                return Err(Error::Argument {
                    argument: format!("output {}", out.display()),
                    problem: format!("is the input {}: it would be overwritten", input.display()),
                });
            }
        }
    }
    Ok(())
}

/// Whether two files' metadata are of the same file.
fn same_file(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        a.dev() == b.dev() && a.ino() == b.ino()
    }
    #[cfg(not(unix))]
    {
        let _ = (a, b);
        false
    }
}
