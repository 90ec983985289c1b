//! Tests of the EXR layer writer and reader (the parent module).

use super::*;
use crate::geometry::Vec3;

fn film() -> Film {
    let mut f = Film::new(3, 2);
    for (i, p) in f.pixels.iter_mut().enumerate() {
        *p = Vec3::new(i as f32 + 0.1, 1e-7 * i as f32, 70000.0 + i as f32);
    }
    f
}

pub(crate) fn layers() -> Vec<Layer> {
    let n = 6;
    let rgb = |s: f32| (0..n * 3).map(|i| s * (i as f32 + 0.3)).collect();
    vec![
        Layer {
            name: "diffuse_direct".into(),
            channels: vec!["R".into(), "G".into(), "B".into()],
            kind: LayerKind::Light,
            values: rgb(1.0 / 3.0),
        },
        Layer {
            name: "depth".into(),
            channels: vec!["Z".into()],
            kind: LayerKind::Data,
            values: (0..n).map(|i| 1000.0 + i as f32 / 7.0).collect(),
        },
        Layer {
            name: "object_id".into(),
            channels: vec!["id".into()],
            kind: LayerKind::Id,
            values: (0..n).map(|i| (16_777_000 + i) as f32).collect(),
        },
    ]
}

pub(crate) fn coverage() -> Vec<Coverage> {
    vec![Coverage {
        kind: "object".into(),
        names: vec!["bunny".into(), "floor".into()],
        pixels: vec![
            vec![(0, 1.0)],
            vec![(0, 0.25), (1, 0.75)],
            vec![],
            vec![(1, 1.0)],
            vec![(1, 0.5)],
            vec![(0, 0.5), (1, 0.5)],
        ],
    }]
}

fn header() -> FrameHeader {
    FrameHeader {
        scene_path: Some("scenes/x.toml".into()),
        spp: Some(4),
        seed: Some(7),
        render_seconds: Some(0.25),
        ..FrameHeader::default()
    }
}

fn channels(path: &Path) -> Vec<(String, FlatSamples)> {
    let img = exr::prelude::read_all_flat_layers_from_file(path).unwrap();
    assert_eq!(img.layer_data.len(), 1);
    img.layer_data[0]
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.clone()))
        .collect()
}

#[test]
fn every_pass_reads_back_with_its_name_type_and_values() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("f.exr");
    let opts = OutputOptions {
        precision: Precision::Half,
        ..OutputOptions::default()
    };
    let (f, l, c) = (film(), layers(), coverage());
    write_frame(&p, &f, &l, &c, &header(), &opts).unwrap();
    let ch = channels(&p);
    let get = |n: &str| {
        &ch.iter()
            .find(|c| c.0 == n)
            .unwrap_or_else(|| panic!("{n}"))
            .1
    };
    let names: Vec<&str> = ch.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names.len(), 4 + 3 + 1 + 1 + 12, "{names:?}");
    // beauty: float, exact
    let FlatSamples::F32(r) = get("R") else {
        panic!("R not float")
    };
    assert_eq!(r, &f.pixels.iter().map(|p| p.x).collect::<Vec<_>>());
    let FlatSamples::F32(b) = get("B") else {
        panic!("B not float")
    };
    assert_eq!(b[1], 70001.0); // beyond half's range: beauty stays float
                               // light pass at half: rounded to nearest half
    let FlatSamples::F16(g) = get("diffuse_direct.G") else {
        panic!("not half")
    };
    let want: Vec<f16> = l[0]
        .values
        .iter()
        .skip(1)
        .step_by(3)
        .map(|&v| f16::from_f32(v))
        .collect();
    assert_eq!(g, &want);
    // data and IDs stay float, exact
    let FlatSamples::F32(z) = get("depth.Z") else {
        panic!("depth not float")
    };
    assert_eq!(z, &l[1].values);
    let FlatSamples::F32(id) = get("object_id.id") else {
        panic!("id not float")
    };
    assert_eq!(id, &l[2].values);
    // Cryptomatte: rank 0 of pixel 1 is floor at 0.75
    let FlatSamples::F32(id0) = get("CryptoObject00.R") else {
        panic!()
    };
    let FlatSamples::F32(cov0) = get("CryptoObject00.G") else {
        panic!()
    };
    assert_eq!((id0[1], cov0[1]), (cryptomatte::name_id("floor"), 0.75));
    assert_eq!((id0[2], cov0[2]), (0.0, 0.0));
    // header
    let a = read_attributes(&p).unwrap();
    let key = cryptomatte::metadata_key("CryptoObject");
    assert_eq!(
        text_attribute(&a, &format!("cryptomatte/{key}/name")).as_deref(),
        Some("CryptoObject")
    );
    assert_eq!(
        text_attribute(&a, &format!("cryptomatte/{key}/manifest")),
        Some(cryptomatte::manifest(&c[0].names))
    );
    assert_eq!(
        text_attribute(&a, "software"),
        Some(format!("lucent {}", env!("CARGO_PKG_VERSION")))
    );
    assert!(a.contains(&("lucent/spp".into(), AttributeValue::I32(4))));
    // float precision: the light pass is float too
    write_frame(&p, &f, &l, &c, &header(), &OutputOptions::default()).unwrap();
    assert!(matches!(
        get_owned(&p, "diffuse_direct.G"),
        FlatSamples::F32(_)
    ));
}

fn get_owned(p: &Path, name: &str) -> FlatSamples {
    channels(p).into_iter().find(|c| c.0 == name).unwrap().1
}

#[test]
fn same_frame_same_bytes_for_every_compression() {
    let dir = tempfile::tempdir().unwrap();
    for comp in ["none", "rle", "zips", "zip", "piz"] {
        let opts = OutputOptions {
            compression: ExrCompression::parse(comp).unwrap(),
            ..OutputOptions::default()
        };
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        for p in [&a, &b] {
            write_frame(p, &film(), &layers(), &coverage(), &header(), &opts).unwrap();
        }
        assert_eq!(
            std::fs::read(&a).unwrap(),
            std::fs::read(&b).unwrap(),
            "{comp}"
        );
        // and lossless
        assert_eq!(Film::read_exr(&a).unwrap(), film(), "{comp}");
        assert_eq!(channels(&a), channels(&dir.path().join("b.exr")));
    }
}

#[test]
fn sorting_the_header_keeps_the_file_readable_and_its_length() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.exr");
    film().write_exr(&p).unwrap();
    let mut bytes = std::fs::read(&p).unwrap();
    let before = bytes.clone();
    sort_header_attributes(&mut bytes).unwrap();
    assert_eq!(bytes.len(), before.len());
    // today's header (required attributes first) is not in name order
    assert_ne!(bytes, before);
    std::fs::write(&p, &bytes).unwrap();
    assert_eq!(Film::read_exr(&p).unwrap(), film());
    assert!(sort_header_attributes(&mut bytes[..20].to_vec()).is_err());
    assert!(sort_header_attributes(&mut b"not an exr".to_vec()).is_err());
}

#[test]
fn a_header_longer_than_the_first_read_is_sorted_too() {
    // a manifest of 4000 names: a header of about 100 kB
    let mut c = coverage();
    c[0].names = (0..4000).map(|i| format!("object_number_{i}")).collect();
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    for p in [&a, &b] {
        write_frame(p, &film(), &[], &c, &header(), &OutputOptions::default()).unwrap();
    }
    let bytes = std::fs::read(&a).unwrap();
    assert!(bytes.len() > 100_000);
    assert_eq!(bytes, std::fs::read(&b).unwrap());
    let key = cryptomatte::metadata_key("CryptoObject");
    let m = text_attribute(
        &read_attributes(&a).unwrap(),
        &format!("cryptomatte/{key}/manifest"),
    );
    assert_eq!(m, Some(cryptomatte::manifest(&c[0].names)));
    assert_eq!(Film::read_exr(&a).unwrap(), film());
}

#[test]
fn beauty_only_frame_has_the_pixels_of_the_plain_writer() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
    film().write_exr(&a).unwrap();
    write_frame(&b, &film(), &[], &[], &header(), &OutputOptions::default()).unwrap();
    assert_eq!(channels(&a), channels(&b));
    assert_eq!(Film::read_exr(&b).unwrap(), film());
}

#[test]
fn split_writes_one_file_per_pass_all_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("f.exr");
    let opts = OutputOptions {
        split: true,
        preview: Some(Preview {
            tonemap: ToneMap::Clamp,
            exposure: 0.0,
        }),
        ..OutputOptions::default()
    };
    write_frame(&p, &film(), &layers(), &coverage(), &header(), &opts).unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "f.CryptoObject.exr",
            "f.depth.exr",
            "f.diffuse_direct.exr",
            "f.exr",
            "f.object_id.exr",
            "f.png"
        ]
    );
    let beauty: Vec<String> = channels(&p).into_iter().map(|c| c.0).collect();
    assert_eq!(beauty, ["A", "B", "G", "R"]);
    let depth = dir.path().join("f.depth.exr");
    assert_eq!(channels(&depth).len(), 1);
    let a = read_attributes(&depth).unwrap();
    assert_eq!(text_attribute(&a, "lucent/pass").as_deref(), Some("depth"));
    assert_eq!(
        text_attribute(&a, "lucent/scene").as_deref(),
        Some("scenes/x.toml")
    );
    let crypto = read_attributes(&dir.path().join("f.CryptoObject.exr")).unwrap();
    assert!(crypto.iter().any(|x| x.0.starts_with("cryptomatte/")));
    assert!(!read_attributes(&p)
        .unwrap()
        .iter()
        .any(|x| x.0.starts_with("cryptomatte/")));
    // one destination that cannot be replaced: nothing changes
    for n in &names {
        std::fs::remove_file(dir.path().join(n)).unwrap();
    }
    std::fs::create_dir(dir.path().join("f.depth.exr")).unwrap();
    assert!(write_frame(&p, &film(), &layers(), &coverage(), &header(), &opts).is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn malformed_passes_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("f.exr");
    let (f, c) = (film(), coverage());
    let try_with = |edit: &dyn Fn(&mut Vec<Layer>)| {
        let mut l = layers();
        edit(&mut l);
        write_frame(&p, &f, &l, &c, &header(), &OutputOptions::default())
    };
    assert!(try_with(&|l| l[0].name = "a.b".into()).is_err());
    assert!(try_with(&|l| l[0].name = "R".into()).is_err());
    assert!(try_with(&|l| l[0].name = "CryptoObject00".into()).is_err());
    assert!(try_with(&|l| l[1].name = "diffuse_direct".into()).is_err());
    assert!(try_with(&|l| l[0].channels[2] = "R".into()).is_err());
    assert!(try_with(&|l| l[0].channels.clear()).is_err());
    assert!(try_with(&|l| l[1].values.pop().map(|_| ()).unwrap_or(())).is_err());
    assert!(try_with(&|_| ()).is_ok());
    std::fs::remove_file(&p).unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    assert_eq!(
        split_path(Path::new("out/a.b.exr"), "sss_direct"),
        Path::new("out/a.b.sss_direct.exr")
    );
}
