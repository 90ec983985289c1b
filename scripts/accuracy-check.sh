#!/usr/bin/env bash
# Checks the accuracy budget's predictions (docs/accuracy.md, "Accuracy
# budget"): for each scene and budget, the estimator `--accuracy` chooses
# and the error the model predicts for it (`--explain=json`), against the
# error examples/error_model.rs measures between K renders of that choice
# and K renders of the random walk (other seeds); "held" when the measured
# error is within the budget. A walk chosen is measured against the
# reference walk: its error is the measurement's noise floor.
#
#   scripts/accuracy-check.sh [K [SPP]]     # defaults 4 seeds × 256 spp
#
# Scenes (48², black background): scenes/keylight-sphere.toml and
# scenes/keylight-bunny.toml (marble under a key light), the bunny with
# its lamp replaced by a constant environment and a transparent film
# (uniform light), and the sphere in skin1 (another material than the
# model's). 1 thread, niced; about 10 minutes on one core.
set -euo pipefail
cd "$(dirname "$0")/.."
k=${1:-4}
spp=${2:-256}
budgets=${BUDGETS:-"2% 5% 10% 20%"}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
cargo build --profile quick --bin lucent --example error_model >&2
cp target/quick/lucent "$out/lucent"
bin="$out/lucent"
em=target/quick/examples/error_model
awk '/^\[\[shapes\]\]/ { n++ } !(n == 1) { print }' scenes/keylight-bunny.toml \
    >"$out/uniform-bunny.toml"
printf '\n[environment]\nradiance = [1.0, 1.0, 1.0]\n' >>"$out/uniform-bunny.toml"
sed -e 's/^preset = "marble".*/preset = "skin1"/' scenes/keylight-sphere.toml >"$out/skin-sphere.toml"
cp scenes/keylight-sphere.toml scenes/keylight-bunny.toml "$out/"
ln -s "$PWD/scenes/meshes" "$out/meshes"
render() { # scene tag first-seed flags…
    local s=$1 tag=$2 first=$3
    shift 3
    for i in $(seq 0 $((k - 1))); do
        nice -n 5 "$bin" render "$s" --spp "$spp" --seed $((first + i)) --threads 1 \
            --transparent "$@" -q -o "$out/$tag-$i.exr"
    done
}
files() { for i in $(seq 0 $((k - 1))); do echo "$out/$1-$i.exr"; done; }
echo "scene,budget,chosen,predicted,measured,sigma,held"
for name in keylight-sphere keylight-bunny uniform-bunny skin-sphere; do
    s="$out/$name.toml"
    render "$s" "$name-ref" 1 --integrator randomwalk
    for b in $budgets; do
        read -r chosen predicted < <("$bin" render "$s" --accuracy "$b" --explain=json |
            python3 -c 'import json,sys
b = json.load(sys.stdin)["materials"]
b = [m["budget"] for m in b if m.get("budget")][0]
i = ["burley", "tabulated", "walk"].index(b["chosen"])
print(b["chosen"], max(o["candidates"][i]["error"] for o in b["objects"]))')
        tag="$name-$chosen"
        [ -e "$out/$tag-0.exr" ] || render "$s" "$tag" 101 --accuracy "$b"
        # shellcheck disable=SC2046
        read -r e sg < <("$em" $(files "$tag") -- $(files "$name-ref"))
        frac=$(awk "BEGIN { v = \"$b\"; sub(/%/, \"\", v); print v / 100 }")
        held=$(awk "BEGIN { print ($e <= $frac) ? \"yes\" : \"no\" }")
        echo "$name,$b,$chosen,$predicted,$e,$sg,$held"
    done
done
