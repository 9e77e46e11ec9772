#!/usr/bin/env bash
# Runs every example in a real renderer (Xvfb + Mesa's lavapipe Vulkan driver) through its
# scripted session (RWT_SCREENSHOT), and fails when an example exits with an error, its
# screenshot is missing or blank (luminance variance < 20), or it reports 0 instances
# (entities and instanced together), or open_world has fewer than a million instanced blades.
#
#   scripts/smoke.sh                 # debug build (reuses `cargo test`'s), screenshots in target/smoke
#   scripts/smoke.sh --docs          # release build, and refresh docs/screenshots/*.png
set -euo pipefail
cd "$(dirname "$0")/.."
docs=0
[ "${1:-}" = "--docs" ] && docs=1
scripts/render_deps.sh
examples=(quickstart open_world paint_density stipple_zoom)
if [ $docs = 1 ]; then
    cargo build --release --examples
    bin=target/release/examples
else
    cargo build --examples
    bin=target/debug/examples
fi
out=target/smoke
mkdir -p "$out"

export DISPLAY=:93
Xvfb $DISPLAY -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
sleep 2
icd=$(ls /usr/share/vulkan/icd.d/lvp_icd*.json | head -1)
export VK_ICD_FILENAMES=$icd VK_DRIVER_FILES=$icd WGPU_BACKEND=vulkan
export BEVY_ASSET_ROOT=$PWD RUST_LOG=${RUST_LOG:-warn} RWT_PAINT_DIR=$PWD/$out/painted

failed=0
for ex in "${examples[@]}"; do
    png=$out/$ex.png
    rm -f "$png"
    start=$(date +%s)
    if ! RWT_SCREENSHOT=$png timeout 600 "$bin/$ex" >"$out/$ex.log" 2>&1; then
        echo "FAIL $ex: exited with an error"; tail -20 "$out/$ex.log"; failed=1; continue
    fi
    line=$(grep -E '^rwt-smoke: screenshot' "$out/$ex.log" || true)
    instances=$(sed -nE 's/.* instances ([0-9]+) instanced [0-9]+$/\1/p' <<<"$line")
    instanced=$(sed -nE 's/.* instanced ([0-9]+)$/\1/p' <<<"$line")
    if [ ! -s "$png" ]; then
        echo "FAIL $ex: no screenshot"; tail -20 "$out/$ex.log"; failed=1; continue
    fi
    read -r w h var < <(python3 scripts/png_stats.py "$png")
    secs=$(( $(date +%s) - start ))
    echo "$ex: ${w}x${h}, luminance variance $var, instances ${instances:-?}, instanced ${instanced:-?}, ${secs} s"
    if python3 -c "import sys; sys.exit(0 if float('$var') >= 20 else 1)"; then :; else
        echo "FAIL $ex: blank screenshot"; failed=1
    fi
    if [ -z "$instances" ] || [ $((instances + ${instanced:-0})) -eq 0 ]; then
        echo "FAIL $ex: no instances"; failed=1
    fi
    if [ "$ex" = open_world ] && [ "${instanced:-0}" -lt 1000000 ]; then
        echo "FAIL $ex: fewer than a million instanced blades"; failed=1
    fi
    if [ $docs = 1 ] && [ $failed = 0 ]; then
        mkdir -p docs/screenshots
        python3 scripts/png_stats.py "$png" --half "docs/screenshots/$ex.png" >/dev/null
    fi
done
exit $failed
