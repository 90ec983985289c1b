#!/usr/bin/env bash
# Mutation testing of lucent's core with cargo-mutants: every mutant of the
# BSSRDF, the integrator, the materials and the BVH is built and run
# against the tests that cover those files; a mutant no test catches
# points at a missing test. Not run in CI (hours for the whole set; see
# docs/testing.md for the cost and how to split it into shards).
#
#   scripts/mutants.sh                      all core files
#   scripts/mutants.sh --file src/accel/bvh/traverse.rs
#   scripts/mutants.sh --shard 0/8          the first of 8 shards (k/n, k from 0)
#   scripts/mutants.sh --list               only list the mutants
#   scripts/mutants.sh --report [DIR]       only summarize an earlier run
#   scripts/mutants.sh --file F -- --re hit1    more cargo-mutants options
#
# Options may be combined; --file may be repeated; what follows `--` is
# passed to cargo-mutants. MUTANTS_TESTS replaces the test subset (cargo
# test arguments, e.g. MUTANTS_TESTS="--lib"). Results go to
# mutants.out/ (cargo-mutants' own layout: caught.txt, missed.txt,
# timeout.txt, unviable.txt, outcomes.json, per-mutant logs), and a table of
# caught / missed / timeout / unviable per file is printed at the end.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; }

# The core files, and the tests that cover them (the library's unit tests
# and the scene-level tests of transport, subsurface and the BVH).
CORE=(src/bssrdf src/integrator src/materials src/accel/bvh)
TESTS=(--lib --test furnace --test slab --test randomwalk --test hard_cases
    --test bvh_brute_force --test dielectric --test specular_coat --test params_edges)
if [ -n "${MUTANTS_TESTS:-}" ]; then
    read -r -a TESTS <<<"$MUTANTS_TESTS"
fi

files=()
extra=()
shard=""
list=0
report_only=""
out=mutants.out
while [ $# -gt 0 ]; do
    case "$1" in
        --file) files+=("$2"); shift 2 ;;
        --shard) shard="$2"; shift 2 ;;
        --list) list=1; shift ;;
        --report) report_only="${2:-$out}"; shift $(( $# > 1 ? 2 : 1 )) ;;
        -h|--help) usage; exit 0 ;;
        --) shift; extra=("$@"); break ;;
        *) echo "mutants.sh: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
    esac
done

# Per file: caught / missed / timeout / unviable, from the outcome lists
# cargo-mutants writes (one mutant per line, "FILE:LINE:COL: description").
report() {
    local dir="$1"
    [ -d "$dir" ] || { echo "mutants.sh: no $dir to report on" >&2; exit 1; }
    for kind in caught missed timeout unviable; do
        [ -f "$dir/$kind.txt" ] || continue
        sed -E "s/^([^:]+):.*/\1 $kind/" "$dir/$kind.txt"
    done | sort | awk '
        # mawk has no asorti: the input is sorted, files keep that order
        !($1 in seen) { seen[$1] = 1; order[++m] = $1 }
        { n[$1, $2]++; total[$2]++ }
        END {
            printf "%-40s %7s %7s %7s %8s\n", "file", "caught", "missed", "timeout", "unviable"
            for (i = 1; i <= m; i++) {
                f = order[i]
                printf "%-40s %7d %7d %7d %8d\n", f, n[f, "caught"], n[f, "missed"], n[f, "timeout"], n[f, "unviable"]
            }
            printf "%-40s %7d %7d %7d %8d\n", "total", total["caught"], total["missed"], total["timeout"], total["unviable"]
        }'
    if [ -s "$dir/missed.txt" ]; then
        echo
        echo "missed (no test failed):"
        sed 's/^/  /' "$dir/missed.txt"
    fi
}

if [ -n "$report_only" ]; then
    report "$report_only"
    exit 0
fi

if ! cargo mutants --version >/dev/null 2>&1; then
    echo "--- installing cargo-mutants ---"
    cargo install --locked cargo-mutants
fi

if [ ${#files[@]} -eq 0 ]; then
    files=("${CORE[@]}")
fi
args=()
for f in "${files[@]}"; do
    if [ -d "$f" ]; then
        args+=(--file "$f/**/*.rs")
    else
        args+=(--file "$f")
    fi
done
if [ -n "$shard" ]; then
    args+=(--shard "$shard")
fi

if [ "$list" = 1 ]; then
    cargo mutants --list "${args[@]}" "${extra[@]}"
    exit 0
fi

# cargo-mutants exits non-zero when a mutant is missed; the report is what
# matters, so it is printed either way and that status is passed on.
status=0
cargo mutants "${args[@]}" "${extra[@]}" -- "${TESTS[@]}" || status=$?
echo
report "$out"
exit "$status"
