//! Forging lucent parts the way an attacker or a damaged disk would: EXR
//! header attributes rewritten byte for byte (the offset table moved with
//! them), and pixel values rewritten through another EXR writer (the `exr`
//! crate, reading and writing the whole image). Used by the hostile-file
//! tests and the fuzzer.

use std::path::Path;

use exr::prelude::*;

use crate::common::exr_file::first_layer;

/// One EXR header attribute: name, type name, raw value.
#[derive(Clone, Debug)]
pub struct Attr {
    pub name: String,
    pub kind: String,
    pub value: Vec<u8>,
}

/// A single-part scan-line EXR split into its header attributes and what
/// follows them (offset table and chunks).
pub struct Parts {
    pub magic: Vec<u8>,
    pub attrs: Vec<Attr>,
    /// Offsets (absolute) of the chunks.
    pub offsets: Vec<u64>,
    pub rest: Vec<u8>,
    /// Where `rest` started in the file.
    rest_at: usize,
}

fn cstr(b: &[u8], at: &mut usize) -> String {
    let end = *at + b[*at..].iter().position(|&c| c == 0).unwrap();
    let s = String::from_utf8_lossy(&b[*at..end]).into_owned();
    *at = end + 1;
    s
}

/// Lines per chunk of an EXR compression code.
fn lines_per_chunk(code: u8) -> i32 {
    match code {
        3 | 5 | 7 | 8 => 16,
        4 | 6 => 32,
        9 => 256,
        _ => 1,
    }
}

impl Parts {
    /// Splits a part file's bytes (as lucent writes it).
    pub fn split(b: &[u8]) -> Parts {
        let mut at = 8;
        let mut attrs = Vec::new();
        while b[at] != 0 {
            let name = cstr(b, &mut at);
            let kind = cstr(b, &mut at);
            let n = i32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize;
            at += 4;
            attrs.push(Attr {
                name,
                kind,
                value: b[at..at + n].to_vec(),
            });
            at += n;
        }
        at += 1;
        let p = Parts {
            magic: b[..8].to_vec(),
            attrs,
            offsets: Vec::new(),
            rest: Vec::new(),
            rest_at: 0,
        };
        let w = p.get("dataWindow");
        let y = |k: usize| i32::from_le_bytes(w[k..k + 4].try_into().unwrap());
        let code = p.get("compression")[0];
        let h = y(12) - y(4) + 1;
        let chunks = ((h + lines_per_chunk(code) - 1) / lines_per_chunk(code)) as usize;
        let offsets = (0..chunks)
            .map(|k| u64::from_le_bytes(b[at + 8 * k..at + 8 * k + 8].try_into().unwrap()))
            .collect();
        let rest_at = at + 8 * chunks;
        Parts {
            offsets,
            rest: b[rest_at..].to_vec(),
            rest_at,
            ..p
        }
    }

    pub fn get(&self, name: &str) -> &[u8] {
        &self.attrs.iter().find(|a| a.name == name).unwrap().value
    }

    /// The names in the `channels` attribute (each a name, its NUL and 16
    /// bytes of type and sampling; a NUL ends the list).
    pub fn channel_names(&self) -> Vec<String> {
        let c = self.get("channels");
        let (mut at, mut names) = (0, Vec::new());
        while at < c.len() && c[at] != 0 {
            names.push(cstr(c, &mut at));
            at += 16;
        }
        names
    }

    /// Sets attribute `name`'s raw value (adding it as `kind` if missing).
    pub fn set(&mut self, name: &str, kind: &str, value: Vec<u8>) {
        match self.attrs.iter_mut().find(|a| a.name == name) {
            Some(a) => a.value = value,
            None => self.attrs.push(Attr {
                name: name.into(),
                kind: kind.into(),
                value,
            }),
        }
    }

    /// Makes the file claim `n` chunks (ZIP16: a data window of 16·n
    /// lines): the `chunkCount` attribute, and an offset table of `n`
    /// entries, the new ones pointing at the last chunk.
    pub fn set_chunks(&mut self, n: usize) {
        if self.attrs.iter().any(|a| a.name == "chunkCount") {
            self.set("chunkCount", "int", (n as i32).to_le_bytes().to_vec());
        }
        let last = *self.offsets.last().unwrap();
        self.offsets.resize(n, last);
    }

    /// Sets a text attribute.
    pub fn set_text(&mut self, name: &str, text: &str) {
        self.set(name, "string", text.as_bytes().to_vec());
    }

    /// Sets a box2i attribute (inclusive bounds, as EXR stores them).
    pub fn set_box(&mut self, name: &str, b: [i32; 4]) {
        self.set(
            name,
            "box2i",
            b.iter().flat_map(|v| v.to_le_bytes()).collect(),
        );
    }

    /// The file: header, offset table moved by the header's change in
    /// length, and the rest unchanged.
    pub fn join(&self) -> Vec<u8> {
        let mut out = self.magic.clone();
        for a in &self.attrs {
            out.extend(a.name.as_bytes());
            out.push(0);
            out.extend(a.kind.as_bytes());
            out.push(0);
            out.extend((a.value.len() as i32).to_le_bytes());
            out.extend(&a.value);
        }
        out.push(0);
        let table_at = out.len();
        let shift = (table_at + 8 * self.offsets.len()) as i64 - self.rest_at as i64;
        for o in &self.offsets {
            out.extend(((*o as i64 + shift) as u64).to_le_bytes());
        }
        out.extend(&self.rest);
        out
    }
}

/// Rewrites the part at `path` with `edit` applied to its header.
pub fn edit_header(path: &Path, edit: impl FnOnce(&mut Parts)) {
    let mut p = Parts::split(&std::fs::read(path).unwrap());
    edit(&mut p);
    std::fs::write(path, p.join()).unwrap();
}

/// Rewrites the part at `path` through the `exr` crate with `edit` applied
/// to channel `name`'s u32 samples (row by row in the part's region).
pub fn edit_channel(path: &Path, name: &str, edit: impl FnOnce(&mut Vec<u32>)) {
    let mut image = first_layer(path);
    let c = image
        .layer_data
        .channel_data
        .list
        .iter_mut()
        .find(|c| c.name == *name)
        .unwrap_or_else(|| panic!("no channel {name}"));
    let FlatSamples::U32(v) = &mut c.sample_data else {
        panic!("{name} is not u32")
    };
    edit(v);
    image.write().to_file(path).unwrap();
}

/// Rewrites summed channel `sum` (`layer.channel`) of the part at `path`
/// with four words a pixel, `edit` changing them; `keep` says which of the
/// words are then stored (`w0` first), so a forger can leave a gap.
pub fn set_words(path: &Path, sum: &str, keep: [bool; 4], edit: impl FnOnce(&mut [Vec<u32>; 4])) {
    let mut image = first_layer(path);
    let list = &mut image.layer_data.channel_data.list;
    let stored: Vec<Vec<u32>> = (0..4)
        .map_while(|j| {
            let name = format!("{sum}.w{j}");
            let c = list.iter().find(|c| c.name == *name.as_str())?;
            match &c.sample_data {
                FlatSamples::U32(v) => Some(v.clone()),
                _ => panic!("{name} is not u32"),
            }
        })
        .collect();
    assert!(!stored.is_empty(), "no channel {sum}.w0");
    // the missing high words extend the highest stored one
    let mut words: [Vec<u32>; 4] = std::array::from_fn(|_| Vec::new());
    for j in 0..4 {
        words[j] = match stored.get(j) {
            Some(v) => v.clone(),
            None => words[j - 1]
                .iter()
                .map(|&w| ((w as i32) >> 31) as u32)
                .collect(),
        };
    }
    edit(&mut words);
    list.retain(|c| !c.name.to_string().starts_with(&format!("{sum}.w")));
    for (j, w) in words.into_iter().enumerate().filter(|(j, _)| keep[*j]) {
        list.push(AnyChannel::new(
            format!("{sum}.w{j}").as_str(),
            FlatSamples::U32(w),
        ));
    }
    list.sort_by(|a, b| a.name.cmp(&b.name));
    image.write().to_file(path).unwrap();
}
