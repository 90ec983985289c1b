//! Whose checkpoint `OUT.partial.exr` is: a render replaces or removes the
//! checkpoint beside its output only if it is a part of this very render
//! (same identity, region and requested samples) or the part it resumes
//! from; another render's finished samples, or a file that is not a part,
//! are refused by name and kept (docs/farm.md, "Checkpoints").

use std::ops::Range;
use std::path::Path;

use crate::error::{Error, InputError};
use crate::farm::part::{Identity, PartFile};
use crate::film::region::Region;

/// What a checkpoint of this render says of itself.
pub(crate) struct ThisRender<'a> {
    pub identity: &'a Identity,
    pub region: Region,
    pub requested: &'a Range<u32>,
}

impl ThisRender<'_> {
    /// Why the file at `keep` is not this render's checkpoint, if it is
    /// not (None: it is, or nothing is there).
    fn foreign(&self, keep: &Path) -> Option<String> {
        std::fs::symlink_metadata(keep).ok()?;
        let h = match PartFile::open(keep) {
            Ok(f) => f.header,
            Err(e) => return Some(format!("it is not a part lucent can read ({e})")),
        };
        if let Some((field, theirs, _)) = h.identity.difference(self.identity) {
            return Some(format!(
                "it is a part of another render ({field} `{theirs}`)"
            ));
        }
        if h.region != self.region || h.requested != *self.requested {
            return Some(format!(
                "it is a part of other pixels or samples ({}, samples {}..{})",
                h.region, h.requested.start, h.requested.end
            ));
        }
        None
    }

    /// Refuses to start a render whose checkpoint path holds another
    /// render's part or a file that is not one (`resume`: the part this
    /// render resumes from, its own).
    pub fn check(&self, keep: &Path, resume: Option<&Path>) -> Result<(), Error> {
        if resume.is_some_and(|r| same_file(r, keep)) {
            return Ok(());
        }
        match self.foreign(keep) {
            None => Ok(()),
            Some(why) => Err(InputError::new(
                keep,
                format!(
                    "this render keeps its checkpoint here, but {why}: it was left as it \
                     is; move it away, or --resume it with the render that wrote it"
                ),
            )
            .into()),
        }
    }

    /// Whether the file at `keep` is this render's checkpoint (to remove
    /// once the output is committed).
    pub fn owns(&self, keep: &Path) -> bool {
        std::fs::symlink_metadata(keep).is_ok() && self.foreign(keep).is_none()
    }
}

/// Whether `a` and `b` name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
