#!/usr/bin/env bash
# Installs what lucent needs on Debian 12 and skips what is already there:
# Embree 3 (Debian's libembree-dev, the production ray-query backend),
# pkg-config (to find it), a C compiler (for the FFI layout test), the
# DejaVu Sans font (text in `lucent study` plots, read by path),
# OpenImageIO's tools (`oiiotool`, `iinfo`: tests/cli/exr_oiio.rs reads the EXR
# files back with them), shellcheck and PyYAML (scripts/check-deploy.sh),
# and an Embree 4 for the tests of the `embree4` backend (Debian 12 has
# none: the 4.4.0 library and the TBB it needs, from the `embreex` wheel on
# PyPI, unpacked into .cache/embree4/, which scripts/test.sh points
# LUCENT_EMBREE4 at), and Open Image Denoise 2.5.1 for the denoise tests
# (Debian 12 has none: the official release libraries from the `pyoidn`
# wheel on PyPI, unpacked into .cache/oidn/lib/, which scripts/test.sh
# points LUCENT_OIDN at). Safe to run any number of times.
set -euo pipefail

need=()
dpkg -s libembree-dev >/dev/null 2>&1 || need+=(libembree-dev)
command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
command -v cc >/dev/null 2>&1 || need+=(gcc libc6-dev)
[ -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need+=(fonts-dejavu-core)
command -v oiiotool >/dev/null 2>&1 || need+=(openimageio-tools)
command -v shellcheck >/dev/null 2>&1 || need+=(shellcheck)
python3 -c 'import yaml' >/dev/null 2>&1 || need+=(python3-yaml)

if ((${#need[@]})); then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo=sudo; fi
  echo "installing: ${need[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y --no-install-recommends "${need[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
  echo "error: cargo not found; install Rust (rustup) first" >&2
  exit 1
fi
for c in rustfmt clippy; do
  if ! cargo "${c/rustfmt/fmt}" --version >/dev/null 2>&1; then
    rustup component add "$c"
  fi
done

# Embree 4.4.0 from the embreex 4.4.0.post1 wheel: its libembree4 (renamed
# by the wheel's packager, with RPATH $ORIGIN) and the libtbb it links,
# renamed too, so it never meets Debian's TBB. Only the two libraries are
# kept; libembree4.so.4 is a link to the real file, the name lucent looks
# for. The wheel is the same library for every CPython tag, so pip is asked
# for one tag explicitly rather than the local interpreter's.
e4=.cache/embree4
cd "$(dirname "$0")/.."
if [ ! -e "$e4/libembree4.so.4" ]; then
  command -v python3 >/dev/null 2>&1 || {
    echo "error: python3 (with pip) is needed to fetch Embree 4 for the tests" >&2
    exit 1
  }
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  python3 -m pip download --quiet --no-deps --only-binary=:all: \
    --python-version 3.11 --platform manylinux_2_28_x86_64 \
    -d "$tmp" embreex==4.4.0.post1
  python3 -m zipfile -e "$tmp"/embreex-4.4.0.post1-*.whl "$tmp/x"
  mkdir -p "$e4.part"
  cp "$tmp"/x/embreex.libs/libembree4-*.so.4 "$tmp"/x/embreex.libs/libtbb-*.so.* "$e4.part/"
  (cd "$e4.part" && ln -sf libembree4-*.so.4 libembree4.so.4)
  rm -rf "$e4"
  mv "$e4.part" "$e4"
  echo "Embree 4.4.0 unpacked into $e4" >&2
fi

# Open Image Denoise 2.5.1 from the pyoidn 2.5.1.0 wheel (py3-none: one
# wheel for every interpreter): the official release's libOpenImageDenoise,
# its core, its CPU device module and the TBB that module links. They keep
# their directory name lib/: each has RPATH $ORIGIN/../lib, and OIDN loads
# its device modules from its own directory. The GPU device modules are
# left out (OIDN skips a module it does not find).
oidn=.cache/oidn
if [ ! -e "$oidn/lib/libOpenImageDenoise.so.2" ]; then
  command -v python3 >/dev/null 2>&1 || {
    echo "error: python3 (with pip) is needed to fetch Open Image Denoise for the tests" >&2
    exit 1
  }
  tmp2=$(mktemp -d)
  trap 'rm -rf "${tmp:-}" "$tmp2"' EXIT
  python3 -m pip download --quiet --no-deps --only-binary=:all: \
    --python-version 3.11 --platform manylinux2014_x86_64 \
    -d "$tmp2" pyoidn==2.5.1.0
  mkdir -p "$oidn.part/lib"
  python3 - "$tmp2"/pyoidn-2.5.1.0-*.whl "$oidn.part/lib" <<'PY'
import sys, zipfile
wheel, dest = sys.argv[1], sys.argv[2]
names = ["libOpenImageDenoise.so.2", "libOpenImageDenoise_core.so.2.5.1",
         "libOpenImageDenoise_device_cpu.so.2.5.1", "libtbb.so.12"]
with zipfile.ZipFile(wheel) as z:
    for n in names:
        with z.open("pyoidn/oidn/lib/" + n) as src, open(dest + "/" + n, "wb") as dst:
            dst.write(src.read())
PY
  rm -rf "$oidn"
  mv "$oidn.part" "$oidn"
  echo "Open Image Denoise 2.5.1 unpacked into $oidn/lib" >&2
fi
