//! Where a render or a merge writes: an `.exr` path in an existing
//! directory.

use std::path::Path;

use crate::error::Error;

/// An output path that ends in `.exr` and lies in an existing directory.
pub fn check_exr_output(output: &Path) -> Result<(), Error> {
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
