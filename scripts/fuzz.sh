#!/usr/bin/env bash
# Runs every fuzz target for a bounded time (default 60 s each) with cargo-fuzz (installed
# when missing; the stable toolchain acts as nightly through RUSTC_BOOTSTRAP=1). Inputs kept
# under fuzz/regressions/<target>/ seed each run and are replayed by `cargo test`.
#
#   scripts/fuzz.sh            # 60 s per target
#   scripts/fuzz.sh 600 query  # 10 minutes, one target
#
# A crash leaves its input in fuzz/artifacts/<target>/: copy it to fuzz/regressions/<target>/
# and fix the bug, so that `cargo test --workspace` replays it from then on.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-60}
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(tileset layer_file image_density query)
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked
export RUSTC_BOOTSTRAP=1
for t in "${targets[@]}"; do
    mkdir -p "fuzz/corpus/$t"
    echo "== $t: ${secs} s"
    cargo fuzz run "$t" "fuzz/corpus/$t" "fuzz/regressions/$t" -- \
        -max_total_time="$secs" -rss_limit_mb=4096 -timeout=10 -print_final_stats=1 2>&1 |
        grep -E "^(#[0-9]+.*DONE|stat::number_of_executed_units|stat::peak_rss|==[0-9]+==|SUMMARY|Test unit written|thread '.*' panicked)" || true
    if compgen -G "fuzz/artifacts/$t/*-*" >/dev/null; then
        echo "FAIL $t: see fuzz/artifacts/$t"
        exit 1
    fi
done
