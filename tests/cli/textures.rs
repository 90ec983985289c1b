//! Textures that cannot be used are scene errors: exit 2 naming the file,
//! its line and the field, and why, with nothing written; a textured scene
//! renders and `--stats` reports the textures' memory.

use std::path::Path;
use std::process::Command;

const CAM: &str = "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\nresolution = [4, 4]\n\
                   [render]\nspp = 2\n[environment]\nradiance = [1, 1, 1]\n";

/// Renders `scene` (beside what `setup` writes) with `args`: exit code,
/// stderr, and whether the output was written.
fn render(scene: &str, args: &[&str], setup: impl FnOnce(&Path)) -> (Option<i32>, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    setup(dir.path());
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out.exr");
    let res = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .arg("render")
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .args(args)
        .output()
        .expect("run lucent");
    (
        res.status.code(),
        String::from_utf8_lossy(&res.stderr).into_owned(),
        out.exists(),
    )
}

fn png(path: &Path, w: u32, h: u32) {
    image::RgbImage::from_pixel(w, h, image::Rgb([100, 150, 200]))
        .save(path)
        .unwrap();
}

/// A diffuse quad with the texture `tex` (its table's body `def`).
fn scene(def: &str, material_key: &str) -> String {
    format!(
        "{CAM}[textures.t]\n{def}\n[materials.m]\ntype = \"diffuse\"\n{material_key}\n\
         [[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\n"
    )
}

/// Caught: a texture two materials share counted once per material
/// (`Scene::textures` without its check for one already seen).
#[test]
fn a_textured_scene_renders_and_reports_its_texture_memory() {
    // a second material and shape read the same texture: held once
    let s = scene("file = \"a.png\"", "albedo_texture = \"t\"")
        + "[materials.n]\ntype = \"diffuse\"\nalbedo_texture = \"t\"\n\
           [[shapes]]\ntype = \"sphere\"\nmaterial = \"n\"\nscale = 0.3\n";
    let (code, stderr, written) = render(&s, &["--stats"], |d| png(&d.join("a.png"), 16, 8));
    assert_eq!(code, Some(0), "{stderr}");
    assert!(written);
    // 16×8 + 8×4 + 4×2 + 2×1 + 1×1 texels of 12 bytes
    let bytes = (128 + 32 + 8 + 2 + 1) * 12;
    let want = format!("textures: 1, {bytes} bytes");
    assert!(stderr.contains(&want), "no {want:?} in {stderr}");
}

#[test]
fn unusable_textures_exit_2_naming_file_line_field_and_reason() {
    type Setup = Box<dyn FnOnce(&Path)>;
    let albedo = "albedo_texture = \"t\"";
    let rows: Vec<(String, Setup, &str, &str)> = vec![
        (
            scene("file = \"absent.png\"", albedo),
            Box::new(|_| {}),
            "textures.t.file",
            "absent.png: cannot read it",
        ),
        (
            scene("file = \"a.gif\"", albedo),
            Box::new(|d| std::fs::write(d.join("a.gif"), b"GIF89a").unwrap()),
            "textures.t.file",
            "unsupported texture format \"gif\"",
        ),
        (
            scene("file = \"cut.jpg\"", albedo),
            Box::new(|d| std::fs::write(d.join("cut.jpg"), b"\xff\xd8\xff").unwrap()),
            "textures.t.file",
            "cut.jpg: cannot read it",
        ),
        (
            scene("file = \"bad.png\"", albedo),
            Box::new(|d| std::fs::write(d.join("bad.png"), b"\x89PNG\r\n\x1a\nnot").unwrap()),
            "textures.t.file",
            "bad.png: cannot read it",
        ),
        (
            scene("file = \"big.png\"", albedo),
            Box::new(|d| {
                image::GrayImage::new(8200, 4100)
                    .save(d.join("big.png"))
                    .unwrap()
            }),
            "textures.t.file",
            "the image is 8200×4100 = 33620000 texels, more than the 33554432",
        ),
        (
            scene("file = \"nan.exr\"", albedo),
            Box::new(|d| {
                exr::prelude::write_rgb_file(d.join("nan.exr"), 4, 2, |x, y| {
                    let g = if (x, y) == (3, 1) { f32::INFINITY } else { 1.0 };
                    (1.0, g, 1.0)
                })
                .unwrap()
            }),
            "textures.t.file",
            "texel (column 3, row 1) has G = inf",
        ),
        (
            scene("file = \"a.png\"\ncolor_space = \"rec2020\"", albedo),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "textures.t.color_space",
            "expected \"srgb\" or \"linear\"",
        ),
        (
            scene("file = \"a.png\"\nwrap = \"mirror\"", albedo),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "textures.t.wrap",
            "expected \"repeat\" or \"clamp\"",
        ),
        (
            scene("file = \"a.png\"", "albedo_texture = \"wood\""),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "materials.m.albedo_texture",
            "unknown texture \"wood\" (defined: t)",
        ),
        (
            scene("file = \"a.png\"", "albedo = [1, 1, 1]\nnormal_map = \"t\""),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "materials.m.normal_map",
            "a normal map is data: give it color_space = \"linear\"",
        ),
        (
            scene("file = \"a.png\"", "albedo = [1, 1, 1]\nbump = \"t\""),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "materials.m.bump",
            "a height map is data: give it color_space = \"linear\"",
        ),
        (
            scene(
                "file = \"a.png\"\ncolor_space = \"linear\"",
                "albedo = [1, 1, 1]\nnormal_map = \"t\"\nbump = \"t\"",
            ),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "materials.m.bump",
            "give either `normal_map` or `bump`",
        ),
        (
            scene("file = \"a.png\"", "albedo = [1, 1, 1]\nbump_scale = 0.1"),
            Box::new(|d| png(&d.join("a.png"), 2, 2)),
            "materials.m.bump_scale",
            "`bump_scale` without `bump`",
        ),
    ];
    for (scene, setup, field, fragment) in rows {
        refused(&scene, setup, field, fragment);
    }
}

/// `scene` (with the files `setup` writes) exits 2 with `fragment` in its
/// message, naming the scene file's line and `field`, and writes nothing.
fn refused(scene: &str, setup: impl FnOnce(&Path), field: &str, fragment: &str) {
    let (code, stderr, written) = render(scene, &[], setup);
    assert_eq!(code, Some(2), "{fragment:?}: {stderr}");
    assert!(
        stderr.contains(fragment),
        "stderr lacks {fragment:?}: {stderr}"
    );
    assert!(
        stderr.contains("scene.toml:") && stderr.contains(&format!("field `{field}`")),
        "no line or field {field}: {stderr}"
    );
    assert!(!written, "output written for {fragment:?}");
}

/// A roughness texture that cannot be used: declared sRGB (a roughness
/// is data), unknown, or on a material without a roughness. Exit 2 naming
/// the file, line and field, nothing written.
#[test]
fn unusable_roughness_textures_exit_2_naming_file_line_field_and_reason() {
    let conductor = |tex: &str, keys: &str| {
        format!(
            "{CAM}[textures.t]\n{tex}\n[materials.m]\ntype = \"conductor\"\n\
             metal = \"gold\"\n{keys}\n[[shapes]]\ntype = \"quad\"\nmaterial = \"m\"\n"
        )
    };
    let linear = "file = \"a.png\"\ncolor_space = \"linear\"";
    let rows = [
        (
            conductor("file = \"a.png\"", "roughness_texture = \"t\""),
            "materials.m.roughness_texture",
            "a roughness is data: give it color_space = \"linear\"",
        ),
        (
            conductor(linear, "roughness_texture = \"rough\""),
            "materials.m.roughness_texture",
            "unknown texture \"rough\" (defined: t)",
        ),
        (
            scene(linear, "albedo = [1, 1, 1]\nroughness_texture = \"t\""),
            "materials.m.roughness_texture",
            "`roughness_texture` does not apply to type \"diffuse\"",
        ),
    ];
    for (scene, field, fragment) in rows {
        refused(&scene, |d| png(&d.join("a.png"), 2, 2), field, fragment);
    }
}

/// An OBJ without texture coordinates under a textured material: exit 2
/// naming the OBJ file and the shape's field.
#[test]
fn an_obj_without_texture_coordinates_under_a_texture_exits_2() {
    let s = format!(
        "{CAM}[textures.t]\nfile = \"a.png\"\n[materials.m]\ntype = \"diffuse\"\n\
         albedo_texture = \"t\"\n[[shapes]]\ntype = \"obj\"\nfile = \"tri.obj\"\nmaterial = \"m\"\n"
    );
    let (code, stderr, written) = render(&s, &[], |d| {
        png(&d.join("a.png"), 2, 2);
        std::fs::write(d.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    });
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("tri.obj") && stderr.contains("shapes[0].file"),
        "{stderr}"
    );
    assert!(stderr.contains("no texture coordinates"), "{stderr}");
    assert!(!written);
    // with `vt` on every face vertex it renders
    let (code, stderr, _) = render(&s, &[], |d| {
        png(&d.join("a.png"), 2, 2);
        std::fs::write(
            d.join("tri.obj"),
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n",
        )
        .unwrap();
    });
    assert_eq!(code, Some(0), "{stderr}");
}

/// A subsurface slab with `material_keys` under the textures `a` (sRGB)
/// and `k` (linear).
#[cfg(feature = "subsurface")]
fn subsurface_scene(material_keys: &str) -> String {
    format!(
        "{CAM}[textures.a]\nfile = \"a.png\"\n\
         [textures.k]\nfile = \"a.png\"\ncolor_space = \"linear\"\n\
         [materials.m]\ntype = \"subsurface\"\n{material_keys}\n\
         [[shapes]]\ntype = \"box\"\nmaterial = \"m\"\n"
    )
}

/// The mistakes: a subsurface texture key accepted where the parameter
/// cannot follow it (a preset's albedo), a length factor read through
/// the sRGB curve, an unknown texture name; and `--explain` silent about
/// what is textured. Each refusal exits 2 naming the line and the field.
#[cfg(feature = "subsurface")]
#[test]
fn subsurface_textures_are_checked_and_explained() {
    let rows = [
        (
            "preset = \"marble\"\nalbedo_texture = \"a\"",
            "materials.m.albedo_texture",
            "a textured albedo needs the artist form",
        ),
        (
            "albedo = [0.5, 0.5, 0.5]\ndmfp = [1, 1, 1]\ndmfp_texture = \"a\"",
            "materials.m.dmfp_texture",
            "a length factor is data: give it color_space = \"linear\"",
        ),
        (
            "dmfp = [1, 1, 1]\nalbedo_texture = \"skin\"",
            "materials.m.albedo_texture",
            "unknown texture \"skin\" (defined: a, k)",
        ),
    ];
    for (keys, field, fragment) in rows {
        let (code, stderr, written) = render(&subsurface_scene(keys), &[], |d| {
            png(&d.join("a.png"), 2, 2)
        });
        assert_eq!(code, Some(2), "{fragment:?}: {stderr}");
        assert!(stderr.contains(fragment), "lacks {fragment:?}: {stderr}");
        assert!(
            stderr.contains("scene.toml:") && stderr.contains(&format!("field `{field}`")),
            "no line or field {field}: {stderr}"
        );
        assert!(!written);
    }
    // a length factor of 10⁹ takes Rmax past the supported range
    let long = subsurface_scene("albedo = [0.5, 0.5, 0.5]\ndmfp = [1, 1, 1]\ndmfp_texture = \"k\"")
        .replace(
            "file = \"a.png\"\ncolor_space",
            "file = \"long.exr\"\ncolor_space",
        );
    let (code, stderr, written) = render(&long, &[], |d| {
        png(&d.join("a.png"), 2, 2);
        exr::prelude::write_rgb_file(d.join("long.exr"), 2, 2, |x, _| {
            let g = if x == 1 { 1e9 } else { 1.0 };
            (1.0, g, 1.0)
        })
        .unwrap()
    });
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("field `materials.m.dmfp_texture`")
            && stderr.contains("largest texels")
            && stderr.contains("beyond 1e7"),
        "{stderr}"
    );
    assert!(!written);
    let s = subsurface_scene("dmfp = [1, 1, 1]\nalbedo_texture = \"a\"\ndmfp_texture = \"k\"");
    let dir = tempfile::tempdir().unwrap();
    png(&dir.path().join("a.png"), 2, 2);
    std::fs::write(dir.path().join("scene.toml"), s).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", "--explain"])
        .arg(dir.path().join("scene.toml"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    assert!(
        text.contains("textures") && text.contains("albedo_texture=a dmfp_texture=k"),
        "{text}"
    );
}
