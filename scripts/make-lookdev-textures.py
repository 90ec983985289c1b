#!/usr/bin/env python3
"""Writes scenes/lookdev/skin.png, the skin ball's albedo map.

A 512 x 256 latitude-longitude map in the layout lucent generates for a
built-in sphere (docs/scene-format.md, "Texture coordinates"): u = 1/2 +
atan2(x, z)/2pi, v = 1/2 + asin(y)/pi. Each texel is a factor on the
material's albedo (an sRGB colour map, 1 = the material's own colour):
soft reddish blotches from a few random plane waves, and freckles (brown
disks of 3.5 to 7 degrees), both drawn on the sphere itself, so they are
round wherever the map stretches. Deterministic (a fixed seed); ours, CC0.

Usage: scripts/make-lookdev-textures.py [OUT]   (needs numpy)
"""

import struct
import sys
import zlib
from pathlib import Path

import numpy as np

WIDTH, HEIGHT = 512, 256
SEED = 35


def directions():
    """The unit vector at each texel centre, shape (H, W, 3); row 0 is v = 1."""
    u = (np.arange(WIDTH) + 0.5) / WIDTH
    v = 1.0 - (np.arange(HEIGHT) + 0.5) / HEIGHT
    phi = (u - 0.5) * 2.0 * np.pi
    lat = (v - 0.5) * np.pi
    lat, phi = np.meshgrid(lat, phi, indexing="ij")
    return np.stack(
        [np.cos(lat) * np.sin(phi), np.sin(lat), np.cos(lat) * np.cos(phi)], axis=-1
    )


def unit_vectors(rng, n):
    x = rng.normal(size=(n, 3))
    return x / np.linalg.norm(x, axis=1, keepdims=True)


def blotches(rng, p):
    """A smooth field in [0, 1]: eight plane waves of 2-5 cycles per radian."""
    field = np.zeros(p.shape[:2])
    for k, phase in zip(unit_vectors(rng, 8), rng.uniform(0, 2 * np.pi, 8)):
        field += np.sin(rng.uniform(2.0, 5.0) * (p @ k) + phase)
    return np.clip(0.5 + field / 6.0, 0.0, 1.0)


def freckles(rng, p):
    """Coverage in [0, 1] of 150 disks of 3.5-7 degrees with soft edges."""
    cover = np.zeros(p.shape[:2])
    centres = unit_vectors(rng, 150)
    radii = np.radians(rng.uniform(3.5, 7.0, len(centres)))
    for c, r in zip(centres, radii):
        angle = np.arccos(np.clip(p @ c, -1.0, 1.0))
        cover = np.maximum(cover, np.clip((r - angle) / (0.3 * r), 0.0, 1.0))
    return cover


def srgb_bytes(linear):
    x = np.clip(linear, 0.0, 1.0)
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    return np.round(s * 255.0).astype(np.uint8)


def write_png(path, rgb):
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[y].tobytes() for y in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    png = b"\x89PNG\r\n\x1a\n"
    png += chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9))
    png += chunk(b"IEND", b"")
    Path(path).write_bytes(png)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "scenes/lookdev/skin.png"
    rng = np.random.default_rng(SEED)
    p = directions()
    blotch = blotches(rng, p)[..., None]
    freckle = freckles(rng, p)[..., None]
    # Linear factors on the albedo: blotches take up to a quarter of the
    # green and blue (redder skin), freckles darken towards brown.
    colour = 1.0 - blotch * np.array([0.04, 0.25, 0.25])
    colour *= 1.0 - freckle * np.array([0.5, 0.66, 0.75])
    write_png(out, srgb_bytes(colour))


if __name__ == "__main__":
    main()
