#!/usr/bin/env bash
# Fuzz the scene parser, the LCP file readers, a short simulation, the mesh file readers and
# the world snapshot reader with cargo fuzz
# (libFuzzer). Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
#   SECONDS  time per target (default 600); targets run one after the other.
#   TARGET   scene_parser, lcp_readers, short_simulation, mesh_readers, snapshot_reader
#            (default: all five).
# cargo fuzz needs nightly compiler flags (-Z sanitizer, -C passes=sancov-module). The script
# sets RUSTC_BOOTSTRAP=1 so that a stable toolchain accepts them; no nightly is installed.
# The corpus grows under fuzz/corpus/<target> (seeded from scenes/*.json, the LCP test data and
# fuzz/seeds/<target> when empty); crashes are written to fuzz/artifacts/<target>. Environment: FUZZ_JOBS (libFuzzer
# -jobs/-workers, default 1: one process; more write fuzz/fuzz-<n>.log), CARGO_TARGET_DIR as usual. docs/fuzzing.md has the details.
set -euo pipefail

seconds="${1:-600}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(scene_parser lcp_readers short_simulation mesh_readers snapshot_reader)
fi
jobs="${FUZZ_JOBS:-1}"
# With -jobs libFuzzer runs workers that log to fuzz-<n>.log; one process logs here.
parallel=()
if [ "$jobs" -gt 1 ]; then
    parallel=(-jobs="$jobs" -workers="$jobs")
fi

root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root/fuzz"
export RUSTC_BOOTSTRAP=1

if ! cargo fuzz --version >/dev/null 2>&1; then
    echo "installing cargo-fuzz" >&2
    cargo install cargo-fuzz --locked
fi

# Seeds for an empty corpus: the repository's scenes (the large ones only slow the fuzzer down)
# and LCP files.
seed() {
    local target="$1" dir="corpus/$1"
    mkdir -p "$dir"
    if [ -n "$(ls -A "$dir")" ]; then
        return
    fi
    case "$target" in
        scene_parser | short_simulation)
            find "$root/scenes" -name '*.json' -size -50k -exec cp {} "$dir" \;
            ;;
        lcp_readers)
            cp "$root"/crates/impulse-lcp/tests/data/siconos/*.dat "$dir"
            cp seeds/lcp_readers/* "$dir"
            ;;
        mesh_readers | snapshot_reader)
            cp "seeds/$target"/* "$dir"
            ;;
    esac
}

# Per target: the largest input libFuzzer makes, and the time after which one input counts as
# a hang (the simulation target caps its work to milliseconds per input).
options() {
    case "$1" in
        short_simulation) echo "-max_len=8192 -timeout=10" ;;
        snapshot_reader) echo "-max_len=16384 -timeout=10" ;;
        *) echo "-max_len=65536 -timeout=10" ;;
    esac
}

for target in "${targets[@]}"; do
    seed "$target"
    log="$(mktemp)"
    echo "== $target: ${seconds} s" >&2
    # shellcheck disable=SC2046
    cargo fuzz run -O "$target" "corpus/$target" -- \
        -max_total_time="$seconds" -print_final_stats=1 "${parallel[@]}" \
        $(options "$target") 2>&1 | tee "$log" | grep -E '^(#[0-9]+[[:space:]]+(INITED|DONE)|Done|stat::number_of_executed_units|==[0-9]+== ERROR|SUMMARY|artifact_prefix|Test unit written)' || true
    status="${PIPESTATUS[0]}"
    runs="$(grep -E '^stat::number_of_executed_units' "$log" | tail -1 | awk '{print $2}')"
    echo "== $target: exit status $status, executions ${runs:-unknown} (full log: $log)" >&2
done
