//! `lucent merge`: adds parts into the frame they split.
//!
//! Every check runs on the headers before any pixel is read, and nothing
//! is written unless every part was read whole: the parts must share one
//! [`Identity`] (lucent version, scene hash, seed, spp, options, frame)
//! and cover the frame's pixels × sample indices exactly once
//! ([`super::cover`]). Then each part's integer sums are added into the
//! frame's (exactly: integer addition, in any order), and the frame is the
//! sums divided by spp, the same [`crate::film::Sums::film`] a
//! single-machine render ends with — so the merged frame is bitwise the
//! uncut render. The passes' sums merge the same way (integer sums added,
//! nearest hits by their unique (Z, sample) minimum, ID coverage by adding
//! sample counts), and their layers and Cryptomatte come from the merged
//! sums by [`crate::film::Sums::layers`], as in the uncut render.

use std::path::PathBuf;

use super::cover::{self, CoverError, Piece};
use super::header::bad;
use super::part::{self, Header, Identity};
use crate::error::Error;
use crate::film::exr_attributes::FrameHeader;
use crate::film::exr_layers::OutputOptions;
use crate::film::layers::{Coverage, Layer};
use crate::film::region::Region;
use crate::film::{Film, Sums};
use crate::stats::Counters;

/// A merged frame and what its parts say about it.
#[derive(Debug)]
pub struct Merged {
    pub film: Film,
    /// The passes, as the uncut render gives them.
    pub layers: Vec<Layer>,
    pub coverage: Vec<Coverage>,
    /// How the frame is to be written (the parts' `lucent.output`; no
    /// preview).
    pub output: OutputOptions,
    pub identity: Identity,
    /// Summed over the parts.
    pub counters: Counters,
    /// What the frame's header says of the render: the parts' (every part's
    /// host; with mixed backends, each backend).
    pub frame: FrameHeader,
}

/// Checks that the parts' headers belong together and cover the frame
/// exactly once; the identity they share. With `mixed_backends` parts
/// rendered on different ray-query backends belong together too (the
/// backends answer alike, tests/accel; the frame then names each).
pub fn check(headers: &[(PathBuf, Header)], mixed_backends: bool) -> Result<Identity, Error> {
    let id = shared_identity(headers, mixed_backends)?;
    let pieces: Vec<Piece> = headers
        .iter()
        .map(|(_, h)| Piece {
            region: h.region,
            samples: h.samples.clone(),
        })
        .collect();
    let frame = Region::full(id.frame.0, id.frame.1);
    match cover::check(&pieces, frame, id.spp) {
        Ok(()) => Ok(id),
        Err(e) => Err(cover_error(headers, &pieces, &id, e)),
    }
}

/// The identity every part has, or an error naming the first part that
/// differs from the first and the field that does.
fn shared_identity(headers: &[(PathBuf, Header)], mixed_backends: bool) -> Result<Identity, Error> {
    let Some((first_path, first)) = headers.first() else {
        return Err(Error::Argument {
            argument: "merge".into(),
            problem: "no parts given".into(),
        });
    };
    let compared = |id: &Identity| match mixed_backends {
        true => id.without_backend(),
        false => id.clone(),
    };
    for (p, h) in &headers[1..] {
        if let Some((field, a, b)) = compared(&h.identity).difference(&compared(&first.identity)) {
            let what = match field {
                "lucent.options" if backend(&a) != backend(&b) => {
                    "the parts were rendered on different ray-query backends \
                     (--mixed-backends merges them, and the frame says so)"
                }
                "lucent.passes" => "the parts carry different passes",
                "lucent.names" => "the parts' passes name different groups or IDs",
                "lucent.output" => "the parts ask for different frame file options",
                _ => "the parts are of different frames",
            };
            let show = |v: &str| {
                if v.is_empty() {
                    "none".to_string()
                } else {
                    format!("`{v}`")
                }
            };
            let (a, first, b) = (show(&a), first_path.display(), show(&b));
            let problem = format!("{a}, but {first} has {b}: {what}");
            return Err(bad(p, Some(field), problem));
        }
    }
    Ok(first.identity.clone())
}

/// The `accel=` token of identity options.
fn backend(options: &str) -> Option<&str> {
    options.split(' ').find(|t| t.starts_with("accel="))
}

/// The frame header the parts' headers say: the same in every part but
/// for the host, the scene's path, the build and (with `mixed_backends`)
/// the backend; the merged one lists every host, build and backend (the
/// first part's scene path).
fn merged_frame(headers: &[(PathBuf, Header)], mixed_backends: bool) -> Result<FrameHeader, Error> {
    let key = |f: &FrameHeader| {
        // where the scene was and which build ran may differ by machine
        let mut k = FrameHeader {
            hosts: Vec::new(),
            scene_path: None,
            build: None,
            ..f.clone()
        };
        if mixed_backends {
            (k.backend, k.backend_version) = (None, None);
        }
        k
    };
    let first = &headers[0].1.frame;
    let mut frame = first.clone();
    for (p, h) in headers {
        let f = &h.frame;
        if key(f) != key(first) {
            let problem = format!(
                "says a different render than {} (scene, camera, plan or sampling)",
                headers[0].0.display()
            );
            return Err(bad(p, Some("lucent.provenance"), problem));
        }
        frame.hosts.extend(f.hosts.iter().cloned());
        for (all, one) in [
            (&mut frame.build, &f.build),
            (&mut frame.backend, &f.backend),
            (&mut frame.backend_version, &f.backend_version),
        ] {
            if let (Some(all), Some(one)) = (all.as_mut(), one) {
                if !all.split(", ").any(|x| x == one) {
                    all.push_str(", ");
                    all.push_str(one);
                }
            }
        }
    }
    frame.hosts.sort();
    frame.hosts.dedup();
    Ok(frame)
}

/// The error of parts (`headers`, covering `pieces`) of the frame `id`
/// that do not cover it exactly once.
fn cover_error(
    headers: &[(PathBuf, Header)],
    pieces: &[Piece],
    id: &Identity,
    e: CoverError,
) -> Error {
    let show = |r: &Region, s: &std::ops::Range<u32>| {
        format!(
            "pixels x {}..{}, y {}..{}, samples {}..{}",
            r.x0, r.x1, r.y0, r.y1, s.start, s.end
        )
    };
    match e {
        CoverError::Outside(i) => bad(
            &headers[i].0,
            Some("lucent.region"),
            format!(
                "{} lies outside the {}×{} frame at {} spp",
                show(&pieces[i].region, &pieces[i].samples),
                id.frame.0,
                id.frame.1,
                id.spp
            ),
        ),
        CoverError::Overlap {
            a,
            b,
            region,
            samples,
        } => bad(
            &headers[b].0,
            None,
            format!(
                "overlaps {}: both cover {}",
                headers[a].0.display(),
                show(&region, &samples)
            ),
        ),
        CoverError::Gap { region, samples } => {
            // name the part that stopped short, if one did
            let short = headers
                .iter()
                .find(|(_, h)| {
                    h.samples.end < h.requested.end && h.region.intersection(&region).is_some()
                })
                .map(|(p, h)| {
                    format!(
                        " ({} holds samples {}..{} of the {}..{} it was asked for: resume it)",
                        p.display(),
                        h.samples.start,
                        h.samples.end,
                        h.requested.start,
                        h.requested.end
                    )
                })
                .unwrap_or_default();
            Error::Input(format!(
                "merge: the parts leave a gap: no part covers {}{short}",
                show(&region, &samples)
            ))
        }
    }
}

/// Reads, checks and merges the parts at `paths` (`mixed_backends`: see
/// [`check`]).
pub fn merge(paths: &[PathBuf], mixed_backends: bool) -> Result<Merged, Error> {
    crate::memory::enter(crate::memory::Phase::ReadingParts);
    let headers = paths
        .iter()
        .map(|p| Ok((p.clone(), part::read_header(p)?)))
        .collect::<Result<Vec<_>, Error>>()?;
    let identity = check(&headers, mixed_backends)?;
    let frame_header = merged_frame(&headers, mixed_backends)?;
    let frame = Region::full(identity.frame.0, identity.frame.1);
    let (first, _) = &headers[0];
    let layout = part::layout_of(&identity).map_err(|e| e.at(first))?;
    let output = part::parse_output(&identity.output).ok_or_else(|| {
        bad(
            first,
            Some("lucent.output"),
            format!("`{}` is not the frame's file options", identity.output),
        )
    })?;
    let mut sums = Sums::with_passes(frame, 0, layout.as_ref())?;
    sums.done = identity.spp;
    for (path, header) in &headers {
        crate::interrupt::stop_if_requested()?;
        let (h, part) = part::read(path)?;
        if h != *header {
            return Err(bad(path, None, "changed while being merged"));
        }
        sums.counters += part.counters;
        let r = part.region;
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let from = part.pixel(x, y);
                // a forged part could hold sums no render makes
                let beyond = || {
                    bad(
                        path,
                        None,
                        format!("pixel ({x}, {y}): sums beyond any render's range"),
                    )
                };
                for (s, v) in sums.pixel_mut(x, y).iter_mut().zip(from) {
                    *s = s.checked_add(*v).ok_or_else(beyond)?;
                }
                let (i, j) = (sums.index(x, y), part.index(x, y));
                if let (Some(to), Some(from)) = (&mut sums.passes, &part.passes) {
                    to.sums
                        .add_pixel(&to.layout, i, &from.sums, j)
                        .ok_or_else(beyond)?;
                }
            }
        }
    }
    let (layers, coverage) = sums.layers(output.transparent)?;
    Ok(Merged {
        film: sums.film()?,
        layers,
        coverage,
        output,
        identity,
        counters: sums.counters,
        frame: frame_header,
    })
}
