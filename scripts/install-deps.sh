#!/usr/bin/env bash
# Installs what lucent needs on Debian 12 and skips what is already there:
# Embree 3 (Debian's libembree-dev, the production ray-query backend),
# pkg-config (to find it), a C compiler (for the FFI layout test) and the
# DejaVu Sans font (text in `lucent study` plots, read by path) and
# OpenImageIO's tools (`oiiotool`, `iinfo`: tests/exr_oiio.rs reads the EXR
# files back with them).
# Safe to run any number of times.
set -euo pipefail

need=()
dpkg -s libembree-dev >/dev/null 2>&1 || need+=(libembree-dev)
command -v pkg-config >/dev/null 2>&1 || need+=(pkg-config)
command -v cc >/dev/null 2>&1 || need+=(gcc libc6-dev)
[ -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] || need+=(fonts-dejavu-core)
command -v oiiotool >/dev/null 2>&1 || need+=(openimageio-tools)

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
