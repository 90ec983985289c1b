#!/usr/bin/env bash
# Fails when a locked dependency needs a newer Rust than the workspace's
# `rust-version` (root Cargo.toml, shared by its three packages) says. Each package built for this host (Cargo.lock as is,
# all features, dev-dependencies included) needs at least its own
# `rust-version` and the first Rust of its edition (2018: 1.31, 2021: 1.56,
# 2024: 1.85). Our own code is held to `rust-version` by clippy's
# incompatible_msrv lint (clippy.toml extends it to tests).
set -euo pipefail
cd "$(dirname "$0")/.."

check=$(
  cat <<'PY'
import json, sys

EDITION_FLOOR = {"2015": "1.0", "2018": "1.31", "2021": "1.56", "2024": "1.85"}


def ver(s):
    parts = [int(x) for x in s.split(".")]
    return tuple(parts + [0] * (3 - len(parts)))


def show(v):
    return ".".join(map(str, v))


meta = json.load(sys.stdin)
ours_all = [p for p in meta["packages"] if p["id"] in meta["workspace_members"]]
root = ours_all[0]
if not all(p.get("rust_version") == root.get("rust_version") for p in ours_all):
    sys.exit("check-msrv: the workspace's packages must share one rust-version")
if not root.get("rust_version"):
    sys.exit("check-msrv: Cargo.toml has no rust-version")
ours = ver(root["rust_version"])

need = []
for p in meta["packages"]:
    if p["id"] in meta["workspace_members"]:
        continue
    floor = ver(EDITION_FLOOR[p["edition"]])
    why = "edition " + p["edition"]
    if p.get("rust_version") and ver(p["rust_version"]) > floor:
        floor = ver(p["rust_version"])
        why = "rust-version " + p["rust_version"]
    need.append((floor, "%s %s (%s)" % (p["name"], p["version"], why)))
need.sort()

too_new = [what for v, what in need if v > ours]
if too_new:
    print("check-msrv: Cargo.toml says rust-version = %s, but these locked "
          "dependencies need a newer Rust:" % root["rust_version"], file=sys.stderr)
    for what in too_new:
        print("  " + what, file=sys.stderr)
    sys.exit("check-msrv: raise rust-version to %s (or lower those dependencies)"
             % show(need[-1][0]))
print("check-msrv: rust-version %s covers the %d locked dependencies built for %s "
      "(the most demanding: %s)" % (root["rust_version"], len(need), sys.argv[1], need[-1][1]))
PY
)

host=$(rustc -vV | sed -n 's/^host: //p')
cargo metadata --format-version 1 --locked --all-features --filter-platform "$host" |
  python3 -c "$check" "$host"
