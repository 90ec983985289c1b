//! MTL material libraries (the `mtllib` of an OBJ file) → what lucent makes
//! of each `newmtl` (`docs/scene-format.md`, "OBJ materials"): `Kd` and
//! `map_Kd` the diffuse albedo, `map_Bump` / `bump` a height map (with its
//! `-bm` multiplier) or, where the shape says so, a normal map, `norm` a
//! tangent-space normal map, `Ns` / `Pr` a roughness (a plastic). Keys lucent knows but
//! does not model are listed for the user; any other key is refused with
//! the file and line.

use std::path::Path;

use crate::error::InputError;
use crate::geometry::Vec3;

/// Keys of the MTL format lucent reads past, naming them on stderr.
const IGNORED: &[&str] = &[
    "Ka",
    "Ks",
    "Ke",
    "Ni",
    "d",
    "Tr",
    "Tf",
    "illum",
    "map_Ka",
    "map_Ks",
    "map_Ns",
    "map_d",
    "map_Ke",
    "map_Pr",
    "map_Pm",
    "map_Ps",
    "disp",
    "decal",
    "refl",
    "Pm",
    "Ps",
    "Pc",
    "Pcr",
    "aniso",
    "anisor",
    "sharpness",
];

/// One `newmtl` and the keys lucent reads of it.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct MtlMaterial {
    pub name: String,
    pub kd: Option<Vec3>,
    /// `map_Kd`'s file, as written (relative to the MTL file), and its line.
    pub map_kd: Option<(String, usize)>,
    /// `map_Bump` or `bump`'s file and line, and its `-bm` multiplier.
    pub bump: Option<(String, usize, f32)>,
    /// `norm`'s file and line.
    pub normal: Option<(String, usize)>,
    /// `Pr`, or the roughness `Ns` converts to.
    pub roughness: Option<f32>,
}

/// A parsed library: its materials, and the keys it had that lucent
/// ignores, each with its first line.
#[derive(Debug, Default)]
pub(super) struct Mtl {
    pub materials: Vec<MtlMaterial>,
    pub ignored: Vec<(String, usize)>,
}

/// The roughness (√α, lucent's GGX parameter) of a Phong exponent `ns`:
/// α = √(2 / (Ns + 2)), the Beckmann width of the same lobe (Walter et
/// al. 2007, §5.2), used for GGX.
pub(super) fn roughness_of_ns(ns: f32) -> f32 {
    (2.0 / (ns + 2.0)).sqrt().sqrt()
}

/// Parses an MTL file's `text`; errors name `path` and the line.
pub(super) fn parse(text: &str, path: &Path) -> Result<Mtl, InputError> {
    let mut out = Mtl::default();
    for (ln, line) in text.lines().enumerate() {
        let ln = ln + 1;
        let err = |msg: String| InputError::new(path, msg).at_line(ln);
        let line = line.split('#').next().unwrap_or("");
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        let rest: Vec<&str> = words.collect();
        if key == "newmtl" {
            let name = rest.join(" ");
            if name.is_empty() {
                return Err(err("`newmtl` needs a name".into()));
            }
            out.materials.push(MtlMaterial {
                name,
                ..Default::default()
            });
            continue;
        }
        if IGNORED.contains(&key) {
            if !out.ignored.iter().any(|(k, _)| k == key) {
                out.ignored.push((key.to_string(), ln));
            }
            continue;
        }
        let Some(m) = out.materials.last_mut() else {
            return Err(err(format!("`{key}` before any `newmtl`")));
        };
        match key {
            "Kd" => m.kd = Some(colour(&rest).map_err(|e| err(format!("`Kd`: {e}")))?),
            "map_Kd" => {
                let f = file(&rest).map_err(|e| err(format!("`map_Kd`: {e}")))?;
                m.map_kd = Some((f, ln));
            }
            "map_Bump" | "map_bump" | "bump" => {
                let (f, bm) = bump_file(&rest).map_err(|e| err(format!("`{key}`: {e}")))?;
                m.bump = Some((f, ln, bm));
            }
            "norm" => {
                let f = file(&rest).map_err(|e| err(format!("`{key}`: {e}")))?;
                m.normal = Some((f, ln));
            }
            "Ns" => {
                let ns = number(&rest, 0.0..=f32::MAX).map_err(|e| err(format!("`Ns`: {e}")))?;
                m.roughness.get_or_insert(roughness_of_ns(ns));
            }
            "Pr" => {
                m.roughness = Some(number(&rest, 0.0..=1.0).map_err(|e| err(format!("`Pr`: {e}")))?)
            }
            _ => {
                return Err(err(format!(
                    "unsupported MTL key `{key}` (lucent reads newmtl, Kd, map_Kd, map_Bump, \
                     bump, norm, Ns, Pr and ignores {})",
                    IGNORED.join(", ")
                )))
            }
        }
    }
    Ok(out)
}

/// `r g b` (or one grey value), each in [0, 1].
fn colour(words: &[&str]) -> Result<Vec3, String> {
    let v: Vec<f32> = words
        .iter()
        .map(|w| {
            w.parse::<f32>()
                .map_err(|_| format!("`{w}` is not a number"))
        })
        .collect::<Result<_, _>>()?;
    let c = match v.as_slice() {
        [g] => Vec3::splat(*g),
        [r, g, b] => Vec3::new(*r, *g, *b),
        _ => return Err(format!("expected r g b, found {} numbers", v.len())),
    };
    // per component: min/max_element would pass over a NaN
    if !c.to_array().iter().all(|x| (0.0..=1.0).contains(x)) {
        return Err(format!(
            "each component must be in [0, 1], found {} {} {}",
            c.x, c.y, c.z
        ));
    }
    Ok(c)
}

/// One number in `range`.
fn number(words: &[&str], range: std::ops::RangeInclusive<f32>) -> Result<f32, String> {
    let [w] = words else {
        return Err(format!("expected one number, found {} words", words.len()));
    };
    match w.parse::<f32>() {
        Ok(x) if range.contains(&x) => Ok(x),
        Ok(x) => Err(format!(
            "{x} is outside [{}, {}]",
            range.start(),
            range.end()
        )),
        Err(_) => Err(format!("`{w}` is not a number")),
    }
}

/// A bump statement's file name and its `-bm` multiplier (1 without it,
/// finite); any other option is refused.
fn bump_file(words: &[&str]) -> Result<(String, f32), String> {
    match words {
        ["-bm", rest @ ..] => {
            let Some((w, rest)) = rest.split_first() else {
                return Err("`-bm` needs a number".into());
            };
            let bm = match w.parse::<f32>() {
                Ok(x) if x.is_finite() => x,
                _ => return Err(format!("`-bm`: `{w}` is not a finite number")),
            };
            Ok((file(rest)?, bm))
        }
        _ => Ok((file(words)?, 1.0)),
    }
}

/// A texture statement's file name; options (`-s …`, `-clamp …`) are refused.
fn file(words: &[&str]) -> Result<String, String> {
    if let Some(opt) = words.iter().find(|w| w.starts_with('-')) {
        return Err(format!(
            "the option `{opt}` is not supported (give the file alone)"
        ));
    }
    if words.is_empty() {
        return Err("expected a file name".into());
    }
    Ok(words.join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_keys_are_read_ignored_ones_listed_others_refused() {
        let text = "# x\nnewmtl wood\nKd 0.5 0.25 1\nmap_Kd tex/wood.png\nKa 1 1 1\n\
                    illum 2\nnorm n.png\nNs 98\nnewmtl metal\nPr 0.3\nKs 1 1 1\n";
        let m = parse(text, Path::new("a.mtl")).unwrap();
        assert_eq!(m.materials.len(), 2);
        let w = &m.materials[0];
        assert_eq!(w.kd, Some(Vec3::new(0.5, 0.25, 1.0)));
        assert_eq!(w.map_kd, Some(("tex/wood.png".to_string(), 4)));
        assert_eq!(w.normal, Some(("n.png".to_string(), 7)));
        assert_eq!(w.bump, None);
        // Ns 98: α = √(2/100), roughness α^½
        assert!((w.roughness.unwrap() - 0.02f32.sqrt().sqrt()).abs() < 1e-6);
        assert_eq!(m.materials[1].roughness, Some(0.3));
        let ignored: Vec<_> = m.ignored.iter().map(|(k, l)| (k.as_str(), *l)).collect();
        assert_eq!(ignored, [("Ka", 5), ("illum", 6), ("Ks", 11)]);
        let e = parse("newmtl a\nKd 1 1 1\nmap_Xyz f.png\n", Path::new("a.mtl")).unwrap_err();
        let s = e.to_string();
        assert!(
            s.contains("a.mtl") && s.contains(":3") && s.contains("`map_Xyz`"),
            "{s}"
        );
        for kd in ["2 1 1", "nan 0 0", "0 NaN 0", "0.5"] {
            let r = parse(&format!("newmtl a\nKd {kd}\n"), Path::new("a.mtl"));
            if kd == "0.5" {
                assert_eq!(r.unwrap().materials[0].kd, Some(Vec3::splat(0.5)));
                continue;
            }
            let e = r.unwrap_err();
            assert!(e.to_string().contains("in [0, 1]"), "{kd}: {e}");
        }
    }

    /// `map_Bump` and `bump` are height maps with their `-bm` multiplier,
    /// `norm` a normal map; a `-bm` without a finite number and any other
    /// option are refused at their line. Caught: `-bm` read as part of the
    /// file name, its value dropped, `norm` and `map_Bump` confused.
    #[test]
    fn bump_statements_carry_their_multiplier() {
        let text = "newmtl a\nmap_Bump -bm 0.02 h.png\nnewmtl b\nbump h 2.png\nnorm n.png\n";
        let m = parse(text, Path::new("a.mtl")).unwrap();
        assert_eq!(m.materials[0].bump, Some(("h.png".to_string(), 2, 0.02)));
        assert_eq!(m.materials[0].normal, None);
        assert_eq!(m.materials[1].bump, Some(("h 2.png".to_string(), 4, 1.0)));
        assert_eq!(m.materials[1].normal, Some(("n.png".to_string(), 5)));
        for (line, want) in [
            ("map_Bump -bm h.png", "`h.png` is not a finite number"),
            ("map_Bump -bm", "`-bm` needs a number"),
            ("bump -bm nan h.png", "`nan` is not a finite number"),
            ("map_Bump -bm 1", "expected a file name"),
            (
                "map_Bump -s 2 2 2 h.png",
                "the option `-s` is not supported",
            ),
        ] {
            let e = parse(&format!("newmtl a\n{line}\n"), Path::new("a.mtl")).unwrap_err();
            let s = e.to_string();
            assert!(
                s.contains("a.mtl") && s.contains(":2") && s.contains(want),
                "{line}: {s}"
            );
        }
    }
}
