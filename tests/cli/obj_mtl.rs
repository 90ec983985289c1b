//! An OBJ with an MTL library renders without scene materials: each
//! `usemtl` part in its MTL colour or texture at the right place, a scene
//! material of the same name overrides, ignored keys are listed on
//! stderr, and a key lucent does not know is an error at its line.

use std::path::Path;
use std::process::Command;

use lucent::film::Film;

/// A 2 × 2 square facing +z filling an 8 × 8 frame, under white light:
/// each pixel is the albedo there.
const VIEW: &str = "[camera]\nlook_from = [0, 0, 5]\nlook_at = [0, 0, 0]\n\
    fov_y = 22.619864948040426\nresolution = [8, 8]\n[render]\nspp = 16\nmax_depth = 2\n\
    [environment]\nradiance = [1, 1, 1]\n";

/// Left half (x < 0) under `usemtl red`, right half under `usemtl tex`
/// with u from ¼ to ¾ (no wrap at the edges).
const OBJ: &str = "mtllib two.mtl\nv -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\nv 1 -1 0\nv 1 1 0\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.25 0\nvt 0.75 0\nvt 0.75 1\nvt 0.25 1\n\
    usemtl red\nf 1/1 2/2 3/3 4/4\nusemtl tex\nf 2/5 5/6 6/7 3/8\n";

/// Writes the OBJ, `mtl` and a 4 × 1 texture green, green, blue, blue;
/// renders `extra` + the OBJ shape: exit code, stderr, the frame.
fn render(mtl: &str, extra: &str) -> (Option<i32>, String, Option<Film>) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("two.obj"), OBJ).unwrap();
    std::fs::write(d.join("two.mtl"), mtl).unwrap();
    image::RgbImage::from_fn(4, 1, |x, _| {
        image::Rgb(if x < 2 { [0, 255, 0] } else { [0, 0, 255] })
    })
    .save(d.join("gb.png"))
    .unwrap();
    let scene = format!("{VIEW}{extra}[[shapes]]\ntype = \"obj\"\nfile = \"two.obj\"\n");
    render_scene(d, &scene)
}

/// Renders `scene` as `scene.toml` in `d`: exit code, stderr, the frame.
fn render_scene(d: &Path, scene: &str) -> (Option<i32>, String, Option<Film>) {
    let path = d.join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = d.join("out.exr");
    let res = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render", "--quiet"])
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run lucent");
    let film = out.exists().then(|| Film::read_exr(&out).unwrap());
    let stderr = String::from_utf8_lossy(&res.stderr).into_owned();
    (res.status.code(), stderr, film)
}

fn near(film: &Film, x: u32, y: u32, want: [f32; 3]) {
    let p = film.get(x, y);
    for (got, w) in [p.x, p.y, p.z].iter().zip(want) {
        assert!(
            (got - w).abs() < 0.02,
            "pixel ({x}, {y}) is {p:?}, expected {want:?}"
        );
    }
}

const MTL: &str = "newmtl red\nKd 1 0 0\nKa 0 0 0\nillum 2\nnewmtl tex\nmap_Kd gb.png\n";

#[test]
fn each_mtl_material_renders_where_its_faces_are() {
    let (code, stderr, film) = render(MTL, "");
    assert_eq!(code, Some(0), "{stderr}");
    let film = film.unwrap();
    for y in 1..7 {
        near(&film, 1, y, [1.0, 0.0, 0.0]);
        near(&film, 2, y, [1.0, 0.0, 0.0]);
        // pixel column 4 sees u ∈ [¼, ⅜], between the green texels'
        // centres; column 7 u ∈ [⅝, ¾], between the blue ones'
        near(&film, 4, y, [0.0, 1.0, 0.0]);
        near(&film, 7, y, [0.0, 0.0, 1.0]);
    }
    assert!(
        stderr.contains("two.mtl: ignored MTL keys: Ka (line 3), illum (line 4)"),
        "{stderr}"
    );
}

#[test]
fn a_scene_material_of_the_same_name_overrides_the_mtl() {
    let extra = "[materials.red]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\n";
    let (code, stderr, film) = render(MTL, extra);
    assert_eq!(code, Some(0), "{stderr}");
    let film = film.unwrap();
    near(&film, 1, 4, [0.5, 0.5, 0.5]);
    near(&film, 7, 4, [0.0, 0.0, 1.0]);
}

#[test]
fn bad_mtl_input_exits_2_naming_file_and_line() {
    for (mtl, fragment) in [
        (
            "newmtl red\nKd 1 0 0\nmap_Xyz a.png\nnewmtl tex\nmap_Kd gb.png\n",
            "two.mtl:3",
        ),
        (
            "newmtl red\nKd 1 0 0\nnewmtl tex\nmap_Kd absent.png\n",
            "two.mtl:4",
        ),
        (
            "newmtl red\nKd 1 0 0\nnewmtl other\nKd 1 1 1\n",
            "two.obj:18",
        ),
    ] {
        let (code, stderr, film) = render(mtl, "");
        assert_eq!(code, Some(2), "{mtl}: {stderr}");
        assert!(stderr.contains(fragment), "no {fragment:?} in {stderr}");
        assert!(film.is_none(), "output written for {mtl}");
    }
}

/// Renders the two-part OBJ (its `usemtl tex` part under `tex_mtl`) with
/// a grey ramp `h.png` beside it, the shape's `shape_keys` and the scene's
/// `extra` tables, under a light from the side: exit code, stderr, frame.
fn render_bumped(
    tex_mtl: &str,
    shape_keys: &str,
    extra: &str,
) -> (Option<i32>, String, Option<Film>) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("two.obj"), OBJ).unwrap();
    std::fs::write(
        d.join("two.mtl"),
        format!("newmtl red\nKd 1 1 1\nnewmtl tex\n{tex_mtl}"),
    )
    .unwrap();
    image::RgbImage::from_fn(4, 1, |x, _| image::Rgb([(x * 85) as u8; 3]))
        .save(d.join("h.png"))
        .unwrap();
    let scene = format!(
        "{VIEW}[[lights]]\ntype = \"distant\"\ndirection = [-1, 0, -1]\nirradiance = [2, 2, 2]\n\
         {extra}[[shapes]]\ntype = \"obj\"\nfile = \"two.obj\"\n{shape_keys}"
    );
    render_scene(d, &scene)
}

/// The scene material `tex` reading `h.png` (linear) with `keys`.
fn scene_tex(keys: &str) -> String {
    format!(
        "[textures.h]\nfile = \"h.png\"\ncolor_space = \"linear\"\n\
         [materials.tex]\ntype = \"diffuse\"\nalbedo = [1, 1, 1]\n{keys}\n"
    )
}

/// `map_Bump` is a height map whose `-bm` is the bump scale: it renders
/// bit for bit as the scene material with `bump` and `bump_scale`, and
/// not as the flat one. With the shape's `map_bump = "normal"` the same
/// image is a normal map, as the scene's `normal_map`. Caught: `map_Bump`
/// read as a normal map by default (or as a height map under
/// `"normal"`), `-bm` dropped.
#[test]
fn map_bump_is_a_height_map_scaled_by_bm_or_a_normal_map_when_asked() {
    let frame = |mtl: &str, shape: &str, extra: &str| {
        let (code, stderr, film) = render_bumped(mtl, shape, extra);
        assert_eq!(code, Some(0), "{stderr}");
        film.unwrap().pixels
    };
    let height = frame("Kd 1 1 1\nmap_Bump -bm 0.3 h.png\n", "", "");
    let want = frame("", "", &scene_tex("bump = \"h\"\nbump_scale = 0.3"));
    assert!(height == want, "map_Bump -bm 0.3 is not bump_scale = 0.3");
    let flat = frame("Kd 1 1 1\n", "", "");
    assert!(height != flat, "map_Bump changed nothing");
    let normal = frame("Kd 1 1 1\nmap_Bump h.png\n", "map_bump = \"normal\"\n", "");
    let want = frame("", "", &scene_tex("normal_map = \"h\""));
    assert!(normal == want, "map_bump = \"normal\" is not normal_map");
    assert!(normal != height);
}

/// A `-bm` without a finite number, and a `map_bump` that is neither
/// kind: exit 2 naming the file, line and field, nothing written.
#[test]
fn a_bad_bump_multiplier_or_map_bump_exits_2() {
    let (code, stderr, film) = render_bumped("map_Bump -bm x h.png\n", "", "");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(film.is_none());
    assert!(
        stderr.contains("two.mtl:4") && stderr.contains("`-bm`"),
        "{stderr}"
    );
    let (code, stderr, film) = render_bumped("map_Bump h.png\n", "map_bump = \"nrm\"\n", "");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(film.is_none());
    assert!(
        stderr.contains("scene.toml:") && stderr.contains("field `shapes[0].map_bump`"),
        "{stderr}"
    );
}
