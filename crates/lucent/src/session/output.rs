//! Where a render or a merge writes: an `.exr` path in an existing
//! directory.

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
    Ok(())
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
