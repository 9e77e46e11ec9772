#!/usr/bin/env bash
# Runs fuzz targets for a bounded time (default 60 s each) or a number of inputs, with
# cargo-fuzz (installed when missing; the stable toolchain acts as nightly through
# RUSTC_BOOTSTRAP=1). The core targets (tileset, image_density, query, stipple) are in
# fuzz/ and build without Bevy; layer_file is in fuzz/bevy/. Inputs kept under
# fuzz/regressions/<target>/ seed each run and are replayed by `cargo test`.
#
#   scripts/fuzz.sh                    # 60 s per target
#   scripts/fuzz.sh 600 query          # 10 minutes, one target
#   RUNS=1000000 scripts/fuzz.sh 0 stipple   # a million inputs (no time limit)
#
# A crash leaves its input in fuzz/artifacts/<target>/ (fuzz/bevy/artifacts/ for
# layer_file): copy it to fuzz/regressions/<target>/ and fix the bug, so that
# `cargo test --workspace` replays it from then on.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(tileset image_density query stipple layer_file)
if ! command -v cargo-fuzz >/dev/null; then
    echo "== installing cargo-fuzz"
    cargo install cargo-fuzz --locked
fi
export RUSTC_BOOTSTRAP=1
limits=(-rss_limit_mb=2048 -timeout=10 -print_final_stats=1)
[ "$secs" != 0 ] && limits+=(-max_total_time="$secs")
[ -n "${RUNS:-}" ] && limits+=(-runs="$RUNS")
for t in "${targets[@]}"; do
    dir=fuzz
    [ "$t" = layer_file ] && dir=fuzz/bevy
    mkdir -p "$dir/corpus/$t"
    echo "== $t ($dir): ${secs} s${RUNS:+, $RUNS inputs}, $(date -u +%Y-%m-%dT%H:%MZ)"
    cargo fuzz run --sanitizer "${SANITIZER:-address}" --fuzz-dir "$dir" "$t" "$dir/corpus/$t" "fuzz/regressions/$t" -- "${limits[@]}" 2>&1 |
        grep -E "^(#[0-9]+.*DONE|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss|==[0-9]+==|SUMMARY|Test unit written|thread '.*' panicked)" || true
    if compgen -G "$dir/artifacts/$t/*-*" >/dev/null; then
        echo "FAIL $t: see $dir/artifacts/$t"
        exit 1
    fi
done
