#!/usr/bin/env bash
# Mutation testing of lucent's core with cargo-mutants: every mutant of the
# BSSRDF, the integrator, the materials and the BVH is built and run
# against the tests that cover those files; a mutant no test catches
# points at a missing test. Not run in CI (hours for the whole set; see
# docs/testing.md for the cost and how to split it into shards).
#
#   scripts/mutants.sh                      all core files
#   scripts/mutants.sh --file crates/lucent/src/accel/bvh/traverse.rs
#   scripts/mutants.sh --shard 0/8          the first of 8 shards (k/n, k from 0)
#   scripts/mutants.sh --list               only list the mutants
#   scripts/mutants.sh --report [DIR]       only summarize an earlier run
#   scripts/mutants.sh --file F -- --re hit1    more cargo-mutants options
#   scripts/mutants.sh --sample 200 --seed 1 [--stop-at 15:40]
#                                           a seeded random sample, one
#                                           mutant at a time, in place
#   scripts/mutants.sh --sample-report mutants/sampled-seed-1.txt
#
# Options may be combined; --file may be repeated; what follows `--` is
# passed to cargo-mutants. MUTANTS_TESTS replaces the test subset (cargo
# test arguments, e.g. MUTANTS_TESTS="--lib"). Results go to
# mutants.out/ (cargo-mutants' own layout: caught.txt, missed.txt,
# timeout.txt, unviable.txt, outcomes.json, per-mutant logs), and a table of
# caught / missed / timeout / unviable per file is printed at the end.
#
# --sample N --seed S: the core's mutants (or those of --file) ordered by
# sha256("S:" + name), a seeded uniformly random permutation, and the first
# N of them run one by one with the test subset of their folder (below),
# IN PLACE: run it only in a clean clone of your own, never in a checkout
# someone edits. Each outcome is appended to mutants/sampled-seed-S.txt
# (outcome, seconds, name); mutants already there are skipped, so running
# again with a larger N continues the same sample. --stop-at HH:MM (UTC)
# starts no mutant after that time (the next such time: a time earlier than
# now is tomorrow's, so a run started at 23:10 with --stop-at 01:30 stops
# after midnight, not at once).
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; }

# The core files, and the tests that cover them (the library's unit tests
# and the scene-level tests of transport, subsurface and the BVH).
CORE=(crates/lucent/src/bssrdf crates/lucent/src/integrator crates/lucent/src/materials crates/lucent/src/accel/bvh)
# The smallest subsets that cover each folder (sample mode): the unit
# tests, which cargo runs first and which stop the run when they catch the
# mutant, then the group binaries (tests/README.md) whose scene-level tests
# reach the folder's code. Only these test binaries are built for a mutant;
# a group runs whole (a name filter would apply to the unit tests too).
TESTS_BVH=(--lib --test accel)
TESTS_BSSRDF=(--lib --test physics --test cli)
TESTS_MATERIALS=(--lib --test physics --test cli)
TESTS_INTEGRATOR=(--lib --test physics --test cli)
TESTS_AOV=(--lib --test cli)
TESTS=(--lib --test physics --test accel)
if [ -n "${MUTANTS_TESTS:-}" ]; then
    read -r -a TESTS <<<"$MUTANTS_TESTS"
fi

files=()
extra=()
shard=""
list=0
report_only=""
sample=""
seed=""
stop_at=""
sample_report=""
out=mutants.out
while [ $# -gt 0 ]; do
    case "$1" in
        --file) files+=("$2"); shift 2 ;;
        --shard) shard="$2"; shift 2 ;;
        --list) list=1; shift ;;
        --report) report_only="${2:-$out}"; shift $(( $# > 1 ? 2 : 1 )) ;;
        --sample) sample="$2"; shift 2 ;;
        --seed) seed="$2"; shift 2 ;;
        --stop-at) stop_at="$2"; shift 2 ;;
        --sample-report) sample_report="$2"; shift 2 ;;
        -h|--help) usage; exit 0 ;;
        --) shift; extra=("$@"); break ;;
        *) echo "mutants.sh: unknown argument '$1'" >&2; usage >&2; exit 2 ;;
    esac
done

# The test selection as options of every cargo command cargo-mutants runs:
# given after `--` it reaches only `cargo test`, and the build before it
# (`cargo test --no-run`) would build every test target and example.
cargo_args() {
    while [ $# -gt 0 ]; do
        if [ "$1" = --test ]; then
            printf -- '--cargo-arg=--test=%s\n' "$2"; shift 2
        else
            printf -- '--cargo-arg=%s\n' "$1"; shift
        fi
    done
}

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

# Per file and in total, from a sample record (outcome, seconds, name):
# tested / caught / missed / timeout / unviable, and the score
# caught / (caught + missed + timeout) with its 95 % Wilson interval.
sample_summary() {
    local rec="$1"
    [ -f "$rec" ] || { echo "mutants.sh: no $rec" >&2; exit 1; }
    grep -v '^#' "$rec" | awk -F '\t' '
        { split($3, a, ":"); f = a[1]; k = $1
          if (!(f in seen)) { seen[f] = 1; order[++m] = f }
          n[f, k]++; n[f, "tested"]++; t[k]++; t["tested"]++; secs += $2 }
        function row(name, tested, c, mi, to, un) {
            printf "%-40s %6d %6d %6d %7d %8d\n", name, tested, c, mi, to, un }
        END {
            printf "%-40s %6s %6s %6s %7s %8s\n", "file", "tested", "caught", "missed", "timeout", "unviable"
            for (i = 1; i <= m; i++) { f = order[i]
                row(f, n[f, "tested"], n[f, "caught"], n[f, "missed"], n[f, "timeout"], n[f, "unviable"]) }
            row("total", t["tested"], t["caught"], t["missed"], t["timeout"], t["unviable"])
            # A timeout counts as caught (the mutant made the tests hang),
            # as cargo-mutants itself treats it; shown apart above.
            nv = t["caught"] + t["missed"] + t["timeout"]; k = t["caught"] + t["timeout"]
            if (nv > 0) {
                z = 1.959964; p = k / nv; d = 1 + z * z / nv
                c = (p + z * z / (2 * nv)) / d
                h = z * sqrt(p * (1 - p) / nv + z * z / (4 * nv * nv)) / d
                printf "score %d / %d viable caught = %.1f %%, 95 %% Wilson interval [%.1f, %.1f] %%\n", k, nv, 100 * p, 100 * (c - h), 100 * (c + h)
            }
            if (t["tested"] > 0) printf "mean %.0f s per mutant (%d s in all)\n", secs / t["tested"], secs
        }'
}

if [ -n "$sample_report" ]; then
    sample_summary "$sample_report"
    exit 0
fi

if [ -n "$report_only" ]; then
    report "$report_only"
    exit 0
fi

if ! cargo mutants --version >/dev/null 2>&1; then
    echo "--- installing cargo-mutants ---"
    cargo install --locked cargo-mutants --version '^27'
fi

if [ ${#files[@]} -eq 0 ]; then
    files=("${CORE[@]}")
fi
# The library's files are mutated, but most tests covering them are the
# root package's (tests/): test the whole workspace, not only the package
# that holds the mutated file.
args=(--test-workspace=true)
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

if [ -n "$sample" ]; then
    [ -n "$seed" ] || { echo "mutants.sh: --sample needs --seed" >&2; exit 2; }
    deadline=""
    if [ -n "$stop_at" ]; then
        if ! [[ "$stop_at" =~ ^([01][0-9]|2[0-3]):[0-5][0-9]$ ]]; then
            echo "mutants.sh: --stop-at wants HH:MM (UTC), got '$stop_at'" >&2
            exit 2
        fi
        deadline=$(date -u -d "today $stop_at" +%s)
        if [ "$deadline" -le "$(date -u +%s)" ]; then
            deadline=$(( deadline + 86400 ))
        fi
    fi
    if [ -n "$(git status --porcelain --untracked-files=no -- src tests)" ]; then
        echo "mutants.sh: --sample mutates the tree in place; run it in a clean clone" >&2
        exit 2
    fi
    mkdir -p mutants
    rec="mutants/sampled-seed-$seed.txt"
    if [ -f "$rec" ]; then
        # a continuation draws from this commit's list (names carry line
        # numbers): say so in the record
        printf '# continued at commit %s\n' "$(git rev-parse --short HEAD)" >>"$rec"
    else
        printf '# outcome\tseconds\tmutant (seed %s; commit %s)\n' \
            "$seed" "$(git rev-parse --short HEAD)" >"$rec"
    fi
    # Seeded permutation: sort by sha256 of seed and name.
    cargo mutants --list "${args[@]}" | while IFS= read -r m; do
        printf '%s\t%s\n' "$(printf '%s:%s' "$seed" "$m" | sha256sum | cut -c1-16)" "$m"
    done | sort | cut -f2- >mutants.out.order
    # (not `| head`: with pipefail, the writer's SIGPIPE would end the script)
    sed -n "1,${sample}p" mutants.out.order >mutants.out.sample
    while IFS= read -r m; do
        if [ -n "$deadline" ] && [ "$(date -u +%s)" -gt "$deadline" ]; then
            echo "mutants.sh: past $stop_at, stopping"
            break
        fi
        if M="$m" awk -F '\t' '$3 == ENVIRON["M"] { f = 1 } END { exit !f }' "$rec"; then
            continue
        fi
        file="${m%%:*}"
        case "$file" in
            crates/lucent/src/accel/bvh/*) t=("${TESTS_BVH[@]}") ;;
            crates/lucent/src/bssrdf/*) t=("${TESTS_BSSRDF[@]}") ;;
            crates/lucent/src/materials/*) t=("${TESTS_MATERIALS[@]}") ;;
            crates/lucent/src/integrator/aov/*) t=("${TESTS_AOV[@]}") ;;
            crates/lucent/src/integrator/*) t=("${TESTS_INTEGRATOR[@]}") ;;
            *) t=("${TESTS[@]}") ;;
        esac
        if [ -n "${MUTANTS_TESTS:-}" ]; then t=("${TESTS[@]}"); fi
        re="^$(printf '%s' "$m" | sed 's/[][\.|$(){}?+*^]/\\&/g')\$"
        start=$(date +%s)
        rm -rf mutants.out
        cargo mutants --in-place --baseline skip --timeout "${MUTANTS_TIMEOUT:-300}" \
            --no-shuffle --file "$file" --re "$re" $(cargo_args "${t[@]}") "${extra[@]}" \
            >mutants.out.log 2>&1 || true
        secs=$(( $(date +%s) - start ))
        outcome=error
        for kind in caught missed timeout unviable; do
            if [ -f "mutants.out/$kind.txt" ] && grep -qxF -- "$m" "mutants.out/$kind.txt"; then
                outcome=$kind
            fi
        done
        if [ "$outcome" = error ]; then
            echo "mutants.sh: no outcome for '$m' (see mutants.out.log)" >&2
            git checkout -- src
            exit 1
        fi
        printf '%s\t%s\t%s\n' "$outcome" "$secs" "$m" | tee -a "$rec"
    done <mutants.out.sample
    echo
    sample_summary "$rec"
    exit 0
fi

if [ "$list" = 1 ]; then
    cargo mutants --list "${args[@]}" "${extra[@]}"
    exit 0
fi

# cargo-mutants exits non-zero when a mutant is missed; the report is what
# matters, so it is printed either way and that status is passed on.
status=0
cargo mutants "${args[@]}" $(cargo_args "${TESTS[@]}") "${extra[@]}" || status=$?
echo
report "$out"
exit "$status"
