#!/usr/bin/env python3
"""Diffusion against the random walk per preset (docs/accuracy.md, "Diffusion
against exact transport per preset").

For each preset: a large slab and spheres of radius 4x, 1x and 0.25x the
diffusion length ld (the largest of the three channels'), in a uniform
environment of radiance 1, rendered with `lucent render` by the diffusion
estimator (A from the albedo table, and the old A with albedo_source =
"given") and by `--integrator randomwalk`. Compared: the mean radiance over
the object's pixels (spheres: pixels wholly inside the projected disk;
slab: the cosine-weighted mean over view directions by a three-point
Gauss-Legendre rule in mu^2, cameras at 70.1, 45 and 19.6 degrees).

    python3 scripts/albedo-report.py [--presets marble,skin1] [--spp-walk 64]
                                     [--spp-diffusion 64] [--out DIR]
    python3 scripts/albedo-report.py --curvature [--presets ...] [--reuse]

`--curvature` measures the curvature correction instead (docs/accuracy.md,
"Curvature correction"): spheres only, the diffusion estimator with
`curvature_correction = "off"` and `"auto"` against the random walk.
`--reuse` keeps random-walk renders already in DIR (they do not depend on
the correction).

Needs `cargo build --release --example image_mean` and the release binary.
Prints a markdown table; renders stay in DIR (default out/albedo-report).
"""
import argparse, math, os, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LUCENT = os.environ.get("LUCENT", os.path.join(ROOT, "target/release/lucent"))
MEAN = os.path.join(ROOT, "target/release/examples/image_mean")

# Jensen et al. 2001 (crates/lucent/src/bssrdf/params.rs PRESETS): sigma_s', sigma_a (1/mm).
PRESETS = {
    "apple": ([2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    "chicken1": ([0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    "chicken2": ([0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    "cream": ([7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    "ketchup": ([0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    "marble": ([2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    "potato": ([0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    "skimmilk": ([0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    "skin1": ([0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    "skin2": ([1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    "spectralon": ([11.6, 20.4, 14.9], [0.0, 0.0, 0.0]),
    "wholemilk": ([2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
}

RES = 16
FOV_SLAB = 4.0
VIEWS = [(math.degrees(math.acos(math.sqrt(u))), w) for u, w in
         ((0.5 - math.sqrt(0.15), 5 / 18), (0.5, 8 / 18), (0.5 + math.sqrt(0.15), 5 / 18))]


def ld_max(name):
    s, a = PRESETS[name]
    return max(1.0 / math.sqrt(3 * a[c] * (s[c] + a[c])) for c in range(3) if a[c] > 0)


CURVATURE = None  # set by --curvature: "auto" or "off" per render


def material(name, source):
    extra = f'curvature_correction = "{CURVATURE}"\n' if CURVATURE else ""
    return (f'[materials.m]\ntype = "subsurface"\npreset = "{name}"\n'
            f'albedo_source = "{source}"\nrenormalize = true\n' + extra)


def slab_scene(name, source, theta):
    ld = ld_max(name)
    t = math.radians(theta)
    d = 5.0 * ld
    eye = [0.0, d * math.cos(t), d * math.sin(t)]
    return (f"units_per_mm = 1.0\n[camera]\nlook_from = {eye}\nlook_at = [0.0, 0.0, 0.0]\n"
            f"up = [1.0, 0.0, 0.0]\nfov_y = {FOV_SLAB}\nresolution = [{RES}, {RES}]\n"
            f"[render]\nspp = 16\nmax_depth = 4\n[environment]\nradiance = [1.0, 1.0, 1.0]\n"
            + material(name, source) +
            f'[[shapes]]\nname = "slab"\ntype = "box"\nmaterial = "m"\n'
            f"scale = [{60 * ld}, {8 * ld}, {60 * ld}]\ntranslate = [0.0, {-8 * ld}, 0.0]\n")


def sphere_scene(name, source, k):
    rho = k * ld_max(name)
    d = 4.0 * rho
    half = math.asin(rho / d) * 1.08
    fov = math.degrees(2 * half)
    disk = math.tan(math.asin(rho / d)) / math.tan(half) * RES / 2
    text = (f"units_per_mm = 1.0\n[camera]\nlook_from = [0.0, 0.0, {d}]\nlook_at = [0.0, 0.0, 0.0]\n"
            f"fov_y = {fov}\nresolution = [{RES}, {RES}]\n"
            f"[render]\nspp = 16\nmax_depth = 4\n[environment]\nradiance = [1.0, 1.0, 1.0]\n"
            + material(name, source) +
            f'[[shapes]]\nname = "ball"\ntype = "sphere"\nsubdivisions = 6\nmaterial = "m"\n'
            f"scale = {rho}\n")
    return text, (RES / 2, RES / 2, disk)


REUSE = False


def render(out, tag, text, spp, walk, disk=None):
    toml = os.path.join(out, tag + ".toml")
    exr = os.path.join(out, tag + ".exr")
    note = ""
    if not (REUSE and walk and os.path.exists(exr)):
        with open(toml, "w") as f:
            f.write(text)
        cmd = [LUCENT, "render", toml, "-o", exr, "--spp", str(spp), "--seed", "1"]
        if walk:
            cmd += ["--integrator", "randomwalk"]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
        if "capped" in r.stderr or "escaped" in r.stderr:
            note = r.stderr.strip().splitlines()[-1]
    args = [MEAN, exr] + ([str(x) for x in disk] if disk else [])
    v = subprocess.run(args, capture_output=True, text=True, check=True).stdout.split()
    return [float(x) for x in v[:3]], [float(x) for x in v[3:6]], note


def rel(a, b):
    return [a[c] / b[c] - 1.0 for c in range(3)]


def fmt(r):
    return "/".join(f"{100 * x:+.1f}" for x in r)


def curvature_report(a):
    """Spheres at 4, 1, 0.25 ld: diffusion with the correction off / auto
    against the random walk, per channel in per cent."""
    global CURVATURE
    print("| preset | ld (mm) | 4 ld: off | 4 ld: auto | 1 ld: off | 1 ld: auto "
          "| 0.25 ld: off | 0.25 ld: auto |")
    print("|---|---|---|---|---|---|---|---|")
    for name in a.presets.split(","):
        cells = [name, f"{ld_max(name):.2f}"]
        for k in (4.0, 1.0, 0.25):
            CURVATURE = None
            text, disk = sphere_scene(name, "table", k)
            walk, _, _ = render(a.out, f"{name}-sphere{k}-walk", text, a.spp_walk, True, disk)
            for mode in ("off", "auto"):
                CURVATURE = mode
                text, disk = sphere_scene(name, "table", k)
                m, _, _ = render(a.out, f"{name}-sphere{k}-{mode}", text, a.spp_diffusion,
                                 False, disk)
                cells.append(fmt(rel(m, walk)))
        print("| " + " | ".join(cells) + " |", flush=True)


def main():
    global REUSE
    ap = argparse.ArgumentParser()
    ap.add_argument("--presets", default="marble,skin1,wholemilk,ketchup,skin2,apple")
    ap.add_argument("--spp-walk", type=int, default=64)
    ap.add_argument("--spp-diffusion", type=int, default=64)
    ap.add_argument("--out", default=os.path.join(ROOT, "out/albedo-report"))
    ap.add_argument("--curvature", action="store_true")
    ap.add_argument("--reuse", action="store_true")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    REUSE = a.reuse
    if a.curvature:
        curvature_report(a)
        return
    print("| preset | ld (mm) | slab: table A | slab: old A | 4 ld: table | 4 ld: old | 1 ld: table | 0.25 ld: table |")
    print("|---|---|---|---|---|---|---|---|")
    for name in a.presets.split(","):
        cells = [name, f"{ld_max(name):.2f}"]
        notes = []
        # slab: cosine-weighted mean over three view directions
        acc = {k: [0.0] * 3 for k in ("walk", "table", "given")}
        for i, (theta, w) in enumerate(VIEWS):
            for kind, src, spp, walk in (("walk", "table", a.spp_walk, True),
                                         ("table", "table", a.spp_diffusion, False),
                                         ("given", "given", a.spp_diffusion, False)):
                m, _, note = render(a.out, f"{name}-slab{i}-{kind}", slab_scene(name, src, theta),
                                    spp, walk)
                if note:
                    notes.append(f"slab {kind}: {note}")
                for c in range(3):
                    acc[kind][c] += w * m[c]
        cells += [fmt(rel(acc["table"], acc["walk"])), fmt(rel(acc["given"], acc["walk"]))]
        for k in (4.0, 1.0, 0.25):
            res = {}
            for kind, src, spp, walk in (("walk", "table", a.spp_walk, True),
                                         ("table", "table", a.spp_diffusion, False),
                                         ("given", "given", a.spp_diffusion, False)):
                if k != 4.0 and kind == "given":
                    continue
                text, disk = sphere_scene(name, src, k)
                m, _, note = render(a.out, f"{name}-sphere{k}-{kind}", text, spp, walk, disk)
                if note:
                    notes.append(f"sphere {k}: {note}")
                res[kind] = m
            cells.append(fmt(rel(res["table"], res["walk"])))
            if k == 4.0:
                cells.append(fmt(rel(res["given"], res["walk"])))
        print("| " + " | ".join(cells) + " |", flush=True)
        for n in notes:
            print(f"<!-- {name}: {n} -->", flush=True)


if __name__ == "__main__":
    main()
