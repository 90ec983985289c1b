//! The EXR files lucent writes, read back by a real VFX tool: OpenImageIO's
//! `oiiotool --info -v` (Debian package `openimageio-tools`, installed by
//! scripts/install-deps.sh). Checks the layer and channel names, the
//! channel count, each channel's data type (half or float) and the header
//! attributes as that tool reports them, for a multi-layer frame with
//! Cryptomatte, a split frame, and a real render's beauty-only file.
//!
//! Without `oiiotool` on the PATH these tests fail (they do not skip): CI
//! installs it, and a file only the exr crate can read would pass
//! otherwise.

use std::path::Path;
use std::process::Command;

use lucent::film::cryptomatte::{self, metadata_key};
use lucent::film::exr_layers::{self, ExrCompression, FrameHeader, OutputOptions, Precision};
use lucent::film::layers::{Coverage, Layer, LayerKind};
use lucent::film::Film;
use lucent::geometry::Vec3;

/// `oiiotool --info -v PATH`, or a failure saying how to install it.
fn oiio_info(path: &Path) -> String {
    let out = Command::new("oiiotool")
        .args(["--info", "-v"])
        .arg(path)
        .output()
        .unwrap_or_else(|e| {
            panic!(
                "cannot run oiiotool ({e}): install OpenImageIO's tools \
                 (Debian: apt-get install openimageio-tools; scripts/install-deps.sh does)"
            )
        });
    assert!(
        out.status.success(),
        "oiiotool --info -v {} failed: {}",
        path.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// What `oiiotool --info -v` says about a file.
struct Info {
    width: u32,
    height: u32,
    /// (channel name, data type) in file order; the type of a channel
    /// without its own annotation is the file's format.
    channels: Vec<(String, String)>,
    /// (attribute name, value as printed).
    attributes: Vec<(String, String)>,
}

impl Info {
    fn parse(text: &str) -> Info {
        // "Reading PATH" first
        let mut lines = text.lines().skip_while(|l| l.starts_with("Reading "));
        // "PATH :  640 x  480, 4 channel, float openexr" (the format is
        // "half/float" or the like when channels differ)
        let first = lines.next().expect("empty oiiotool output");
        let (_, dims) = first.rsplit_once(" : ").expect(first);
        let mut parts = dims.split(',');
        let wh: Vec<u32> = parts
            .next()
            .unwrap()
            .split('x')
            .map(|s| s.trim().parse().unwrap())
            .collect();
        let format = parts
            .nth(1)
            .unwrap()
            .trim()
            .split(' ')
            .next()
            .unwrap()
            .to_string();
        let mut channels = Vec::new();
        let mut attributes = Vec::new();
        for line in lines {
            let line = line.trim();
            if let Some(list) = line.strip_prefix("channel list: ") {
                for c in list.split(", ") {
                    channels.push(match c.split_once(" (") {
                        Some((name, ty)) => {
                            (name.to_string(), ty.trim_end_matches(')').to_string())
                        }
                        None => (c.to_string(), format.clone()),
                    });
                }
            } else if let Some((k, v)) = line.split_once(": ") {
                attributes.push((k.to_string(), v.to_string()));
            }
        }
        Info {
            width: wh[0],
            height: wh[1],
            channels,
            attributes,
        }
    }

    fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|a| a.0 == name)
            .map(|a| a.1.as_str())
    }

    fn type_of(&self, channel: &str) -> &str {
        &self
            .channels
            .iter()
            .find(|c| c.0 == channel)
            .unwrap_or_else(|| panic!("no channel {channel} in {:?}", self.channels))
            .1
    }
}

fn film() -> Film {
    let mut f = Film::new(5, 3);
    for (i, p) in f.pixels.iter_mut().enumerate() {
        *p = Vec3::new(i as f32 * 0.25, 0.5, 2.0);
    }
    f
}

fn layers(pixels: usize) -> Vec<Layer> {
    let layer = |name: &str, channels: &[&str], kind| Layer {
        name: name.into(),
        channels: channels.iter().map(|s| s.to_string()).collect(),
        kind,
        values: (0..pixels * channels.len())
            .map(|i| i as f32 / 8.0)
            .collect(),
    };
    vec![
        layer("diffuse_direct", &["R", "G", "B"], LayerKind::Light),
        layer("sss_indirect", &["R", "G", "B"], LayerKind::Light),
        layer("N", &["X", "Y", "Z"], LayerKind::Data),
        layer("depth", &["Z"], LayerKind::Data),
        layer("object_id", &["id"], LayerKind::Id),
    ]
}

fn coverage(pixels: usize) -> Vec<Coverage> {
    let names = vec!["bunny".to_string(), "floor".to_string(), "lamp".to_string()];
    let per_pixel = |p: usize| match p % 3 {
        0 => vec![(0, 1.0)],
        1 => vec![(0, 0.5), (1, 0.25), (2, 0.25)],
        _ => vec![],
    };
    ["object", "material"]
        .iter()
        .map(|k| Coverage {
            kind: k.to_string(),
            names: names.clone(),
            pixels: (0..pixels).map(per_pixel).collect(),
        })
        .collect()
}

fn header() -> FrameHeader {
    FrameHeader {
        scene_path: Some("scenes/marble-bunny.toml".into()),
        scene_sha256: Some("ab".repeat(32)),
        spp: Some(64),
        seed: Some(12345678901234),
        max_depth: Some(8),
        backend: Some("bvh".into()),
        backend_version: Some("lucent 0.1.0".into()),
        integrator: Some("path".into()),
        sampling: vec![("bunny".into(), "axes=curvature roughness=0.3".into())],
        plan: Some(r#"{"schema":1,"integrator":"path"}"#.into()),
        render_seconds: Some(12.5),
        ..FrameHeader::default()
    }
}

/// The attributes every file carries, as OpenImageIO prints them.
fn assert_header(info: &Info) {
    let want = [
        (
            "software",
            format!("\"lucent {}\"", env!("CARGO_PKG_VERSION")),
        ),
        ("lucent/scene", "\"scenes/marble-bunny.toml\"".into()),
        ("lucent/sceneSha256", format!("\"{}\"", "ab".repeat(32))),
        ("lucent/resolution", "5, 3".into()),
        ("lucent/spp", "64".into()),
        ("lucent/seed", "\"12345678901234\"".into()),
        ("lucent/maxDepth", "8".into()),
        ("lucent/backend", "\"bvh\"".into()),
        ("lucent/backendVersion", "\"lucent 0.1.0\"".into()),
        ("lucent/integrator", "\"path\"".into()),
        (
            "lucent/sampling",
            "\"bunny: axes=curvature roughness=0.3\"".into(),
        ),
        (
            "lucent/plan",
            r#""{"schema":1,"integrator":"path"}""#.into(),
        ),
        ("lucent/renderTime", "12.5".into()),
    ];
    for (name, value) in want {
        assert_eq!(
            info.attribute(name),
            Some(value.as_str()),
            "{name} in {:?}",
            info.attributes
        );
    }
}

#[test]
fn oiiotool_reads_every_layer_type_and_attribute_of_a_multilayer_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.exr");
    let f = film();
    let n = f.pixels.len();
    let opts = OutputOptions {
        precision: Precision::Half,
        compression: ExrCompression::Piz,
        ..OutputOptions::default()
    };
    exr_layers::write_frame(&path, &f, &layers(n), &coverage(n), &header(), &opts).unwrap();
    let info = Info::parse(&oiio_info(&path));
    assert_eq!((info.width, info.height), (5, 3));
    // beauty 4 + two light passes 6 + N 3 + depth 1 + id 1 + 2 × 3 RGBA
    assert_eq!(
        info.channels.len(),
        4 + 6 + 3 + 1 + 1 + 24,
        "{:?}",
        info.channels
    );
    for c in ["R", "G", "B", "A"] {
        assert_eq!(info.type_of(c), "float", "{c}");
    }
    for c in ["diffuse_direct.R", "diffuse_direct.B", "sss_indirect.G"] {
        assert_eq!(info.type_of(c), "half", "{c}");
    }
    for c in ["N.X", "N.Z", "depth.Z", "object_id.id"] {
        assert_eq!(info.type_of(c), "float", "{c}");
    }
    for kind in ["CryptoObject", "CryptoMaterial"] {
        for layer in 0..3 {
            for c in ["R", "G", "B", "A"] {
                assert_eq!(info.type_of(&format!("{kind}{layer:02}.{c}")), "float");
            }
        }
        let key = metadata_key(kind);
        let attr = |f: &str| info.attribute(&format!("cryptomatte/{key}/{f}"));
        assert_eq!(attr("name"), Some(format!("\"{kind}\"").as_str()));
        assert_eq!(attr("hash"), Some("\"MurmurHash3_32\""));
        assert_eq!(attr("conversion"), Some("\"uint32_to_float32\""));
        let manifest = attr("manifest").unwrap();
        let bunny = format!("{:08x}", cryptomatte::name_id("bunny").to_bits());
        assert!(manifest.contains(&bunny), "{manifest}");
    }
    assert_eq!(info.attribute("compression"), Some("\"piz\""));
    assert_header(&info);
}

#[test]
fn oiiotool_reads_each_file_of_a_split_frame() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.exr");
    let f = film();
    let n = f.pixels.len();
    let opts = OutputOptions {
        split: true,
        ..OutputOptions::default()
    };
    exr_layers::write_frame(&path, &f, &layers(n), &coverage(n), &header(), &opts).unwrap();
    let beauty = Info::parse(&oiio_info(&path));
    assert_eq!(beauty.channels.len(), 4);
    assert_header(&beauty);
    assert_eq!(beauty.attribute("compression"), Some("\"zip\""));
    let pass = Info::parse(&oiio_info(&dir.path().join("frame.diffuse_direct.exr")));
    let names: Vec<&str> = pass.channels.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(
        names,
        ["diffuse_direct.R", "diffuse_direct.G", "diffuse_direct.B"]
    );
    assert_eq!(pass.type_of("diffuse_direct.G"), "float");
    assert_eq!(pass.attribute("lucent/pass"), Some("\"diffuse_direct\""));
    assert_header(&pass);
    let crypto = Info::parse(&oiio_info(&dir.path().join("frame.CryptoObject.exr")));
    assert_eq!(crypto.channels.len(), 12);
    let key = metadata_key("CryptoObject");
    assert_eq!(
        crypto.attribute(&format!("cryptomatte/{key}/name")),
        Some("\"CryptoObject\"")
    );
}

#[test]
fn oiiotool_reads_the_header_of_a_real_render() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        "[camera]\nlook_from = [0, 0, 4]\nlook_at = [0, 0, 0]\nresolution = [8, 6]\n\
         [render]\nspp = 2\nseed = 5\n[environment]\nradiance = [0.5, 0.5, 0.5]\n\
         [materials.wax]\ntype = \"subsurface\"\npreset = \"marble\"\n\
         [[shapes]]\ntype = \"sphere\"\nmaterial = \"wax\"\n\
         [output]\nexr_compression = \"rle\"\n",
    )
    .unwrap();
    let exr = dir.path().join("r.exr");
    let out = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args([
            "render", "--quiet", "--accel", "bvh", "--axes", "mis3", "-o",
        ])
        .arg(&exr)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let info = Info::parse(&oiio_info(&exr));
    let names: Vec<&str> = info.channels.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, ["R", "G", "B", "A"]);
    assert_eq!(info.type_of("R"), "float");
    assert_eq!(info.attribute("compression"), Some("\"rle\""));
    assert_eq!(info.attribute("lucent/spp"), Some("2"));
    assert_eq!(info.attribute("lucent/seed"), Some("\"5\""));
    assert_eq!(info.attribute("lucent/resolution"), Some("8, 6"));
    assert_eq!(info.attribute("lucent/backend"), Some("\"bvh\""));
    assert_eq!(info.attribute("lucent/integrator"), Some("\"path\""));
    let sampling = info.attribute("lucent/sampling").unwrap();
    assert!(sampling.contains("axes=mis3"), "{sampling}");
    let sha = info
        .attribute("lucent/sceneSha256")
        .unwrap()
        .trim_matches('"');
    assert_eq!(sha.len(), 64);
    assert!(info.attribute("lucent/renderTime").is_some());
    // the render plan, as the JSON `--explain=json` prints (on one line)
    let plan = info.attribute("lucent/plan").unwrap();
    let plan: lucent::integrator::plan::Explanation =
        serde_json::from_str(&plan[1..plan.len() - 1]).unwrap();
    assert_eq!(plan.integrator, "path");
    assert_eq!(plan.probe_queries.method, "on");
    assert_eq!(plan.environment.method, "escaping rays");
    // level of detail (the default, auto) first, then the diffusion
    use lucent::integrator::plan::explain::SubsurfaceMethod;
    let methods = &plan.materials[0].subsurface;
    assert!(
        matches!(methods[0], SubsurfaceMethod::LevelOfDetail { .. }),
        "{methods:?}"
    );
    let axes = match &methods[1] {
        SubsurfaceMethod::Diffusion { axes, .. } => axes,
        m => panic!("{m:?}"),
    };
    assert_eq!(axes, "mis3");
    // the command line overrides the scene's [output]
    let out = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", "--quiet", "--exr-compression", "piz", "-o"])
        .arg(&exr)
        .arg(&scene)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let info = Info::parse(&oiio_info(&exr));
    assert_eq!(info.attribute("compression"), Some("\"piz\""));
}

/// `lucent ARGS` in `dir`, which must succeed.
fn lucent_ok(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A single render and the merge of its parts: the same header attributes
/// as oiiotool reads them, but for the render time (the merge cannot know
/// it) and the date; the plan names the passes written, the backend is
/// the one that ran, the camera is there as the standard matrices, and
/// the build and host are recorded. Caught: a merge that writes only spp
/// and seed; a plan built without the passes (`aovs: none` with --aov).
#[test]
fn a_single_and_a_merged_frame_carry_the_same_provenance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("s.toml"),
        "[camera]\nlook_from = [0, 1, 4]\nlook_at = [0, 0, 0]\nresolution = [8, 6]\n\
         [render]\nspp = 4\nseed = 5\n[environment]\nradiance = [0.5, 0.5, 0.5]\n\
         [materials.wax]\ntype = \"subsurface\"\npreset = \"marble\"\n\
         [[shapes]]\ntype = \"sphere\"\nmaterial = \"wax\"\n",
    )
    .unwrap();
    let common = [
        "render", "--quiet", "--accel", "bvh", "--aov", "albedo,Z", "s.toml",
    ];
    let with = |extra: &[&'static str]| [&common[..], extra].concat();
    lucent_ok(d, &with(&["-o", "single.exr"]));
    lucent_ok(d, &with(&["--samples", "0..1", "-o", "p0.exr"]));
    lucent_ok(d, &with(&["--samples", "1..4", "-o", "p1.exr"]));
    lucent_ok(
        d,
        &["merge", "--quiet", "-o", "merged.exr", "p1.exr", "p0.exr"],
    );
    let single = Info::parse(&oiio_info(&d.join("single.exr")));
    let merged = Info::parse(&oiio_info(&d.join("merged.exr")));
    let own = |i: &Info| -> Vec<(String, String)> {
        i.attributes
            .iter()
            .filter(|(n, _)| n != "lucent/renderTime" && n != "DateTime" && n != "capDate")
            .cloned()
            .collect()
    };
    assert_eq!(own(&single), own(&merged));
    for name in [
        "lucent/scene",
        "lucent/sceneSha256",
        "lucent/integrator",
        "lucent/maxDepth",
        "lucent/sampling",
        "lucent/build",
        "lucent/hosts",
        "worldToCamera",
        "worldToNDC",
    ] {
        assert!(
            merged.attribute(name).is_some(),
            "{name} missing: {:?}",
            merged.attributes
        );
    }
    assert!(merged
        .attribute("capDate")
        .or(merged.attribute("DateTime"))
        .is_some());
    assert!(single.attribute("lucent/renderTime").is_some());
    assert_eq!(merged.attribute("lucent/backend"), Some("\"bvh\""));
    let plan = merged.attribute("lucent/plan").unwrap();
    assert!(
        plan.contains("recorded") && plan.contains("albedo"),
        "{plan}"
    );
}

/// `oiiotool PATH --cut WxH+X+Y --printstats`: per channel, (min, max)
/// over that window.
fn oiio_min_max(path: &Path, window: &str) -> Vec<(f64, f64)> {
    let out = Command::new("oiiotool")
        .arg(path)
        .args(["--cut", window, "--printstats"])
        .output()
        .expect("cannot run oiiotool");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let row = |key: &str| -> Vec<f64> {
        let line = text
            .lines()
            .find_map(|l| l.trim().strip_prefix(key))
            .unwrap_or_else(|| panic!("no {key} in {text}"));
        line.split_whitespace()
            .filter_map(|v| v.parse().ok())
            .collect()
    };
    row("Stats Min:")
        .into_iter()
        .zip(row("Stats Max:"))
        .collect()
}

/// Whether `name` matches `pattern`, where `<…>` stands for one or more
/// letters, digits or `_`.
fn matches_pattern(pattern: &str, name: &str) -> bool {
    match pattern.find('<') {
        None => pattern == name,
        Some(i) => {
            let end = pattern[i..].find('>').map(|j| i + j + 1).unwrap();
            let (head, rest) = (&pattern[..i], &pattern[end..]);
            let Some(tail) = name.strip_prefix(head) else {
                return false;
            };
            (1..=tail.len()).any(|k| {
                tail[..k]
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_')
                    && matches_pattern(rest, &tail[k..])
            })
        }
    }
}

/// The rows of docs/output.md's "Compositing conventions" table: channel
/// patterns, type, miss value.
fn conventions_table() -> Vec<(Vec<String>, String, String)> {
    let doc = std::fs::read_to_string("docs/output.md").unwrap();
    let (_, after) = doc.split_once("### Compositing conventions").unwrap();
    after
        .lines()
        .skip_while(|l| !l.starts_with("| channels |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let channels = cells[1]
                .split('`')
                .map(str::trim)
                .filter(|c| !c.is_empty())
                .map(String::from)
                .collect();
            (channels, cells[2].to_string(), cells[3].to_string())
        })
        .collect()
}

/// The conventions table of docs/output.md is what a render with every
/// pass writes, as oiiotool reads it: every channel matches one row, of
/// the row's type, and a pixel that sees only the environment has each
/// row's miss value (depth finite). Caught: depth written as `Z.Z` or
/// +∞ on a miss, light groups without A, a row for a channel no longer
/// written.
#[test]
fn the_conventions_table_is_what_a_render_writes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("s.toml"),
        "[camera]\nlook_from = [0, 0, 4]\nlook_at = [0, 0, 0]\nresolution = [16, 12]\n\
         [render]\nspp = 2\n[environment]\nradiance = [0.5, 0.5, 0.5]\n\
         [materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n\
         [materials.lamp]\ntype = \"diffuse\"\nalbedo = [0, 0, 0]\n\
         [[shapes]]\ntype = \"sphere\"\nmaterial = \"white\"\n\
         [[shapes]]\ntype = \"quad\"\nmaterial = \"lamp\"\nemission = [4, 4, 4]\n\
         light_group = \"key\"\nrotate = [[90, 1, 0, 0]]\ntranslate = [0, 5, 0]\n",
    )
    .unwrap();
    lucent_ok(
        d,
        &["render", "s.toml", "--quiet", "--aov", "all", "-o", "f.exr"],
    );
    let f = d.join("f.exr");
    let info = Info::parse(&oiio_info(&f));
    let table = conventions_table();
    assert!(table.len() >= 10, "{table:?}");
    let corner = oiio_min_max(&f, "2x2+0+0");
    let whole = oiio_min_max(&f, "16x12+0+0");
    assert_eq!(corner.len(), info.channels.len());
    let mut used = vec![false; table.len()];
    for (k, (name, ty)) in info.channels.iter().enumerate() {
        // the most specific row: the matching pattern with the most fixed
        // characters (`RGBA_<group>.A` before `<path>.A`)
        let fixed = |p: &str| {
            let mut inside = false;
            p.chars()
                .filter(|&c| {
                    inside = (inside || c == '<') && c != '>';
                    !inside && c != '>'
                })
                .count()
        };
        let row = table
            .iter()
            .enumerate()
            .flat_map(|(i, (pats, _, _))| pats.iter().map(move |p| (i, p)))
            .filter(|(_, p)| matches_pattern(p, name))
            .max_by_key(|(_, p)| fixed(p))
            .map(|(i, _)| i)
            .unwrap_or_else(|| panic!("channel {name} is in no row of the table"));
        used[row] = true;
        let (_, want_ty, miss) = &table[row];
        assert!(
            want_ty.starts_with(ty.as_str()),
            "{name}: {ty}, the table says {want_ty}"
        );
        if let Ok(v) = miss.parse::<f64>() {
            assert_eq!(
                corner[k],
                (v, v),
                "{name} where only the environment is seen"
            );
        }
        // finite everywhere but the one-sample variance
        assert!(
            whole[k].1.is_finite() && whole[k].0.is_finite(),
            "{name}: {:?}",
            whole[k]
        );
    }
    for (row, u) in table.iter().zip(used) {
        assert!(u, "no channel written for the row {:?}", row.0);
    }
    // not vacuous: the sphere is hit in the middle, nearer than the far value
    let z = info.channels.iter().position(|c| c.0 == "Z").unwrap();
    let mid = oiio_min_max(&f, "2x2+7+5");
    assert!(mid[z].1 < 4.0, "{:?}", mid[z]);
}
