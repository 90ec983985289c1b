//! Malformed scene files and OBJ meshes must fail with a `SceneError` that
//! names the file and the line and/or field, with a message saying what was
//! expected; and the `lucent render` CLI must turn such errors into exit
//! code 2 without writing an output file.

use std::path::{Path, PathBuf};
use std::process::Command;

use lucent::scene::{load, SceneError};

const CAM: &str = "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = [32, 32]\n";
const MAT: &str = "[materials.white]\ntype = \"diffuse\"\nalbedo = [0.8, 0.8, 0.8]\n";
/// The header of a subsurface material; each case adds its keys.
const SSS: &str = "[materials.skin]\ntype = \"subsurface\"\n";

/// Which file the error must name.
#[derive(Clone, Copy, Debug, PartialEq)]
enum In {
    Scene,
    Obj,
}

struct Case {
    name: &'static str,
    scene: String,
    /// Written as `mesh.obj` next to the scene.
    obj: Option<&'static str>,
    fragment: &'static str,
    file: In,
    /// The error's line is the first line of the named file containing this
    /// text; None: the error must have no line.
    line_of: Option<&'static str>,
    field: Option<&'static str>,
}

fn case(
    name: &'static str,
    scene: impl Into<String>,
    fragment: &'static str,
    line_of: Option<&'static str>,
    field: Option<&'static str>,
) -> Case {
    Case {
        name,
        scene: scene.into(),
        obj: None,
        fragment,
        file: In::Scene,
        line_of,
        field,
    }
}

fn obj_case(
    name: &'static str,
    obj: &'static str,
    fragment: &'static str,
    line_of: Option<&'static str>,
) -> Case {
    Case {
        name,
        scene: format!(
            "{CAM}{MAT}[[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"white\"\n"
        ),
        obj: Some(obj),
        fragment,
        file: In::Obj,
        line_of,
        field: None,
    }
}

fn shape(extra: &str) -> String {
    format!("{CAM}{MAT}[[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n{extra}")
}

fn cases() -> Vec<Case> {
    vec![
        // --- TOML syntax and structure
        case("syntax error", "[camera\nlook_from = [0, 0, 1]\n", "invalid table header", Some("[camera"), None),
        case("unknown top-level key", format!("sampels = 4\n{CAM}"), "unknown field `sampels`", Some("sampels"), Some("sampels")),
        case("unknown camera key", format!("{CAM}fov = 30\n"), "unknown field `fov`", Some("fov ="), Some("camera.fov")),
        case("unknown render key", format!("{CAM}[render]\nsamples = 4\n"), "unknown field `samples`", Some("samples"), Some("render.samples")),
        case("missing camera", MAT, "missing table `[camera]`: every scene needs one", None, Some("camera")),
        case("form feed in a comment", format!("# a comment\n# with a \x0c form feed\n{CAM}"), "control character U+000C (form feed) is not allowed", Some("form feed"), None),
        case("NUL in a comment", format!("{CAM}fov_y = 30 # \0\n"), "control character U+0000 (NUL)", Some("fov_y"), Some("camera.fov_y")),
        case("file ends mid-assignment", format!("{CAM}[render]\nspp ="), "the file ends in the middle of an assignment: `spp =` has no value", Some("spp ="), Some("render.spp")),
        case(
            "material name with a newline and a quote",
            format!("{CAM}[materials.\"a\\n\\\"b\"]\ntype = \"diffuse\"\nalbedo = [2, 0, 0]\n"),
            "expected RGB components in [0, 1]",
            Some("albedo"),
            Some("materials.\"a\\n\\\"b\".albedo"),
        ),
        case(
            "missing resolution",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\n",
            "missing field `resolution`",
            Some("[camera]"),
            Some("camera.resolution"),
        ),
        case(
            "wrong type for resolution",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = \"512x512\"\n",
            "expected an array of 2 numbers",
            Some("resolution"),
            Some("camera.resolution"),
        ),
        case(
            "negative resolution",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = [512, -1]\n",
            "expected u32",
            Some("resolution"),
            Some("camera.resolution"),
        ),
        case(
            "wrong arity",
            "[camera]\nlook_from = [0, 1]\nlook_at = [0, 1, 0]\nresolution = [8, 8]\n",
            "expected 3 numbers, found 2",
            Some("look_from"),
            Some("camera.look_from"),
        ),
        // --- fixed-size arrays: serde's own array reader ignores trailing
        // elements; every wrong length is an error naming the counts.
        case(
            "resolution with three entries",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = [8, 8, 8]\n",
            "expected 2 numbers, found 3",
            Some("resolution"),
            Some("camera.resolution"),
        ),
        case(
            "resolution with one entry",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = [8]\n",
            "expected 2 numbers, found 1",
            Some("resolution"),
            Some("camera.resolution"),
        ),
        case(
            "look_from with four entries",
            "[camera]\nlook_from = [0, 1, 5, 7]\nlook_at = [0, 1, 0]\nresolution = [8, 8]\n",
            "expected 3 numbers, found 4",
            Some("look_from"),
            Some("camera.look_from"),
        ),
        case(
            "look_at with four entries",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0, 0]\nresolution = [8, 8]\n",
            "expected 3 numbers, found 4",
            Some("look_at"),
            Some("camera.look_at"),
        ),
        case("up with four entries", format!("{CAM}up = [0, 1, 0, 0]\n"), "expected 3 numbers, found 4", Some("up ="), Some("camera.up")),
        case("empty up", format!("{CAM}up = []\n"), "expected 3 numbers, found 0", Some("up ="), Some("camera.up")),
        case(
            "radiance with four entries",
            format!("{CAM}[environment]\nradiance = [1, 1, 1, 1]\n"),
            "expected 3 numbers, found 4",
            Some("radiance"),
            Some("environment.radiance"),
        ),
        case(
            "albedo with four entries",
            format!("{CAM}[materials.red]\ntype = \"diffuse\"\nalbedo = [1, 0, 0, 1]\n"),
            "expected 3 numbers, found 4",
            Some("albedo"),
            Some("materials.red.albedo"),
        ),
        case(
            "sigma_s_prime with four entries",
            format!("{CAM}{SSS}sigma_s_prime = [1, 1, 1, 1]\nsigma_a = [0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\n"),
            "expected 3 numbers, found 4",
            Some("sigma_s_prime"),
            Some("materials.skin.sigma_s_prime"),
        ),
        case(
            "sigma_a with four entries",
            format!("{CAM}{SSS}sigma_s_prime = [1, 1, 1]\nsigma_a = [0.1, 0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\n"),
            "expected 3 numbers, found 4",
            Some("sigma_a"),
            Some("materials.skin.sigma_a"),
        ),
        case(
            "dmfp with four entries",
            format!("{CAM}{SSS}albedo = [0.8, 0.8, 0.8]\ndmfp = [1, 1, 1, 1]\n"),
            "expected 3 numbers, found 4",
            Some("dmfp"),
            Some("materials.skin.dmfp"),
        ),
        case("emission with four entries", shape("emission = [1, 1, 1, 1]\n"), "expected 3 numbers, found 4", Some("emission"), Some("shapes[0].emission")),
        case("translate with two entries", shape("translate = [1, 1]\n"), "expected 3 numbers, found 2", Some("translate"), Some("shapes[0].translate")),
        case("translate with four entries", shape("translate = [1, 1, 1, 1]\n"), "expected 3 numbers, found 4", Some("translate"), Some("shapes[0].translate")),
        case("scale with four entries", shape("scale = [1, 1, 1, 1]\n"), "of 3 numbers, found 4", Some("scale"), Some("shapes[0].scale")),
        case("scale with two entries", shape("scale = [1, 1]\n"), "of 3 numbers, found 2", Some("scale"), Some("shapes[0].scale")),
        case("rotation with five entries", shape("rotate = [[90, 0, 1, 0, 0]]\n"), "of 4 numbers, found 5", Some("rotate"), Some("shapes[0].rotate")),
        case("rotation with three entries", shape("rotate = [[90, 0, 1]]\n"), "of 4 numbers, found 3", Some("rotate"), Some("shapes[0].rotate")),
        // --- camera and render values
        case(
            "zero resolution",
            "[camera]\nlook_from = [0, 1, 5]\nlook_at = [0, 1, 0]\nresolution = [0, 512]\n",
            "each in 1..=",
            Some("resolution"),
            Some("camera.resolution"),
        ),
        case("fov 180", format!("{CAM}fov_y = 180\n"), "strictly between 0 and 180", Some("fov_y"), Some("camera.fov_y")),
        case("fov negative", format!("{CAM}fov_y = -5.0\n"), "strictly between 0 and 180", Some("fov_y"), Some("camera.fov_y")),
        case("fov nan", format!("{CAM}fov_y = nan\n"), "expected a finite number", Some("fov_y"), Some("camera.fov_y")),
        case(
            "look_from inf",
            "[camera]\nlook_from = [0, inf, 5]\nlook_at = [0, 1, 0]\nresolution = [8, 8]\n",
            "expected finite numbers",
            Some("look_from"),
            Some("camera.look_from"),
        ),
        case(
            "look_from overflows f32",
            "[camera]\nlook_from = [0, 1e300, 5]\nlook_at = [0, 1, 0]\nresolution = [8, 8]\n",
            "expected finite numbers",
            Some("look_from"),
            Some("camera.look_from"),
        ),
        case(
            "look_from equals look_at",
            "[camera]\nlook_from = [1, 2, 3]\nlook_at = [1, 2, 3]\nresolution = [8, 8]\n",
            "must differ",
            Some("look_at"),
            Some("camera.look_at"),
        ),
        case("up parallel to view", format!("{CAM}up = [0, 0, -2]\n"), "not parallel", Some("up ="), Some("camera.up")),
        case(
            "default up parallel to view",
            "[camera]\nlook_from = [0, 5, 0]\nlook_at = [0, 0, 0]\nresolution = [8, 8]\n",
            "not parallel",
            Some("[camera]"),
            Some("camera.up"),
        ),
        case("spp zero", format!("{CAM}[render]\nspp = 0\n"), "at least 1 sample", Some("spp"), Some("render.spp")),
        case("max_depth zero", format!("{CAM}[render]\nmax_depth = 0\n"), "a path depth of 1 to 1024", Some("max_depth"), Some("render.max_depth")),
        case("traversal unknown", format!("{CAM}[render]\ntraversal = \"robust\"\n"), "expected \"fast\" or \"watertight\", found \"robust\"", Some("traversal"), Some("render.traversal")),
        case("sampler unknown", format!("{CAM}[render]\nsampler = \"halton\"\n"), "expected \"sobol\" or \"random\", found \"halton\"", Some("sampler"), Some("render.sampler")),
        case("traversal not a string", format!("{CAM}[render]\ntraversal = true\n"), "expected a string", Some("traversal"), Some("render.traversal")),
        case("seed negative", format!("{CAM}[render]\nseed = -3\n"), "expected u64", Some("seed"), Some("render.seed")),
        case("units_per_mm zero", format!("units_per_mm = 0\n{CAM}"), "expected a number > 0", Some("units_per_mm"), Some("units_per_mm")),
        case("units_per_mm inf", format!("units_per_mm = inf\n{CAM}"), "finite", Some("units_per_mm"), Some("units_per_mm")),
        case(
            "environment negative",
            format!("{CAM}[environment]\nradiance = [0.1, -0.1, 0]\n"),
            ">= 0",
            Some("radiance"),
            Some("environment.radiance"),
        ),
        // --- materials
        case(
            "material without type",
            format!("{CAM}[materials.red]\nalbedo = [1, 0, 0]\n"),
            "missing field `type`",
            Some("[materials.red]"),
            Some("materials.red.type"),
        ),
        case(
            "unknown material type",
            format!("{CAM}[materials.chrome]\ntype = \"metal\"\n"),
            "unknown variant `metal`, expected one of `diffuse`, `dielectric`, `subsurface`",
            Some("metal"),
            Some("materials.chrome.type"),
        ),
        case(
            "unknown material key",
            format!("{CAM}[materials.red]\ntype = \"diffuse\"\ncolour = [1, 0, 0]\n"),
            "unknown field `colour`",
            Some("colour"),
            Some("materials.red.colour"),
        ),
        case(
            "diffuse without albedo",
            format!("{CAM}[materials.red]\ntype = \"diffuse\"\n"),
            "missing field `albedo`",
            Some("[materials.red]"),
            Some("materials.red.albedo"),
        ),
        case(
            "albedo above 1",
            format!("{CAM}[materials.red]\ntype = \"diffuse\"\nalbedo = [1.2, 0, 0]\n"),
            "in [0, 1]",
            Some("albedo"),
            Some("materials.red.albedo"),
        ),
        case(
            "albedo nan",
            format!("{CAM}[materials.red]\ntype = \"diffuse\"\nalbedo = [nan, 0, 0]\n"),
            "finite",
            Some("albedo"),
            Some("materials.red.albedo"),
        ),
        case(
            "eta zero",
            format!("{CAM}[materials.glass]\ntype = \"dielectric\"\neta = 0.0\n"),
            "expected a number > 0",
            Some("eta"),
            Some("materials.glass.eta"),
        ),
        case(
            "eta on diffuse",
            format!("{CAM}[materials.red]\ntype = \"diffuse\"\nalbedo = [1, 0, 0]\neta = 1.5\n"),
            "does not apply to type \"diffuse\"",
            Some("eta"),
            Some("materials.red.eta"),
        ),
        // --- subsurface materials
        case(
            "subsurface unknown preset",
            format!("{CAM}{SSS}preset = \"jade\"\n"),
            "unknown material \"jade\" (known: Apple,",
            Some("jade"),
            Some("materials.skin.preset"),
        ),
        case(
            "subsurface preset mixed with artist form",
            format!("{CAM}{SSS}preset = \"marble\"\ndmfp = [1, 1, 1]\n"),
            "`preset` cannot be combined with `dmfp`",
            Some("dmfp"),
            Some("materials.skin.dmfp"),
        ),
        case(
            "subsurface measured mixed with artist form",
            format!("{CAM}{SSS}sigma_s_prime = [1, 1, 1]\nsigma_a = [0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\ndmfp = [1, 1, 1]\n"),
            "`sigma_s_prime` cannot be combined with `dmfp`",
            Some("dmfp"),
            Some("materials.skin.dmfp"),
        ),
        case(
            "subsurface sigma_a without sigma_s_prime",
            format!("{CAM}{SSS}sigma_a = [0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\n"),
            "missing field `sigma_s_prime`",
            Some("[materials.skin]"),
            Some("materials.skin.sigma_s_prime"),
        ),
        case(
            "subsurface measured without albedo",
            format!("{CAM}{SSS}sigma_s_prime = [1, 1, 1]\nsigma_a = [0.1, 0.1, 0.1]\n"),
            "missing field `albedo`",
            Some("[materials.skin]"),
            Some("materials.skin.albedo"),
        ),
        case(
            "subsurface no parameters",
            format!("{CAM}{SSS}eta = 1.4\n"),
            "give exactly one of",
            Some("[materials.skin]"),
            Some("materials.skin"),
        ),
        case(
            "subsurface albedo above 1",
            format!("{CAM}{SSS}albedo = [1.2, 0.5, 0.5]\ndmfp = [1, 1, 1]\n"),
            "albedo.r: 1.2 must be in [0, 1]",
            Some("albedo"),
            Some("materials.skin.albedo"),
        ),
        case(
            "subsurface negative dmfp",
            format!("{CAM}{SSS}albedo = [0.5, 0.5, 0.5]\ndmfp = [1, -1, 1]\n"),
            "dmfp.g: -1 must be finite and non-negative",
            Some("dmfp"),
            Some("materials.skin.dmfp"),
        ),
        case(
            "subsurface negative sigma_s_prime",
            format!("{CAM}{SSS}sigma_s_prime = [1, 1, -2]\nsigma_a = [0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\n"),
            "sigma_s_prime.b: -2 must be finite and non-negative",
            Some("sigma_s_prime"),
            Some("materials.skin.sigma_s_prime"),
        ),
        case(
            "subsurface no medium",
            format!("{CAM}{SSS}sigma_s_prime = [1, 0, 1]\nsigma_a = [0.1, 0, 0.1]\nalbedo = [0.5, 0.5, 0.5]\n"),
            "both zero, there is no medium",
            Some("sigma_s_prime"),
            Some("materials.skin.sigma_s_prime"),
        ),
        case(
            "subsurface g = 1",
            format!("{CAM}{SSS}sigma_s_prime = [1, 1, 1]\nsigma_a = [0.1, 0.1, 0.1]\nalbedo = [0.5, 0.5, 0.5]\ng = 1.0\n"),
            "g: 1 must be in (-1, 1)",
            Some("g = "),
            Some("materials.skin.g"),
        ),
        case(
            "subsurface g on a preset",
            format!("{CAM}{SSS}preset = \"skin1\"\ng = 0.8\n"),
            "`preset` cannot be combined with `g`",
            Some("g = "),
            Some("materials.skin.g"),
        ),
        case(
            "subsurface rmax_quantile 1",
            format!("{CAM}{SSS}preset = \"skin1\"\nrmax_quantile = 1.0\n"),
            "expected a number in (0, 1), found 1",
            Some("rmax_quantile"),
            Some("materials.skin.rmax_quantile"),
        ),
        case(
            "subsurface rmax_quantile 0",
            format!("{CAM}{SSS}preset = \"skin1\"\nrmax_quantile = 0\n"),
            "expected a number in (0, 1), found 0",
            Some("rmax_quantile"),
            Some("materials.skin.rmax_quantile"),
        ),
        case(
            "subsurface roughness above 1",
            format!("{CAM}{SSS}preset = \"skin1\"\nroughness = 1.5\n"),
            "roughness: 1.5 must be in [0, 1]",
            Some("roughness"),
            Some("materials.skin.roughness"),
        ),
        case(
            "subsurface roughness negative",
            format!("{CAM}{SSS}preset = \"skin1\"\nroughness = -0.1\n"),
            "roughness: -0.1 must be in [0, 1]",
            Some("roughness"),
            Some("materials.skin.roughness"),
        ),
        case(
            "subsurface roughness nan",
            format!("{CAM}{SSS}preset = \"skin1\"\nroughness = nan\n"),
            "roughness: NaN must be in [0, 1]",
            Some("roughness"),
            Some("materials.skin.roughness"),
        ),
        case(
            "subsurface regularize above 1",
            format!("{CAM}{SSS}preset = \"skin1\"\nregularize = 1.5\n"),
            "regularize: 1.5 must be in [0, 1]",
            Some("regularize"),
            Some("materials.skin.regularize"),
        ),
        case(
            "subsurface regularize nan",
            format!("{CAM}{SSS}preset = \"skin1\"\nregularize = nan\n"),
            "regularize: NaN must be in [0, 1]",
            Some("regularize"),
            Some("materials.skin.regularize"),
        ),
        case(
            "subsurface accuracy of 1 or more",
            format!("{CAM}{SSS}preset = \"skin1\"\naccuracy = 1.5\n"),
            "expected a fraction in (0, 1)",
            Some("accuracy"),
            Some("materials.skin.accuracy"),
        ),
        case(
            "subsurface accuracy nan",
            format!("{CAM}{SSS}preset = \"skin1\"\naccuracy = nan\n"),
            "found \"NaN\"",
            Some("accuracy"),
            Some("materials.skin.accuracy"),
        ),
        case(
            "subsurface accuracy as text",
            format!("{CAM}{SSS}preset = \"skin1\"\naccuracy = \"1%\"\n"),
            "invalid type",
            Some("accuracy"),
            Some("materials.skin.accuracy"),
        ),
        case(
            "subsurface roughness not a number",
            format!("{CAM}{SSS}preset = \"skin1\"\nroughness = \"rough\"\n"),
            "invalid type: string \"rough\", expected f64",
            Some("roughness"),
            Some("materials.skin.roughness"),
        ),
        case(
            "subsurface unknown radius sampler",
            format!("{CAM}{SSS}preset = \"skin1\"\nradius = \"gauss\"\n"),
            "unknown sampler \"gauss\" (expected uniform, table[:N], table-uniform[:N], analytic or mixture)",
            Some("gauss"),
            Some("materials.skin.radius"),
        ),
        case(
            "subsurface table size 0",
            format!("{CAM}{SSS}preset = \"skin1\"\nradius = \"table:0\"\n"),
            "table size 0 must be in [2, 16777216]",
            Some("table:0"),
            Some("materials.skin.radius"),
        ),
        case(
            "subsurface table size not a number",
            format!("{CAM}{SSS}preset = \"skin1\"\nradius = \"table:many\"\n"),
            "table size \"many\" must be in [2, 16777216]",
            Some("table:many"),
            Some("materials.skin.radius"),
        ),
        case(
            "subsurface bad axes",
            format!("{CAM}{SSS}preset = \"skin1\"\naxes = \"tangent\"\n"),
            "expected \"curvature\" or \"mis3\", found \"tangent\"",
            Some("tangent"),
            Some("materials.skin.axes"),
        ),
        case(
            "subsurface bad channel",
            format!("{CAM}{SSS}preset = \"skin1\"\nchannel = \"all\"\n"),
            "expected \"mis\", found \"all\"",
            Some("all"),
            Some("materials.skin.channel"),
        ),
        case(
            "subsurface unknown random-walk boundary",
            format!("{CAM}{SSS}preset = \"skin1\"\nboundary = \"lambertian\"\n"),
            "expected \"dielectric\", \"dielectric-nee\" or \"diffuse\", found \"lambertian\"",
            Some("lambertian"),
            Some("materials.skin.boundary"),
        ),
        case(
            "subsurface unknown curvature correction",
            format!("{CAM}{SSS}preset = \"skin1\"\ncurvature_correction = \"always\"\n"),
            "expected \"auto\" or \"off\", found \"always\"",
            Some("always"),
            Some("materials.skin.curvature_correction"),
        ),
        case(
            "subsurface unknown lod",
            format!("{CAM}{SSS}preset = \"skin1\"\nlod = \"force\"\n"),
            "expected \"auto\" or \"off\", found \"force\"",
            Some("force"),
            Some("materials.skin.lod"),
        ),
        case(
            "subsurface lod threshold not positive",
            format!("{CAM}{SSS}preset = \"skin1\"\nlod_threshold = -2.0\n"),
            "expected a finite number > 0",
            Some("-2.0"),
            Some("materials.skin.lod_threshold"),
        ),
        case(
            "subsurface lod threshold zero",
            format!("{CAM}{SSS}preset = \"skin1\"\nlod_threshold = 0\n"),
            "found 0",
            Some("lod_threshold = 0"),
            Some("materials.skin.lod_threshold"),
        ),
        case(
            "subsurface unknown fit",
            format!("{CAM}{SSS}preset = \"skin1\"\nfit = \"dipole\"\n"),
            "unknown fit \"dipole\"",
            Some("dipole"),
            Some("materials.skin.fit"),
        ),
        case(
            "subsurface control variate not a boolean",
            format!("{CAM}{SSS}preset = \"skin1\"\ncontrol_variate = \"on\"\n"),
            "expected a boolean",
            Some("control_variate"),
            Some("materials.skin.control_variate"),
        ),
        case(
            "probe pair on a diffuse material",
            format!("{CAM}{MAT}probe_pair = true\n"),
            "`probe_pair` does not apply to type \"diffuse\"",
            Some("probe_pair"),
            Some("materials.white.probe_pair"),
        ),
        case(
            "subsurface renormalize not a boolean",
            format!("{CAM}{SSS}preset = \"skin1\"\nrenormalize = \"yes\"\n"),
            "expected a boolean",
            Some("renormalize"),
            Some("materials.skin.renormalize"),
        ),
        // --- shapes
        case(
            "unknown material name",
            format!("{CAM}{MAT}[[shapes]]\ntype = \"quad\"\nmaterial = \"gold\"\n"),
            "unknown material \"gold\" (defined: white)",
            Some("gold"),
            Some("shapes[0].material"),
        ),
        case(
            "shape without material",
            format!("{CAM}{MAT}[[shapes]]\ntype = \"box\"\n[[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n"),
            "missing field `material`",
            Some("[[shapes]]"),
            Some("shapes[0].material"),
        ),
        case(
            "unknown shape type",
            format!("{CAM}{MAT}[[shapes]]\ntype = \"quad\"\nmaterial = \"white\"\n[[shapes]]\ntype = \"cone\"\nmaterial = \"white\"\n"),
            "unknown variant `cone`",
            Some("cone"),
            Some("shapes[1].type"),
        ),
        case("negative emission", shape("emission = [1, 1, -0.5]\n"), ">= 0", Some("emission"), Some("shapes[0].emission")),
        case("infinite emission", shape("emission = [inf, 1, 1]\n"), "finite", Some("emission"), Some("shapes[0].emission")),
        case("zero scale", shape("scale = [1, 0, 1]\n"), "non-zero", Some("scale"), Some("shapes[0].scale")),
        case("scale string", shape("scale = \"big\"\n"), "expected a number or an array [x, y, z]", Some("scale"), Some("shapes[0].scale")),
        case("rotate not a list", shape("rotate = [90, 1, 0, 0]\n"), "expected a rotation [angle_degrees", Some("rotate"), Some("shapes[0].rotate")),
        case("rotate zero axis", shape("rotate = [[45, 0, 0, 0]]\n"), "axis must be non-zero", Some("rotate"), Some("shapes[0].rotate[0]")),
        case("rotate nan angle", shape("rotate = [[0, 0, 1, 0], [nan, 0, 1, 0]]\n"), "finite", Some("rotate"), Some("shapes[0].rotate[1]")),
        case("translate nan", shape("translate = [0, nan, 0]\n"), "finite", Some("translate"), Some("shapes[0].translate")),
        case("subdivisions on a quad", shape("subdivisions = 3\n"), "does not apply to type \"quad\"", Some("subdivisions"), Some("shapes[0].subdivisions")),
        case(
            "too many subdivisions",
            format!("{CAM}{MAT}[[shapes]]\ntype = \"sphere\"\nmaterial = \"white\"\nsubdivisions = 12\n"),
            "at most 9",
            Some("subdivisions"),
            Some("shapes[0].subdivisions"),
        ),
        case(
            "obj without file",
            format!("{CAM}{MAT}[[shapes]]\ntype = \"obj\"\nmaterial = \"white\"\n"),
            "missing field `file`",
            Some("[[shapes]]"),
            Some("shapes[0].file"),
        ),
        case(
            "missing obj file",
            format!("{CAM}{MAT}[[shapes]]\ntype = \"obj\"\nfile = \"nowhere/x.obj\"\nmaterial = \"white\"\n"),
            "cannot read OBJ file",
            Some("nowhere"),
            Some("shapes[0].file"),
        ),
        // --- OBJ contents: the error names the OBJ file and its line
        obj_case("obj nan vertex", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", "non-finite number `nan`", Some("nan")),
        obj_case("obj inf normal", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 inf\nf 1//1 2//1 3//1\n", "non-finite", Some("vn")),
        obj_case("obj vertex overflows f32", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n", "non-finite", Some("1e39")),
        obj_case("obj garbage number", "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", "expected a number", Some("1 x")),
        obj_case("obj zero weight", "v 0 0 0\nv 1 0 0 0\nv 0 1 0\nf 1 2 3\n", "weight w = 0", Some("v 1")),
        obj_case("obj trailing comment", "v 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "has `#`, expected a number", Some("origin")),
        obj_case("obj five numbers", "v 0 0 0\nv 1 0 0 1 1\nv 0 1 0\nf 1 2 3\n", "has 5 numbers", Some("v 1")),
        case("stray text line", format!("{CAM}fov_y\n"), "expected", Some("fov_y"), None),
        obj_case("obj short vertex", "v 0 0\nf 1 1 1\n", "needs 3 numbers", Some("v 0 0")),
        obj_case("obj index out of range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "index 9 out of range", Some("f 1 2 9")),
        obj_case("obj index zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "index 0 out of range", Some("f 0")),
        obj_case("obj relative index too far back", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "index -4 out of range", Some("f -1")),
        obj_case("obj forward reference", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", "index 3 out of range", Some("f 1")),
        obj_case(
            "obj texcoord index zero",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/0 2/1 3/1\n",
            "texture coordinate index 0 out of range",
            Some("f 1/0"),
        ),
        obj_case(
            "obj normal index out of range",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
            "normal index 2 out of range",
            Some("f 1//"),
        ),
        obj_case("obj huge index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n", "not an integer", Some("f 1")),
        obj_case("obj malformed vertex ref", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", "malformed face vertex", Some("f 1/")),
        obj_case("obj two-vertex face", "v 0 0 0\nv 1 0 0\nf 1 2\n", "at least 3", Some("f 1 2")),
        obj_case("obj zero normal", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n", "zero-length normal", Some("vn")),
        obj_case("obj without faces", "# only vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "no triangles", None),
        obj_case("obj empty", "", "no triangles", None),
        // --- the glossy materials
        case(
            "unknown metal",
            format!("{CAM}[materials.m]\ntype = \"conductor\"\nmetal = \"unobtainium\"\n"),
            "unknown metal \"unobtainium\"; expected one of \"gold\"",
            Some("metal ="),
            Some("materials.m.metal"),
        ),
        case(
            "conductor with metal and n",
            format!("{CAM}[materials.m]\ntype = \"conductor\"\nmetal = \"gold\"\nn = [1, 1, 1]\nk = [2, 2, 2]\n"),
            "`metal` cannot be combined with `n` and `k`",
            Some("metal ="),
            Some("materials.m.metal"),
        ),
        case(
            "conductor without k",
            format!("{CAM}[materials.m]\ntype = \"conductor\"\nn = [1, 1, 1]\n"),
            "missing field `k`",
            Some("[materials.m]"),
            Some("materials.m.k"),
        ),
        case(
            "conductor with n = 0",
            format!("{CAM}[materials.m]\ntype = \"conductor\"\nn = [1, 0, 1]\nk = [2, 2, 2]\n"),
            "expected RGB components > 0",
            Some("n = [1, 0"),
            Some("materials.m.n"),
        ),
        case(
            "roughness out of range",
            format!("{CAM}[materials.m]\ntype = \"plastic\"\nalbedo = [0.5, 0.5, 0.5]\nroughness = 1.5\n"),
            "expected a number in [0, 1], found 1.5",
            Some("roughness ="),
            Some("materials.m.roughness"),
        ),
        case(
            "plastic without albedo",
            format!("{CAM}[materials.m]\ntype = \"plastic\"\nroughness = 0.5\n"),
            "missing field `albedo`",
            Some("[materials.m]"),
            Some("materials.m.albedo"),
        ),
        // --- [[lights]] and emitters' power
        case(
            "sphere light with radiance and power",
            format!("{CAM}[[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0.1\nradiance = [1, 1, 1]\npower = [5, 5, 5]\n"),
            "`radiance` and `power` are two forms of the light's strength: give one",
            Some("power ="),
            Some("lights[0].power"),
        ),
        case(
            "sphere light with neither radiance nor power",
            format!("{CAM}[[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0.1\n"),
            "give the light's `radiance` or its `power`",
            Some("[[lights]]"),
            Some("lights[0].radiance"),
        ),
        case(
            "sphere light of radius 0",
            format!("{CAM}[[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0\npower = [5, 5, 5]\n"),
            "expected a number > 0",
            Some("radius ="),
            Some("lights[0].radius"),
        ),
        case(
            "spot angle without its direction",
            format!("{CAM}[[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0.1\npower = [5, 5, 5]\nspot_angle = 30\n"),
            "give its axis, `spot_direction`",
            Some("spot_angle ="),
            Some("lights[0].spot_angle"),
        ),
        case(
            "spot falloff wider than the cone",
            format!("{CAM}[[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0.1\npower = [5, 5, 5]\nspot_direction = [0, -1, 0]\nspot_angle = 30\nspot_falloff = 40\n"),
            "expected degrees in [0, 30], found 40",
            Some("spot_falloff ="),
            Some("lights[0].spot_falloff"),
        ),
        case(
            "distant light with a sphere's key",
            format!("{CAM}[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\nradius = 1\n"),
            "`radius` does not apply to type \"distant\"",
            Some("radius ="),
            Some("lights[0].radius"),
        ),
        case(
            "distant light of angle 0 with a radiance",
            format!("{CAM}[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nangle = 0\nradiance = [1, 1, 1]\n"),
            "give its `irradiance`",
            Some("radiance ="),
            Some("lights[0].radiance"),
        ),
        case(
            "distant light towards nowhere",
            format!("{CAM}[[lights]]\ntype = \"distant\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]\n"),
            "expected a non-zero direction",
            Some("direction ="),
            Some("lights[0].direction"),
        ),
        case(
            "light of unknown type",
            format!("{CAM}[[lights]]\ntype = \"area\"\n"),
            "unknown variant `area`",
            Some("type ="),
            Some("lights[0].type"),
        ),
        case(
            "shape with emission and power",
            shape("emission = [1, 1, 1]\npower = [10, 10, 10]\n"),
            "`emission` and `power` are two forms of the shape's light: give one",
            Some("power ="),
            Some("shapes[0].power"),
        ),
        case(
            "bad light group of a light",
            format!("{CAM}[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\nlight_group = \"a b\"\n"),
            "expected a light group name",
            Some("light_group ="),
            Some("lights[0].light_group"),
        ),
        case(
            "diffuse with roughness",
            format!("{CAM}[materials.m]\ntype = \"diffuse\"\nalbedo = [0.5, 0.5, 0.5]\nroughness = 0.5\n"),
            "roughness",
            Some("roughness ="),
            Some("materials.m.roughness"),
        ),
    ]
}

fn line_containing(text: &str, needle: &str) -> usize {
    let at = text
        .find(needle)
        .unwrap_or_else(|| panic!("test bug: {needle:?} not in {text:?}"));
    text[..at].matches('\n').count() + 1
}

fn write_case(dir: &Path, c: &Case) -> (PathBuf, PathBuf) {
    let scene = dir.join("scene.toml");
    let obj = dir.join("mesh.obj");
    std::fs::write(&scene, &c.scene).unwrap();
    if let Some(o) = c.obj {
        std::fs::write(&obj, o).unwrap();
    }
    (scene, obj)
}

#[test]
fn malformed_inputs_are_located_errors() {
    let cases = cases();
    assert!(cases.len() >= 20);
    let mut failures = Vec::new();
    for c in &cases {
        let dir = tempfile::tempdir().unwrap();
        let (scene, obj) = write_case(dir.path(), c);
        let err: SceneError = match load(&scene) {
            Ok(_) => {
                failures.push(format!("{}: loaded without error", c.name));
                continue;
            }
            Err(e) => e,
        };
        let shown = err.to_string();
        let (file, text) = match c.file {
            In::Scene => (&scene, c.scene.as_str()),
            In::Obj => (&obj, c.obj.unwrap()),
        };
        let mut problems = Vec::new();
        if &err.file != file {
            problems.push(format!("file {:?}, expected {:?}", err.file, file));
        }
        if !shown.starts_with(&file.display().to_string()) {
            problems.push("display does not start with the file".into());
        }
        if !err.message.contains(c.fragment) {
            problems.push(format!("message lacks {:?}", c.fragment));
        }
        let want_line = c.line_of.map(|n| line_containing(text, n));
        if err.line != want_line {
            problems.push(format!("line {:?}, expected {:?}", err.line, want_line));
        }
        if err.field.as_deref() != c.field {
            problems.push(format!("field {:?}, expected {:?}", err.field, c.field));
        }
        if err.line.is_none() && err.field.is_none() && c.file == In::Scene {
            problems.push("neither line nor field".into());
        }
        if let Some(l) = err.line {
            if !shown.contains(&format!(":{l}: ")) {
                problems.push("display lacks the line".into());
            }
        }
        if let Some(f) = &err.field {
            if !shown.contains(&format!("`{f}`")) {
                problems.push("display lacks the field".into());
            }
        }
        if !problems.is_empty() {
            failures.push(format!(
                "{}: {}\n    got: {shown}",
                c.name,
                problems.join("; ")
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} cases failed:\n{}",
        failures.len(),
        cases.len(),
        failures.join("\n")
    );
}

#[test]
fn unreadable_scene_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("absent.toml");
    let err = load(&missing).unwrap_err();
    assert_eq!(err.file, missing);
    assert!(err.message.contains("cannot read scene file"), "{err}");
    // A directory is not readable as a scene either.
    let err = load(dir.path()).unwrap_err();
    assert!(err.message.contains("cannot read scene file"), "{err}");
}

// --- The CLI: `lucent render scene.toml -o out.exr` exits with code 2 on a
// scene error, prints the located error, and writes no output file.

fn run_cli(scene_text: &str, obj: Option<&str>) -> (Option<i32>, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, scene_text).unwrap();
    if let Some(o) = obj {
        std::fs::write(dir.path().join("mesh.obj"), o).unwrap();
    }
    let out = dir.path().join("out.exr");
    let res = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .arg("render")
        .arg(&scene)
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run lucent");
    (
        res.status.code(),
        String::from_utf8_lossy(&res.stderr).into_owned(),
        out.exists(),
    )
}

#[test]
fn cli_exits_2_on_scene_errors_without_writing_output() {
    let rows: Vec<(String, Option<&str>, &str)> = vec![
        (format!("{CAM}fov_y = 0\n"), None, "scene.toml:5"),
        (
            format!("{CAM}{MAT}[[shapes]]\ntype = \"quad\"\nmaterial = \"gold\"\n"),
            None,
            "unknown material \"gold\"",
        ),
        ("[camera\n".to_string(), None, "invalid table header"),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\nboundary = \"rough\"\n"),
            None,
            "scene.toml:8: field `materials.skin.boundary`: expected \"dielectric\", \"dielectric-nee\" or \"diffuse\"",
        ),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\ncurvature_correction = 1\n"),
            None,
            "scene.toml:8: field `materials.skin.curvature_correction`",
        ),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\ncurvature_correction = \"sometimes\"\n"),
            None,
            "scene.toml:8: field `materials.skin.curvature_correction`: expected \"auto\" or \"off\"",
        ),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\nlod = \"sometimes\"\n"),
            None,
            "scene.toml:8: field `materials.skin.lod`: expected \"auto\" or \"off\"",
        ),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\nlod_threshold = nan\n"),
            None,
            "scene.toml:8: field `materials.skin.lod_threshold`: expected a finite number > 0",
        ),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\nlod_threshold = \"big\"\n"),
            None,
            "scene.toml:8: field `materials.skin.lod_threshold`",
        ),
        (
            format!("{CAM}{SSS}preset = \"skin1\"\nroughness = 2\n"),
            None,
            "scene.toml:8: field `materials.skin.roughness`",
        ),
        (
            format!("{CAM}[[lights]]\ntype = \"sphere\"\nposition = [0, 2, 0]\nradius = 0.1\nradiance = [1, 1, 1]\npower = [5, 5, 5]\n"),
            None,
            "scene.toml:10: field `lights[0].power`: `radiance` and `power`",
        ),
        (
            format!("{CAM}[[lights]]\ntype = \"distant\"\ndirection = [0, -1, 0]\nangle = 0\nradiance = [1, 1, 1]\n"),
            None,
            "scene.toml:9: field `lights[0].radiance`",
        ),
        (
            format!(
                "{CAM}{MAT}[[shapes]]\ntype = \"obj\"\nfile = \"mesh.obj\"\nmaterial = \"white\"\n"
            ),
            Some("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"),
            "mesh.obj:4",
        ),
    ];
    for (scene, obj, fragment) in rows {
        let (code, stderr, wrote) = run_cli(&scene, obj);
        assert_eq!(
            code,
            Some(2),
            "exit code for {fragment:?}; stderr: {stderr}"
        );
        assert!(
            stderr.contains(fragment),
            "stderr lacks {fragment:?}: {stderr}"
        );
        assert!(
            !wrote,
            "output written despite a scene error ({fragment:?})"
        );
    }
}

#[test]
fn cli_exits_2_on_a_missing_scene_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.exr");
    let res = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["render"])
        .arg(dir.path().join("nope.toml"))
        .arg("-o")
        .arg(&out)
        .output()
        .expect("run lucent");
    let stderr = String::from_utf8_lossy(&res.stderr);
    assert_eq!(res.status.code(), Some(2), "stderr: {stderr}");
    assert!(
        stderr.contains("nope.toml") && stderr.contains("cannot read scene file"),
        "{stderr}"
    );
    assert!(!out.exists());
}
