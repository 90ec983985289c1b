#!/usr/bin/env bash
# Tiles the passes of a multi-layer EXR (as lucent writes it: beauty in
# R,G,B, passes as LAYER.CHANNEL) into one labelled PNG, with OpenImageIO's
# oiiotool (scripts/install-deps.sh installs it) and the DejaVu Sans font.
#
#   scripts/contact-sheet.sh IN.exr OUT.png [TILE_WIDTH=320] [COLUMNS=4]
#
# Display of each layer (docs/output.md, "Contact sheet"):
# - beauty and light passes (channels R,G,B): clamped to [0, 1], sRGB;
# - other passes (normals, positions, depth, IDs, counts): each channel
#   stretched from its minimum to its maximum over the image, so the tile
#   shows the pass's structure, not its units;
# - Cryptomatte layers (NAME00 …): the coverage of rank 0 (NAME00.G), the
#   dominant object's or material's share of each pixel.
set -euo pipefail

if [ $# -lt 2 ]; then
  echo "usage: $0 IN.exr OUT.png [TILE_WIDTH] [COLUMNS]" >&2
  exit 2
fi
in=$1
out=$2
tile=${3:-320}
cols=${4:-4}
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
command -v oiiotool >/dev/null || { echo "oiiotool not found (scripts/install-deps.sh)" >&2; exit 1; }
[ -f "$font" ] || { echo "font $font not found (fonts-dejavu-core)" >&2; exit 1; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# channel names in file order, without their "(half)"/"(float)" notes
mapfile -t channels < <(oiiotool --info -v "$in" | sed -n 's/^ *channel list: //p' |
  sed 's/ ([a-z0-9]*)//g' | tr ',' '\n' | sed 's/^ *//')

# layers in order of first appearance; ":beauty" is the plain channels
declare -a layers=()
declare -A members=()
for c in "${channels[@]}"; do
  case $c in
    *.*) l=${c%.*} ;;
    *) l=":beauty" ;;
  esac
  # Cryptomatte: NAME00, NAME01, … → one tile NAME
  if [[ $l =~ ^(.*[A-Za-z_])[0-9][0-9]$ ]] && [[ " ${channels[*]} " == *" $l.G "* ]] &&
    [[ " ${channels[*]} " == *" $l.A "* ]]; then
    l="crypto:${BASH_REMATCH[1]}"
  fi
  if [ -z "${members[$l]+x}" ]; then
    layers+=("$l")
    members[$l]=""
  fi
  members[$l]+="$c "
done

# "R=a,G=b,B=c" from up to three channels (one channel: grey)
shuffle() {
  local -a ch=("$@")
  case ${#ch[@]} in
    1) echo "R=${ch[0]},G=${ch[0]},B=${ch[0]}" ;;
    2) echo "R=${ch[0]},G=${ch[1]},B=0.0" ;;
    *) echo "R=${ch[0]},G=${ch[1]},B=${ch[2]}" ;;
  esac
}

# comma lists of the per-channel minimum and range over the image
stats() {
  local s min max
  s=$(oiiotool "$1" --printstats)
  min=$(echo "$s" | sed -n 's/^ *Stats Min: //p' | head -1 | sed 's/ (.*//')
  max=$(echo "$s" | sed -n 's/^ *Stats Max: //p' | head -1 | sed 's/ (.*//')
  paste -d' ' <(echo "$min" | tr ' ' '\n') <(echo "$max" | tr ' ' '\n') | awk '
    NF == 2 { r = $2 - $1; if (r <= 0) r = 1; mins = mins sep $1; ranges = ranges sep r; sep = "," }
    END { print mins " " ranges }'
}

tiles=()
i=0
for l in "${layers[@]}"; do
  read -r -a ch <<<"${members[$l]}"
  raw="$tmp/raw$i.exr"
  case $l in
    ":beauty")
      label=beauty
      oiiotool "$in" --ch "R,G,B" --clamp:min=0:max=1 --colorconvert linear sRGB -o "$raw"
      ;;
    crypto:*)
      label="${l#crypto:} rank 0"
      c="${l#crypto:}00.G"
      oiiotool "$in" --ch "R=$c,G=$c,B=$c" -o "$raw"
      ;;
    *)
      label=$l
      short=("${ch[@]##*.}")
      sel="$tmp/sel$i.exr"
      oiiotool "$in" --ch "$(shuffle "${ch[@]:0:3}")" -d float -o "$sel"
      if [ "${short[*]:0:3}" = "R G B" ]; then
        oiiotool "$sel" --clamp:min=0:max=1 --colorconvert linear sRGB -o "$raw"
      else
        read -r mins ranges <<<"$(stats "$sel")"
        oiiotool "$sel" --fixnan black --subc "$mins" --divc "$ranges" \
          --clamp:min=0:max=1 -o "$raw"
      fi
      ;;
  esac
  t="$tmp/tile$i.png"
  oiiotool "$raw" --resize "${tile}x0" \
    --text:x=6:y=18:size=15:color=1,1,0.3:font="$font" "$label" \
    -d uint8 -o "$t"
  tiles+=("$t")
  i=$((i + 1))
done

n=${#tiles[@]}
[ "$cols" -gt "$n" ] && cols=$n
rows=$(((n + cols - 1) / cols))
oiiotool "${tiles[@]}" --mosaic:pad=4 "${cols}x${rows}" -d uint8 -o "$out"
echo "$out: $n passes, ${cols}x${rows}" >&2
