#!/usr/bin/env bash
# Mutation testing (cargo-mutants) of the contact solver, the contact rows, the settings and the
# islands: each mutant is a one-token change of the source (an operator swapped, a function body
# replaced by a default, a match arm deleted); the impulse package's tests run against it and
# should fail. On demand, not in CI: a mutant costs about 45 s here (rebuild and tests), and the
# files below give about 2,400 of them.
# Usage: scripts/mutants.sh [OUT_DIR] [SHARD] [JOBS]
#   OUT_DIR  where mutants.out/ goes (default target/mutants)
#   SHARD    k/n: run only mutants i with i mod n = k (a spread sample); default all
#   JOBS     parallel build/test jobs (default 1)
# Results: OUT_DIR/mutants.out/{caught,missed,timeout,unviable}.txt; docs/testing.md reports them.
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/target/mutants}"
shard="${2:-}"
jobs="${3:-1}"
cd "$root"
if ! cargo mutants --version >/dev/null 2>&1; then
    cargo install --locked cargo-mutants
fi
files=()
for f in crates/impulse/src/solver/*.rs crates/impulse/src/contact/*.rs \
    crates/impulse/src/settings.rs crates/impulse/src/island.rs; do
    case "$f" in *_tests.rs) continue ;; esac
    files+=(-f "$f")
done
# Shuffled, so that a run stopped early is still a spread sample of its mutants.
sharding=(--shuffle)
if [ -n "$shard" ]; then
    sharding+=(--shard "$shard" --sharding round-robin)
fi
mkdir -p "$out"
# A target directory of the copy's own: sharing the workspace's would rebuild it each time.
env -u CARGO_TARGET_DIR cargo mutants --package impulse "${files[@]}" "${sharding[@]}" \
    --jobs "$jobs" --timeout 300 --output "$out"
