#!/usr/bin/env bash
# Long runs of the mutation fuzzer (tests/robustness/fuzz.rs): `scripts/fuzz.sh
# [SECONDS] [SEED]` (defaults: 600 s, a seed from the clock, printed).
# Every failing case is saved under tests/fuzz-corpus/ (scene, mesh,
# arguments, and an `expect` file with the exit codes allowed and what
# was found), where the `corpus_replays` test runs it on every test run
# until it is fixed. LUCENT_FUZZ_JOBS sets the cases run in parallel
# (default 2), LUCENT_FUZZ_CASE_TIMEOUT the seconds after which a case
# counts as a hang (default 30). The files fuzzer (tests/robustness/
# fuzz_files.rs: parts, output paths) then runs LUCENT_FUZZ_FILE_CASES
# cases (default 400), and the study-directory fuzzer (fuzz_study.rs)
# LUCENT_FUZZ_STUDY_CASES (default 200).
set -euo pipefail
cd "$(dirname "$0")/.."
export LUCENT_FUZZ_SECONDS="${1:-${LUCENT_FUZZ_SECONDS:-600}}"
export LUCENT_FUZZ_SEED="${2:-${LUCENT_FUZZ_SEED:-$(date +%s)}}"
export LUCENT_FUZZ_CORPUS="${LUCENT_FUZZ_CORPUS:-$PWD/tests/fuzz-corpus}"
echo "fuzzing for ${LUCENT_FUZZ_SECONDS} s with seed ${LUCENT_FUZZ_SEED}; failures go to ${LUCENT_FUZZ_CORPUS}"
cargo test --test robustness fuzz::mutated_inputs_end_in_an_image_or_a_clear_error -- --nocapture
export LUCENT_FUZZ_FILE_CASES="${LUCENT_FUZZ_FILE_CASES:-400}"
cargo test --test robustness fuzz_files::damaged_files_and_hostile_output_paths_end_cleanly -- --nocapture
export LUCENT_FUZZ_STUDY_CASES="${LUCENT_FUZZ_STUDY_CASES:-200}"
cargo test --test robustness fuzz_study::damaged_study_directories_end_cleanly -- --nocapture
