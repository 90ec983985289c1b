//! Cryptomatte: ID mattes from per-pixel coverage of named things
//! ([`Coverage`]), encoded as the open Cryptomatte standard lays out
//! (Psyop, "Cryptomatte Specification" 1.1.0, `docs/output.md` has the
//! summary and the reference), so Nuke, Blender, Fusion, Houdini and
//! OpenImageIO-based tools pull a matte per object or material.
//!
//! - **ID:** the 32-bit MurmurHash3 (x86_32, seed 0) of the name's UTF-8
//!   bytes, [`murmur3_32`]; its bits become a float32 bit for bit except the
//!   exponent, clamped to [1, 254] so that no ID is a denormal, an infinity
//!   or a NaN ([`id_to_float`]). Equal names give equal IDs in every frame
//!   and every renderer that follows the standard.
//! - **Ranks:** per pixel the things seen, their coverages summed per ID
//!   (two names with one hash, or two objects with one name, are one matte,
//!   as the standard says), sorted by coverage, largest first (ties by the
//!   ID's bits, so the order is deterministic), the first `ranks` kept.
//!   Channel layout: `NAME00.R` = ID of rank 0, `NAME00.G` its coverage,
//!   `NAME00.B` = ID of rank 1, `NAME00.A` its coverage, `NAME01.*` ranks 2
//!   and 3, and so on; an empty rank is (ID 0, coverage 0). Where every
//!   sample hit something and at most `ranks` things were seen, the
//!   coverages add up to 1 (tested); where more were seen the smallest are
//!   dropped, which is what the standard's default of 6 ranks accepts.
//! - **Metadata:** `cryptomatte/KEY/name`, `/hash` (`MurmurHash3_32`),
//!   `/conversion` (`uint32_to_float32`) and `/manifest` (JSON object name
//!   → 8 hex digits of the float ID's bits), KEY the first 7 hex digits of
//!   the MurmurHash3 of the layer name (what Blender does; the standard
//!   suggests "a hash of the type name").
//!
//! The coverage values are the renderer's sample fractions (exact multiples
//! of 1/spp up to float rounding), stored as 32-bit floats; IDs are always
//! 32-bit floats (half would destroy them).

use std::collections::BTreeMap;

use super::layers::Coverage;
use crate::error::Error;

/// The standard's suggested number of ranks (3 RGBA layers).
pub(crate) const DEFAULT_RANKS: usize = 6;

/// The largest number of ranks accepted (32 RGBA layers).
pub const MAX_RANKS: usize = 64;

/// MurmurHash3 x86_32 (Austin Appleby's public-domain reference,
/// `MurmurHash3_x86_32`) of `data` with `seed`.
pub fn murmur3_32(data: &[u8], seed: u32) -> u32 {
    const C1: u32 = 0xcc9e_2d51;
    const C2: u32 = 0x1b87_3593;
    let mix = |k: u32| k.wrapping_mul(C1).rotate_left(15).wrapping_mul(C2);
    let mut h = seed;
    let mut blocks = data.chunks_exact(4);
    for b in &mut blocks {
        h ^= mix(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        h = h.rotate_left(13).wrapping_mul(5).wrapping_add(0xe654_6b64);
    }
    let tail = blocks.remainder();
    if !tail.is_empty() {
        let mut k = 0u32;
        for (i, &byte) in tail.iter().enumerate() {
            k |= u32::from(byte) << (8 * i);
        }
        h ^= mix(k);
    }
    // the length modulo 2^32, as the reference's 32-bit `len`
    h ^= data.len() as u32;
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// The standard's `uint32_to_float32` conversion: the hash's bits as a
/// float32 with the exponent field clamped to [1, 254] (sign and mantissa
/// kept), so the ID is a finite normal number.
pub fn id_to_float(hash: u32) -> f32 {
    let exponent = ((hash >> 23) & 0xff).clamp(1, 254);
    f32::from_bits((hash & 0x807f_ffff) | (exponent << 23))
}

/// The float ID of `name`.
pub fn name_id(name: &str) -> f32 {
    id_to_float(murmur3_32(name.as_bytes(), 0))
}

/// The 7-character metadata key of a Cryptomatte layer: the first 7 hex
/// digits of the MurmurHash3 of its name.
pub fn metadata_key(layer: &str) -> String {
    let mut s = format!("{:08x}", murmur3_32(layer.as_bytes(), 0));
    s.truncate(7);
    s
}

/// The layer name of a coverage kind: `CryptoObject`, `CryptoMaterial`
/// (the names Blender and most renderers use), else `Crypto` + the kind
/// with its first letter capitalized.
pub fn layer_name(kind: &str) -> String {
    let mut c = kind.chars();
    match c.next() {
        Some(first) => format!("Crypto{}{}", first.to_uppercase(), c.as_str()),
        None => "Crypto".into(),
    }
}

/// The JSON manifest: every name → the 8 hex digits of its float ID's
/// bits, keys sorted (deterministic).
pub fn manifest(names: &[String]) -> String {
    let map: BTreeMap<&str, String> = names
        .iter()
        .map(|n| (n.as_str(), format!("{:08x}", name_id(n).to_bits())))
        .collect();
    serde_json::to_string(&map).unwrap_or_else(|_| "{}".into())
}

/// One Cryptomatte, ready for the file: planar channels (`NAME00.R`, …)
/// and the header attributes (name, value) of its metadata.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Encoded {
    pub name: String,
    /// (channel name, one value per pixel, row-major).
    pub channels: Vec<(String, Vec<f32>)>,
    pub attributes: Vec<(String, String)>,
}

/// Encodes `cov` over `pixels` pixels with `ranks` ranks (rounded up to
/// whole RGBA layers; the extra rank, if any, stays empty).
pub(crate) fn encode(cov: &Coverage, pixels: usize, ranks: usize) -> Result<Encoded, Error> {
    if !(1..=MAX_RANKS).contains(&ranks) {
        return Err(Error::Runtime(format!(
            "Cryptomatte ranks: {ranks} is not in 1 to {MAX_RANKS}"
        )));
    }
    if cov.pixels.len() != pixels {
        return Err(Error::Runtime(format!(
            "{} coverage has {} pixels, the image {pixels}",
            cov.kind,
            cov.pixels.len()
        )));
    }
    let ids: Vec<f32> = cov.names.iter().map(|n| name_id(n)).collect();
    let name = layer_name(&cov.kind);
    let layers = ranks.div_ceil(2);
    let mut planes = vec![vec![0f32; pixels]; 4 * layers];
    // (ID bits, coverage) of one pixel, reused
    let mut seen: Vec<(u32, f32)> = Vec::new();
    for (p, entries) in cov.pixels.iter().enumerate() {
        seen.clear();
        for &(i, fraction) in entries {
            let Some(&id) = ids.get(i as usize) else {
                return Err(Error::Runtime(format!(
                    "{} coverage names thing {i} of {}",
                    cov.kind,
                    ids.len()
                )));
            };
            match seen.iter_mut().find(|(bits, _)| *bits == id.to_bits()) {
                Some((_, c)) => *c += fraction,
                None => seen.push((id.to_bits(), fraction)),
            }
        }
        seen.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        for (rank, &(bits, c)) in seen.iter().take(ranks).enumerate() {
            planes[2 * rank][p] = f32::from_bits(bits);
            planes[2 * rank + 1][p] = c;
        }
    }
    let channels = planes
        .into_iter()
        .enumerate()
        .map(|(k, plane)| {
            (
                format!("{name}{:02}.{}", k / 4, ["R", "G", "B", "A"][k % 4]),
                plane,
            )
        })
        .collect();
    let key = metadata_key(&name);
    let attr = |field: &str, value: String| (format!("cryptomatte/{key}/{field}"), value);
    let attributes = vec![
        attr("name", name.clone()),
        attr("hash", "MurmurHash3_32".into()),
        attr("conversion", "uint32_to_float32".into()),
        attr("manifest", manifest(&cov.names)),
    ];
    Ok(Encoded {
        name,
        channels,
        attributes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Published hash values: Psyop/Cryptomatte,
    /// `nuke/cryptomatte_utilities_tests.py`, `CryptoHashing` (the float
    /// IDs, printed to 12 or more digits, so rounding them to f32 gives the
    /// ID exactly), and the manifest example of the specification
    /// (`specification/cryptomatte_specification.rtf`, "Metadata").
    #[test]
    // the values as published, digit for digit
    #[allow(clippy::excessive_precision)]
    fn hashes_of_known_names_match_the_published_values() {
        let published: [(&str, f64); 6] = [
            ("hello", 6.0705627102400005616e-17),
            ("cube", -4.08461912519e+15),
            ("sphere", 2.79018604383e+15),
            ("plane", 3.66557617593e-11),
            ("равнина", -1.3192631212399999468e-25),
            ("mädchen", 6.2361298211599995797e+25),
        ];
        for (name, id) in published {
            assert_eq!(name_id(name), id as f32, "{name}");
        }
        let manifest_example = [
            ("bunny", 0x1385_1a76u32),
            ("default", 0x42c9_679f),
            ("bunny_porcelain_mat", 0xb24b_26d4),
        ];
        for (name, bits) in manifest_example {
            assert_eq!(name_id(name).to_bits(), bits, "{name}");
        }
        assert_eq!(
            manifest(&["default".into(), "bunny".into()]),
            r#"{"bunny":"13851a76","default":"42c9679f"}"#
        );
        // Blender's test of its metadata key (blenkernel cryptomatte_test.cc)
        assert_eq!(metadata_key("ViewLayer.CryptoMaterial"), "c7dbf5e");
    }

    #[test]
    fn float_conversion_clamps_only_the_exponent() {
        // exponent 0 (a denormal) → 1; 255 (inf / NaN) → 254
        assert_eq!(id_to_float(0x0000_0001).to_bits(), 0x0080_0001);
        assert_eq!(id_to_float(0x8000_0000).to_bits(), 0x8080_0000);
        assert_eq!(id_to_float(0x7f80_0000).to_bits(), 0x7f00_0000);
        assert_eq!(id_to_float(0xffff_ffff).to_bits(), 0xff7f_ffff);
        // a normal exponent passes bit for bit
        assert_eq!(id_to_float(0x3f80_0000), 1.0);
        assert_eq!(id_to_float(0xc049_0fdb).to_bits(), 0xc049_0fdb);
        for h in [0u32, 1, 0x7f7f_ffff, 0x7fff_ffff, 0x807f_ffff, u32::MAX] {
            let f = id_to_float(h);
            assert!(f.is_normal(), "{h:#x} → {f:e}");
        }
    }

    fn coverage(names: &[&str], pixels: Vec<Vec<(u32, f32)>>) -> Coverage {
        Coverage {
            kind: "object".into(),
            names: names.iter().map(|s| s.to_string()).collect(),
            pixels,
        }
    }

    /// (ID, coverage) of every rank of pixel `p`.
    fn ranks_of(e: &Encoded, p: usize) -> Vec<(f32, f32)> {
        e.channels
            .chunks(2)
            .map(|pair| (pair[0].1[p], pair[1].1[p]))
            .collect()
    }

    #[test]
    fn ranks_are_sorted_by_coverage_and_sum_to_one_where_covered() {
        let names = ["a", "b", "c", "d", "e", "f", "g", "h"];
        let full: Vec<(u32, f32)> = (0..8).map(|i| (i, (i + 1) as f32 / 36.0)).collect();
        let cov = coverage(
            &names,
            vec![
                vec![(0, 0.25), (1, 0.5), (2, 0.25)],
                vec![(3, 1.0)],
                vec![],
                full[..6]
                    .iter()
                    .map(|&(i, c)| (i, c * 36.0 / 21.0))
                    .collect(),
                full,
            ],
        );
        let e = encode(&cov, 5, DEFAULT_RANKS).unwrap();
        let names_out: Vec<&str> = e.channels.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(
            names_out,
            [
                "CryptoObject00.R",
                "CryptoObject00.G",
                "CryptoObject00.B",
                "CryptoObject00.A",
                "CryptoObject01.R",
                "CryptoObject01.G",
                "CryptoObject01.B",
                "CryptoObject01.A",
                "CryptoObject02.R",
                "CryptoObject02.G",
                "CryptoObject02.B",
                "CryptoObject02.A"
            ]
        );
        for p in 0..5 {
            let r = ranks_of(&e, p);
            for w in r.windows(2) {
                assert!(w[0].1 >= w[1].1, "pixel {p}: {r:?}");
            }
            let sum: f32 = r.iter().map(|x| x.1).sum();
            let expected = [1.0, 1.0, 0.0, 1.0, 33.0 / 36.0][p];
            assert!((sum - expected).abs() < 1e-6, "pixel {p}: {sum}");
            for &(id, c) in &r {
                assert_eq!(id == 0.0, c == 0.0, "pixel {p}: {r:?}");
            }
        }
        let r = ranks_of(&e, 0);
        assert_eq!(r[0], (name_id("b"), 0.5));
        // ties by the ID's bits
        let (x, y) = (name_id("a"), name_id("c"));
        let (lo, hi) = if x.to_bits() < y.to_bits() {
            (x, y)
        } else {
            (y, x)
        };
        assert_eq!(&r[1..3], &[(lo, 0.25), (hi, 0.25)]);
        assert_eq!(ranks_of(&e, 4)[0], (name_id("h"), 8.0 / 36.0));
        // metadata
        let key = metadata_key("CryptoObject");
        assert_eq!(
            e.attributes[0],
            (format!("cryptomatte/{key}/name"), "CryptoObject".into())
        );
        assert!(e.attributes[3]
            .1
            .contains(&format!("\"d\":\"{:08x}\"", name_id("d").to_bits())));
    }

    #[test]
    fn equal_names_are_one_matte_and_bad_input_is_an_error() {
        let cov = coverage(&["x", "x"], vec![vec![(0, 0.5), (1, 0.5)]]);
        let e = encode(&cov, 1, 2).unwrap();
        assert_eq!(e.channels.len(), 4);
        assert_eq!(ranks_of(&e, 0), [(name_id("x"), 1.0), (0.0, 0.0)]);
        // an odd rank count rounds up to whole layers, the extra rank empty
        assert_eq!(encode(&cov, 1, 3).unwrap().channels.len(), 8);
        assert!(encode(&cov, 1, 0).is_err());
        assert!(encode(&cov, 2, 6).is_err());
        // a tie ranks the same whatever order the things were listed in
        let tie = coverage(
            &["a", "c"],
            vec![vec![(0, 0.5), (1, 0.5)], vec![(1, 0.5), (0, 0.5)]],
        );
        let e = encode(&tie, 2, 2).unwrap();
        assert_eq!(ranks_of(&e, 0), ranks_of(&e, 1));
        let bad = coverage(&["x"], vec![vec![(1, 1.0)]]);
        assert!(encode(&bad, 1, 6).is_err());
    }
}
