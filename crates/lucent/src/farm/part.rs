//! A part: the exact sums of a region of a frame over a range of sample
//! indices, as an OpenEXR file that says what it is ([`Header`]).
//!
//! One scan-line EXR (ZIP), its data window the part's region, its display
//! window the whole frame. Each summed channel `C` of a layer `L` (the
//! beauty's `beauty.R` … then the passes' summed layers) is up to four
//! `u32` channels `L.C.w0` … `L.C.w3`, the words of the pixel's `i128` sum,
//! least significant first ([`to_words`]: EXR's only integer sample type
//! is u32), the high words the channel's sums do not need left out
//! (`farm/part_words.rs`).
//! With P, Z or an ID pass the nearest camera hit is the u32 channels
//! `nearest.depth`, `nearest.sample`, `nearest.px`/`py`/`pz` (f32 bits),
//! `nearest.object`, `nearest.material`; with Cryptomatte, the sample
//! counts per ID are `coverage.<kind>.id{k}` (index + 1, 0: empty) and
//! `coverage.<kind>.n{k}`. docs/farm.md, "Parts".

use std::path::Path;
use std::result::Result;

use exr::prelude::*;

pub use super::header::{
    beauty_layer, layers_of, layout_of, names_text, output_text, parse_output, parse_samples,
    passes_text, FieldError, Header, Identity, LayerFormat, FORMAT_VERSION,
};

use super::header::bad;
pub(crate) use super::part_file::PartFile;
use super::part_file::NEAREST;
use super::part_values::PixelAt;
use super::part_words;
use crate::error::Error;
use crate::film::accumulate::{from_words, to_words};
use crate::film::pass_sums::{AovSums, Nearest, Passes};
use crate::film::{Staged, Sums};

/// A part's EXR channels: u32 samples, one a pixel of the region.
type Channel = AnyChannel<FlatSamples>;

fn nearest_words(n: &Nearest) -> [u32; 7] {
    let [px, py, pz] = n.p.map(f32::to_bits);
    [n.z.to_bits(), n.sample, px, py, pz, n.object, n.material]
}

fn nearest_from_words(w: [u32; 7]) -> Nearest {
    Nearest {
        z: f32::from_bits(w[0]),
        sample: w[1],
        p: [w[2], w[3], w[4]].map(f32::from_bits),
        object: w[5],
        material: w[6],
    }
}

/// The region's pixels, row by row: their index in `sums`.
fn pixel_order(sums: &Sums) -> Vec<usize> {
    let r = sums.region;
    (r.y0..r.y1)
        .flat_map(|y| (r.x0..r.x1).map(move |x| (x, y)))
        .map(|(x, y)| sums.index(x, y))
        .collect()
}

/// The summed channels' names (`L.C`), in the order of `layers`: the
/// beauty's [`Sums::CHANNELS`], then the passes' in their stride order.
fn sum_names(layers: &[LayerFormat]) -> Vec<String> {
    layers
        .iter()
        .flat_map(|l| l.channels.iter().map(move |c| format!("{}.{c}", l.name)))
        .collect()
}

/// Summed channel `k` ([`sum_names`] order) of the pixel of index `i`.
fn sum_at(sums: &mut Sums, k: usize, i: usize) -> Option<&mut i128> {
    const C: usize = Sums::CHANNELS;
    if k < C {
        return Some(&mut sums.pixel_at_mut(i)[k]);
    }
    let p = sums.passes.as_mut()?;
    let stride = p.layout.stride();
    p.sums.sums.get_mut(i * stride + k - C)
}

/// Pixels a thread copies at a time.
const CHUNK: usize = 4096;

/// The summed values of the pixel of index `i`, in [`sum_names`] order.
fn pixel_sums(sums: &Sums, i: usize) -> impl Iterator<Item = &i128> {
    let passes = sums.passes.as_ref().map_or(&[][..], |p| {
        let stride = p.layout.stride();
        &p.sums.sums[i * stride..(i + 1) * stride]
    });
    sums.pixel_at(i).iter().chain(passes)
}

/// The words of every summed channel, as many as its largest sum needs
/// (`farm/part_words.rs`). The sums are read pixel by pixel, as they lie
/// in memory, on every core: a checkpoint's copy holds up the render, an
/// interrupted render's its exit.
fn sum_channels(sums: &Sums, order: &[usize]) -> Vec<Channel> {
    use rayon::prelude::*;
    let layout = sums.passes.as_ref().map(|p| &p.layout);
    let names = sum_names(&layers_of(layout));
    let ones = || vec![1usize; names.len()];
    let m = order
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut m = ones();
            for &i in chunk {
                for (m, v) in m.iter_mut().zip(pixel_sums(sums, i)) {
                    *m = (*m).max(part_words::words_needed(*v));
                }
            }
            m
        })
        .reduce(ones, |a, b| {
            a.iter().zip(b).map(|(a, b)| b.max(*a)).collect()
        });
    let n = order.len();
    let mut words: Vec<Vec<u32>> = m.iter().flat_map(|&m| (0..m).map(|_| vec![0; n])).collect();
    let mut chunks: Vec<Vec<&mut [u32]>> = (0..n.div_ceil(CHUNK)).map(|_| Vec::new()).collect();
    for w in words.iter_mut() {
        for (t, slice) in w.chunks_mut(CHUNK).enumerate() {
            chunks[t].push(slice);
        }
    }
    chunks
        .into_par_iter()
        .zip(order.par_chunks(CHUNK))
        .for_each(|(mut out, pixels)| {
            for (j, &i) in pixels.iter().enumerate() {
                let mut at = 0;
                for (&m, v) in m.iter().zip(pixel_sums(sums, i)) {
                    for (o, w) in out[at..at + m].iter_mut().zip(to_words(*v)) {
                        o[j] = w;
                    }
                    at += m;
                }
            }
        });
    let mut words = words.into_iter();
    let mut out = Vec::with_capacity(words.len());
    for (name, &m) in names.iter().zip(&m) {
        for (j, w) in words.by_ref().take(m).enumerate() {
            out.push(Channel::new(
                format!("{name}.w{j}").as_str(),
                FlatSamples::U32(w),
            ));
        }
    }
    out
}

/// The nearest hit's channels, when the passes keep it.
fn nearest_channels(aov: &AovSums, order: &[usize]) -> Vec<Channel> {
    if aov.nearest.is_empty() {
        return Vec::new();
    }
    let words: Vec<[u32; 7]> = order
        .iter()
        .map(|&i| nearest_words(&aov.nearest[i]))
        .collect();
    (0..NEAREST.len())
        .map(|f| {
            let v = words.iter().map(|w| w[f]).collect();
            Channel::new(
                format!("nearest.{}", NEAREST[f]).as_str(),
                FlatSamples::U32(v),
            )
        })
        .collect()
}

/// The coverage channels: per kind, as many (ID, count) pairs as the
/// pixel with the most IDs has.
fn coverage_channels(aov: &AovSums, order: &[usize]) -> Vec<Channel> {
    let mut out = Vec::new();
    for (kind, counts) in [("object", &aov.objects), ("material", &aov.materials)] {
        if counts.is_empty() {
            continue;
        }
        let most = order.iter().map(|&i| counts[i].len()).max().unwrap_or(0);
        for k in 0..most {
            let at = |i: usize| counts[i].get(k).copied();
            let ids = order.iter().map(|&i| at(i).map_or(0, |e| e.0 + 1));
            let ns = order.iter().map(|&i| at(i).map_or(0, |e| e.1));
            out.push(Channel::new(
                format!("coverage.{kind}.id{k}").as_str(),
                FlatSamples::U32(ids.collect()),
            ));
            out.push(Channel::new(
                format!("coverage.{kind}.n{k}").as_str(),
                FlatSamples::U32(ns.collect()),
            ));
        }
    }
    out
}

/// An attribute's text as EXR text (bytes 0–255): anything else (a file
/// name) shown escaped.
fn exr_text(s: &str) -> AttributeValue {
    let t: String = s.chars().flat_map(|c| c.escape_default()).collect();
    AttributeValue::Text(Text::new_or_panic(if s.is_ascii() { s } else { &t }))
}

/// Stages the part file of `sums` at `path` (commit it with
/// [`crate::film::commit_all`]).
pub fn stage(path: &Path, header: &Header, sums: &Sums) -> Result<Staged, Error> {
    prepare(header, sums).stage(path, true)
}

/// A part's EXR image, its channels copied out of the sums: what
/// [`Prepared::stage`] compresses and writes (a checkpoint, in a thread of
/// its own while the sums go on changing).
pub struct Prepared(Image<Layer<AnyChannels<FlatSamples>>>);

/// The part image of `sums` with `header`.
pub fn prepare(header: &Header, sums: &Sums) -> Prepared {
    let r = sums.region;
    let order = pixel_order(sums);
    let mut channels = sum_channels(sums, &order);
    if let Some(p) = &sums.passes {
        channels.extend(nearest_channels(&p.sums, &order));
        channels.extend(coverage_channels(&p.sums, &order));
    }
    let mut attrs = LayerAttributes {
        layer_position: Vec2(r.x0 as i32, r.y0 as i32),
        ..LayerAttributes::default()
    };
    for (k, v) in header.attributes() {
        attrs.other.insert(Text::new_or_panic(k), exr_text(&v));
    }
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let size = (r.width() as usize, r.height() as usize);
    let channels = AnyChannels::sort(SmallVec::from_vec(channels));
    let mut image = Image::from_layer(Layer::new(size, attrs, encoding, channels));
    let (w, h) = header.identity.frame;
    image.attributes.display_window = IntegerBounds::new((0, 0), (w as usize, h as usize));
    Prepared(image)
}

impl Prepared {
    /// Stages the part file at `path`, its blocks compressed on every core
    /// (`parallel`: nothing else is running) or, for a checkpoint beside
    /// the render, in this thread alone and given up at a signal (the
    /// interrupted render writes its own part at once). The bytes are the
    /// same either way.
    pub fn stage(self, path: &Path, parallel: bool) -> Result<Staged, Error> {
        let image = self.0;
        Staged::write(path, |tmp| {
            let w = image.write();
            match parallel {
                true => w.to_buffered(&mut *tmp),
                false => tmp
                    .try_clone()
                    .map_err(exr::error::Error::from)
                    .and_then(|f| w.non_parallel().to_unbuffered(UntilSignal(f))),
            }
            .map_err(|e| e.to_string())
        })
    }
}

/// A file that refuses further writes once a signal asked the process to
/// stop ([`crate::interrupt::requested`]).
struct UntilSignal(std::fs::File);

impl std::io::Write for UntilSignal {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        match crate::interrupt::requested() {
            Some(_) => Err(std::io::Error::other("a signal stopped the write")),
            None => self.0.write(buf),
        }
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}

impl std::io::Seek for UntilSignal {
    fn seek(&mut self, pos: std::io::SeekFrom) -> std::io::Result<u64> {
        self.0.seek(pos)
    }
}

/// The header of the part at `path`, without its pixels, checked to be
/// one a render writes ([`PartFile::open`]).
pub(crate) fn read_header(path: &Path) -> Result<Header, Error> {
    Ok(PartFile::open(path)?.header)
}

/// A part's channels, found by name.
struct Channels<'a> {
    path: &'a Path,
    list: &'a [Channel],
    /// Pixels of the region.
    n: usize,
    /// Where pixel `j` of a channel is, and the bounds on its values.
    at: PixelAt<'a>,
}

impl Channels<'_> {
    fn has(&self, name: &str) -> bool {
        self.list.iter().any(|a| a.name == Text::new_or_panic(name))
    }

    /// Channel `name`'s samples.
    fn get(&self, name: &str) -> Result<&[u32], Error> {
        let found = self
            .list
            .iter()
            .find(|a| a.name == Text::new_or_panic(name));
        match found.map(|a| &a.sample_data) {
            Some(FlatSamples::U32(v)) if v.len() == self.n => Ok(v),
            Some(_) => Err(self.bad(format!("channel {name} is not u32 pixels"))),
            None => Err(self.bad(format!("channel {name} is missing"))),
        }
    }

    fn bad(&self, problem: String) -> Error {
        bad(self.path, None, problem)
    }

    /// A bad value of channel `name` (layer.channel).
    fn located(&self, name: &str, problem: impl std::fmt::Display) -> Error {
        bad(self.path, Some(name), problem.to_string())
    }

    /// Reads every summed channel of `layers` into `sums`; the channels
    /// read.
    fn read_sums(
        &self,
        layers: &[LayerFormat],
        order: &[usize],
        sums: &mut Sums,
    ) -> Result<usize, Error> {
        let names = sum_names(layers);
        let mut read = 0;
        for (k, name) in names.iter().enumerate() {
            let stored = self.stored_words(name)?;
            read += stored.len();
            for (j, &i) in order.iter().enumerate() {
                let mut words = [0u32; 4];
                for (w, s) in words.iter_mut().zip(&stored) {
                    *w = s[j];
                }
                let v = from_words(part_words::widened(&words[..stored.len()]));
                self.at.check_sum(v, j).map_err(|e| self.located(name, e))?;
                if let Some(s) = sum_at(sums, k, i) {
                    *s = v;
                }
            }
        }
        Ok(read)
    }

    /// The stored words of summed channel `name`: `w0`, then each higher
    /// word up to the first missing one; a word above a missing one is
    /// refused.
    fn stored_words(&self, name: &str) -> Result<Vec<&[u32]>, Error> {
        let mut stored = vec![self.get(&format!("{name}.w0"))?];
        for j in 1..4 {
            let word = format!("{name}.w{j}");
            match (self.has(&word), stored.len() == j) {
                (true, true) => stored.push(self.get(&word)?),
                (true, false) => {
                    let problem = format!("channel {word} without {name}.w{}", j - 1);
                    return Err(self.located(name, problem));
                }
                (false, _) => {}
            }
        }
        Ok(stored)
    }

    /// Reads the nearest hits, if the passes keep them; the channels read.
    fn read_nearest(&self, order: &[usize], aov: &mut AovSums) -> Result<usize, Error> {
        if aov.nearest.is_empty() {
            return Ok(0);
        }
        let mut c: [&[u32]; 7] = [&[]; 7];
        for (c, name) in c.iter_mut().zip(NEAREST) {
            *c = self.get(&format!("nearest.{name}"))?;
        }
        for (j, &i) in order.iter().enumerate() {
            let n = nearest_from_words(c.map(|c| c[j]));
            let (channel, problem) = self.at.check_nearest(&n, j);
            if let Some(channel) = channel {
                return Err(self.located(&format!("nearest.{channel}"), problem));
            }
            aov.nearest[i] = n;
        }
        Ok(NEAREST.len())
    }

    /// Reads the ID coverage of the passes that keep it; the channels read.
    fn read_coverage(&self, order: &[usize], p: &mut Passes) -> Result<usize, Error> {
        let l = &p.layout;
        let mut read = 0;
        for (kind, names, counts) in [
            ("object", l.object_names.len(), &mut p.sums.objects),
            ("material", l.material_names.len(), &mut p.sums.materials),
        ] {
            if counts.is_empty() {
                continue;
            }
            let mut k = 0;
            while self.has(&format!("coverage.{kind}.id{k}")) {
                let ids = self.get(&format!("coverage.{kind}.id{k}"))?;
                let ns = self.get(&format!("coverage.{kind}.n{k}"))?;
                for (j, &i) in order.iter().enumerate() {
                    add_coverage(&mut counts[i], ids[j], ns[j], names).map_err(|e| {
                        let problem = format!("{}: {e}", self.at.pixel(j));
                        self.located(&format!("coverage.{kind}.id{k}"), problem)
                    })?;
                }
                read += 2;
                k += 1;
            }
            for (j, &i) in order.iter().enumerate() {
                let total: u64 = counts[i].iter().map(|e| e.1 as u64).sum();
                self.at
                    .check_coverage(total, j)
                    .map_err(|e| self.located(&format!("coverage.{kind}"), e))?;
            }
        }
        Ok(read)
    }
}

/// What is wrong with a pair of coverage channels.
#[derive(Debug, thiserror::Error)]
enum BadCoverage {
    #[error("IDs out of order")]
    OutOfOrder,
    #[error("no such ID (index + 1) {0} with a count of {1}")]
    NoSuchId(u32, u32),
}

/// Appends the pair (`id` = index + 1, `count`) of a coverage channel to
/// a pixel's counts (sorted by ID) of `names` things.
fn add_coverage(
    counts: &mut Vec<(u32, u32)>,
    id: u32,
    count: u32,
    names: usize,
) -> Result<(), BadCoverage> {
    match (id, count) {
        (0, 0) => Ok(()),
        (id, c) if id >= 1 && id as usize <= names && c > 0 => {
            if counts.last().is_some_and(|e| e.0 + 1 > id - 1) {
                return Err(BadCoverage::OutOfOrder);
            }
            counts.push((id - 1, c));
            Ok(())
        }
        (id, c) => Err(BadCoverage::NoSuchId(id, c)),
    }
}

/// The part at `path`: its header and sums. A damaged, truncated or
/// forged file, or one whose pixels disagree with its header, is bad input
/// naming it (and the channel and pixel at fault).
pub fn read(path: &Path) -> Result<(Header, Sums), Error> {
    read_pixels(path, PartFile::open(path)?)
}

/// The header and sums of the checked part `file` at `path`.
pub(crate) fn read_pixels(path: &Path, file: PartFile) -> Result<(Header, Sums), Error> {
    let header = file.header.clone();
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .pedantic()
        .non_parallel()
        .from_buffered(file.rewound()?)
        .map_err(|e| bad(path, None, format!("damaged or truncated part: {e}")))?;
    let layer = &image.layer_data;
    let r = header.region;
    let layout = layout_of(&header.identity).map_err(|e| e.at(path))?;
    let mut sums = Sums::with_passes(r, header.samples.start, layout.as_ref())?;
    sums.done = header.samples.end;
    sums.counters = header.counters;
    let list = &layer.channel_data.list;
    let channels = Channels {
        path,
        list,
        n: r.area() as usize,
        at: PixelAt::new(&header, layout.as_ref()),
    };
    let order = pixel_order(&sums);
    let mut expected = channels.read_sums(&header.layers, &order, &mut sums)?;
    if let Some(p) = &mut sums.passes {
        expected += channels.read_nearest(&order, &mut p.sums)?;
        expected += channels.read_coverage(&order, p)?;
    }
    if list.len() != expected {
        let problem = format!(
            "{} channels, a part of these layers and passes has {expected}",
            list.len()
        );
        return Err(bad(path, None, problem));
    }
    Ok((header, sums))
}
