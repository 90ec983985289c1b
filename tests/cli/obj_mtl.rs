//! An OBJ with an MTL library renders without scene materials: each
//! `usemtl` part in its MTL colour or texture at the right place, a scene
//! material of the same name overrides, ignored keys are listed on
//! stderr, and a key lucent does not know is an error at its line.

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
