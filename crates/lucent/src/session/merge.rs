//! A frame merged from its parts (`lucent merge`, docs/farm.md) and
//! written as one EXR with its preview.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::output::{check_exr_output, check_not_an_input};
use crate::error::Error;
use crate::farm::merge::merge;
use crate::film::exr_attributes::FrameHeader;
use crate::film::exr_layers::{self, OutputOptions, Preview};

/// What a merge made: the frame's size and samples, and how long it took.
#[derive(Clone, Debug)]
pub struct MergedFrame {
    pub parts: usize,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seconds: f64,
    /// Non-finite samples the parts discarded.
    pub nonfinite: u64,
}

/// Merges `parts` into the frame `output` (EXR, with the preview
/// `preview`); `mixed_backends` lets parts rendered on different
/// ray-query backends merge (the frame names each).
pub fn merge_parts(
    parts: &[PathBuf],
    output: &Path,
    preview: Preview,
    mixed_backends: bool,
) -> Result<MergedFrame, Error> {
    check_exr_output(output)?;
    let preview_path = crate::film::preview_path(output);
    check_not_an_input(&[output, &preview_path], parts)?;
    let start = Instant::now();
    let m = merge(parts, mixed_backends)?;
    // what the parts say of the render, as a single render's frame says it
    let header = FrameHeader {
        spp: Some(m.identity.spp),
        seed: Some(m.identity.seed),
        date: Some(super::provenance::date_now()),
        ..m.frame.clone()
    };
    let out = OutputOptions {
        preview: Some(preview),
        ..m.output
    };
    crate::memory::enter(crate::memory::Phase::Writing);
    exr_layers::write_frame(output, &m.film, &m.layers, &m.coverage, &header, &out)?;
    Ok(MergedFrame {
        parts: parts.len(),
        width: m.film.width,
        height: m.film.height,
        spp: m.identity.spp,
        seconds: start.elapsed().as_secs_f64(),
        nonfinite: m.counters.nonfinite,
    })
}

impl MergedFrame {
    /// One line: where the frame went, from how many parts, its size,
    /// samples and time.
    pub fn summary(&self, output: &Path) -> String {
        format!(
            "{}: {} parts merged, {}×{} at {} spp, {:.2} s{}",
            output.display(),
            self.parts,
            self.width,
            self.height,
            self.spp,
            self.seconds,
            if self.nonfinite > 0 {
                format!(", {} non-finite samples discarded", self.nonfinite)
            } else {
                String::new()
            }
        )
    }
}
