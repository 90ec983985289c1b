//! Checkpoints: the finished samples saved as a part beside the output,
//! atomically, for `--resume` (docs/farm.md).

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::error::Error;
use crate::farm::part::{self, Header};
use crate::film::Sums;

/// Where a render keeps its finished samples for `--resume` (at a signal,
/// at checkpoints): `OUT.partial.exr` beside `OUT.exr`.
pub(crate) fn checkpoint_path(output: &Path) -> PathBuf {
    output.with_extension("partial.exr")
}

/// Saves the sums at the end of a pass once `every` seconds passed since
/// the last save, unless the render is about to finish (at `end`).
pub(crate) struct Checkpoints<'a> {
    pub path: &'a Path,
    pub every: Option<f64>,
    pub end: u32,
    pub last: Instant,
}

impl Checkpoints<'_> {
    /// Called after every pass with its sums and their part header.
    pub(crate) fn after_pass(&mut self, sums: &Sums, header: &Header) -> Result<(), Error> {
        match self.every {
            Some(every) if self.last.elapsed().as_secs_f64() >= every && sums.done < self.end => {
                crate::film::commit_all(vec![part::stage(self.path, header, sums)?])?;
                self.last = Instant::now();
                Ok(())
            }
            _ => Ok(()),
        }
    }
}

/// Removes what was kept to resume from (the finished output replaces it)
/// and a checkpoint a killed process was writing.
pub fn clean(path: &Path) {
    if path.is_file() {
        let _ = std::fs::remove_file(path);
    }
    crate::film::stale::clean(path);
}
