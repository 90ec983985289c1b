//! Resuming: the sums of a part a stopped render left, checked to be a
//! start of the same render (docs/farm.md).

use std::path::Path;

use crate::error::{Error, InputError};
use crate::farm::part::{self, Identity};
use crate::film::Sums;
use crate::render::Job;

/// The sums of the part at `path`, checked to be a start of `job` of the
/// frame `identity`: its header is checked against this render before its
/// pixels are read, so what reading sizes comes from this render.
pub fn resumable(path: &Path, identity: &Identity, job: &Job) -> Result<Sums, Error> {
    let file = part::PartFile::open(path)?;
    let h = file.header.clone();
    let located = |field: &str, problem: String| -> Error {
        InputError::new(path, problem).in_field(field).into()
    };
    if let Some((field, theirs, ours)) = h.identity.difference(identity) {
        return Err(located(
            field,
            format!("`{theirs}`, but this render has `{ours}`: not a part of this render"),
        ));
    }
    if h.region != job.region {
        return Err(located(
            "lucent.region",
            format!("{}, but this render covers {}", h.region, job.region),
        ));
    }
    if h.samples.start != job.samples.start || h.samples.end > job.samples.end {
        return Err(located(
            "lucent.samples",
            format!(
                "{}..{}, not a start of this render's samples {}..{}",
                h.samples.start, h.samples.end, job.samples.start, job.samples.end
            ),
        ));
    }
    Ok(part::read_pixels(path, file)?.1)
}
