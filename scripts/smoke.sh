#!/usr/bin/env bash
# Runs every example in a real renderer (Xvfb + Mesa's lavapipe Vulkan driver) through its
# scripted session (RWT_SCREENSHOT), and fails when an example exits with an error, its
# screenshot is missing or blank (luminance variance < 20), or it reports 0 instances
# (entities and instanced together), or open_world has fewer than a million instanced blades
# or its scripted brush stroke changed no instance (`painted 0`) or its brush did not save
# the painted maps and layer files, or (its `eye` view) the trees it chopped and the ground
# its cabin cleared did not persist through a flight 3 km away and back, or its walker on
# foot did not stop at a tree's trunk, or stipple_zoom lost a dot in view while zooming in
# (or took fewer than its three screenshots, 1x, 30x and 1000x), or mesh_ground placed an
# instance off its glTF level's surfaces (floating, buried, on a wall); and runs
# instanced_passes, which fails unless instanced grass receives and casts shadows and is
# drawn with 4x MSAA and with the prepasses, TAA and SSAO, gpu_culling, which fails unless the frame culled
# per instance on the GPU is the frame drawn whole and its indirect counts are the CPU's, and
# gpu_occlusion, which fails unless a camera rising over a hill, occluding, draws the frame
# drawn whole (the blades peeking over the crest included) and occlusion dropped instances,
# impostor_match, which fails unless trees drawn as impostors cover the pixels their meshes
# cover (silhouette IoU >= 0.8), coloured alike, culled per instance as the CPU does, and
# asset_match, which fails unless a glTF asset drawn instanced covers the pixels Bevy's own
# scene entities of it cover (silhouette IoU >= 0.98, each primitive's colour in its place),
# asset_shadows, which fails unless an asset's cut-out leaves cast their shadows where Bevy's
# own scene entities of it cast theirs (shadow IoU >= 0.85) and its moss receives them,
# asset_lods, which fails unless an asset's levels of detail, chosen per instance on the
# GPU, draw fewer vertices as the camera moves away, each instance the level its distance
# calls for, and multiplayer, which fails unless a server and three players (processes on
# 127.0.0.1, a server restart from its save between them) end with the same edits and
# cabins.
#
#   scripts/smoke.sh                 # debug build (reuses `cargo test`'s), screenshots in target/smoke
#   scripts/smoke.sh --docs          # release build, and refresh docs/screenshots/*.png, with
#                                    # open_world's five views (RWT_VIEW=eye|forest|aerial|brush|
#                                    # clearing, the eye view's gameplay seen from above)
#   scripts/smoke.sh --docs open_world:clearing   # only the runs named
set -euo pipefail
cd "$(dirname "$0")/.."
docs=0
[ "${1:-}" = "--docs" ] && docs=1 && shift
scripts/render_deps.sh
examples=(quickstart open_world paint_density stipple_zoom mesh_ground instanced_passes gpu_culling gpu_occlusion impostor_match asset_match asset_shadows asset_lods multiplayer)
runs=("${examples[@]}")
if [ $docs = 1 ]; then
    runs=(quickstart open_world:eye open_world:forest open_world:aerial open_world:brush open_world:clearing paint_density stipple_zoom mesh_ground instanced_passes gpu_culling gpu_occlusion impostor_match asset_match asset_shadows asset_lods multiplayer)
fi
[ $# -gt 0 ] && runs=("$@")
# The examples the runs need, once each.
mapfile -t needed < <(printf '%s\n' "${runs[@]%%:*}" | sort -u)
build=()
# quickstart is the game a user copies, with nothing but bevy and bevy_rwt: its check runs
# the same systems under the harness (examples/quickstart_check.rs).
binary() { if [ "$1" = quickstart ]; then echo quickstart_check; else echo "$1"; fi; }
for ex in "${needed[@]}"; do build+=(--example "$(binary "$ex")"); done
if [ $docs = 1 ]; then
    cargo build --release "${build[@]}"
    bin=target/release/examples
else
    # The binaries `cargo test --workspace` builds (CI's test stage): one build with the
    # workspace's features, not a second one with the examples' own (`cargo build
    # --example NAME` unifies features over fewer packages and rebuilds much of Bevy).
    cargo test --workspace --no-run
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
# CI's runs check behaviour on a 640 x 360 window (a quarter of the pixels lavapipe shades on
# the CPU); the screenshots for the docs are 1280 x 720.
# The docs' screenshots show the game, not the debug overlay.
if [ $docs = 0 ]; then export RWT_WINDOW=${RWT_WINDOW:-640x360}; else export RWT_HUD=${RWT_HUD:-off}; fi

failed=0
# Runs example $ex (log $name) that checks itself: $1 (VAR=folder) names where it saves its
# screenshots; it passes when it printed `$2: $3...` and no `$2: FAIL` or ERROR line.
self_checked() {
    env "$1" timeout 1200 "$bin/$(binary "$ex")" >"$out/$name.log" 2>&1 || true
    line=$(grep -E "^$2: $3" "$out/$name.log" || true)
    echo "$name: ${line:-no result line}, $(( $(date +%s) - start )) s"
    if [ -z "$line" ] || grep -qE "^$2: FAIL|ERROR" "$out/$name.log"; then
        echo "FAIL $name"; grep -E 'FAIL|ERROR' -A6 "$out/$name.log" | head -30; failed=1
    fi
}
for run in "${runs[@]}"; do
    ex=${run%%:*}
    view=${run#*:}; [ "$view" = "$run" ] && view=
    name=$ex${view:+_$view}
    png=$out/$name.png
    rm -f "$png"
    start=$(date +%s)
    if [ "$ex" = instanced_passes ]; then
        # Its own screenshots, compared region by region: grass receives and casts
        # shadows, and is drawn with the prepasses, TAA and SSAO.
        self_checked RWT_PASSES_DIR=$out/passes rwt-passes 'cards'
        continue
    fi
    if [ "$ex" = gpu_culling ]; then
        # Culling per instance: the frame matches the whole chunks' and the GPU's counts
        # the CPU's, again once the slab grew and shrank under the field.
        self_checked RWT_CULLING_DIR=$out/culling rwt-culling '(draws|slab)'
        continue
    fi
    if [ "$ex" = gpu_occlusion ]; then
        # Occlusion: the frame of a camera rising over a hill matches the whole chunks',
        # its late phase kept what the early phase's stale depth hid.
        self_checked RWT_OCCLUSION_DIR=$out/occlusion rwt-occlusion 'draws'
        continue
    fi
    if [ "$ex" = impostor_match ]; then
        # Impostors: trees as cards cover their meshes' pixels, coloured alike.
        self_checked RWT_IMPOSTOR_DIR=$out/impostor rwt-impostor 'trees'
        continue
    fi
    if [ "$ex" = asset_match ]; then
        # Assets: rwt's instanced draw of a glTF asset against Bevy's scene entities.
        self_checked RWT_ASSET_DIR=$out/asset rwt-asset 'instances'
        continue
    fi
    if [ "$ex" = asset_shadows ]; then
        # Shadows of an asset: rwt's cut-out card casts where Bevy's own scene casts.
        self_checked RWT_ASSET_SHADOWS_DIR=$out/asset_shadows rwt-asset-shadows 'instances'
        continue
    fi
    if [ "$ex" = multiplayer ]; then
        # Multiplayer: the server and three players as processes on 127.0.0.1 (A chops and
        # asks for a cabin, B joins late, the server restarts from its save, B reconnects, C
        # joins late and takes the screenshot); every world must hold the same edits and
        # cabins. 15 % of the vegetation grows: three debug windows render at once.
        RWT_DETAIL=${RWT_DETAIL:-0.15} self_checked RWT_SCREENSHOT=$png rwt-multiplayer 'agree'
        [ -s "$png" ] || { echo "FAIL $name: no screenshot"; failed=1; }
        if [ $docs = 1 ] && [ $failed = 0 ]; then
            mkdir -p docs/screenshots
            python3 scripts/png_stats.py "$png" --half docs/screenshots/multiplayer_late_player.png >/dev/null
        fi
        continue
    fi
    if [ "$ex" = asset_lods ]; then
        # Levels of detail per instance: the vertices the indirect arguments draw.
        self_checked RWT_LODS=1 rwt-lods 'vertices'
        continue
    fi
    # CI's runs take fewer frames than the 150 of the docs' (the same checks): open_world
    # flies its path in 100 (its script waits for streaming to settle before each check),
    # quickstart and mesh_ground, which script nothing, take their screenshot after 80
    # (streaming settles within about 60 at 640x360).
    frames=
    if [ $docs = 0 ]; then
        case $ex in
        open_world) frames=100 ;;
        quickstart | mesh_ground) frames=80 ;;
        esac
    fi
    if ! RWT_EXIT_AFTER_FRAMES=$frames RWT_VIEW=$view RWT_SCREENSHOT=$png timeout 1200 "$bin/$(binary "$ex")" >"$out/$name.log" 2>&1; then
        echo "FAIL $name: exited with an error"; tail -20 "$out/$name.log"; failed=1; continue
    fi
    line=$(grep -E '^rwt-smoke: screenshot' "$out/$name.log" || true)
    instances=$(sed -nE 's/.* instances ([0-9]+) instanced [0-9]+( painted [0-9]+)?$/\1/p' <<<"$line")
    instanced=$(sed -nE 's/.* instanced ([0-9]+)( painted [0-9]+)?$/\1/p' <<<"$line")
    painted=$(sed -nE 's/.* painted ([0-9]+)$/\1/p' <<<"$line")
    grep -E '^rwt-smoke: pending' "$out/$name.log" || true
    if [ ! -s "$png" ]; then
        echo "FAIL $ex: no screenshot"; tail -20 "$out/$ex.log"; failed=1; continue
    fi
    read -r w h var < <(python3 scripts/png_stats.py "$png")
    secs=$(( $(date +%s) - start ))
    echo "$name: ${w}x${h}, luminance variance $var, instances ${instances:-?}, instanced ${instanced:-?}, painted ${painted:--}, ${secs} s"
    if python3 -c "import sys; sys.exit(0 if float('$var') >= 20 else 1)"; then :; else
        echo "FAIL $name: blank screenshot"; failed=1
    fi
    if [ -z "$instances" ] || [ $((instances + ${instanced:-0})) -eq 0 ]; then
        echo "FAIL $name: no instances"; failed=1
    fi
    if [ "$ex" = open_world ]; then
        if [ "${instanced:-0}" -lt 1000000 ]; then
            echo "FAIL $name: fewer than a million instanced blades"; failed=1
        fi
        if [ "${painted:-0}" -eq 0 ]; then
            echo "FAIL $name: the scripted brush stroke changed no instance"; failed=1
        fi
        if [ -z "$view" ] || [ "$view" = eye ] || [ "$view" = clearing ]; then
            # The scripted gameplay: trees chopped, a cabin's footprint cleared, all still so
            # after flying 3 km away and back.
            play=$(grep -E '^rwt-smoke: gameplay chopped' "$out/$name.log" || true)
            echo "${play:-FAIL $name: no gameplay line}"
            read -r c k p < <(sed -nE 's/.*chopped ([0-9]+) cleared ([0-9]+) persisted ([0-9]+)$/\1 \2 \3/p' <<<"$play")
            if [ -z "${c:-}" ] || [ "$c" -eq 0 ] || [ "$k" -eq 0 ] || [ "$p" -ne $((c + k)) ]; then
                echo "FAIL $name: chopped and cleared instances did not all persist"; failed=1
            fi
            # On foot, into a trunk: the capsule stops at it.
            walked=$(grep -E '^rwt-smoke: walked into a trunk' "$out/$name.log" || true)
            echo "${walked:-FAIL $name: no walk line}"
            read -r closest contact < <(sed -nE 's/.*closest ([0-9.]+) m from its axis, collision at ([0-9.]+) m$/\1 \2/p' <<<"$walked")
            if [ -z "${closest:-}" ] || ! python3 -c "import sys; sys.exit(0 if $closest >= $contact - 0.05 and $closest < $contact + 1.0 else 1)"; then
                echo "FAIL $name: the walker did not stop at the trunk"; failed=1
            fi
        fi
        grep -E '^rwt-smoke: brush' "$out/$name.log" || true
        if ! grep -qE '^rwt-smoke: brush saved 4 maps, 2 layer files and [0-9]+ edits' "$out/$name.log"; then
            echo "FAIL $name: the brush did not save the painted maps and layer files"; failed=1
        fi
    fi
    if [ "$ex" = mesh_ground ]; then
        # Instances on the glTF level's surfaces, checked by vertical rays against its
        # meshes: none floating, none inside a solid, none on a slope its layer refuses.
        ground=$(grep -E '^rwt-smoke: ground instances' "$out/$name.log" || true)
        echo "${ground:-FAIL $name: no ground line}"
        read -r gi gs gf gb gw < <(sed -nE 's/^rwt-smoke: ground instances ([0-9]+) surfaces ([0-9]+) floating ([0-9]+) buried ([0-9]+) steep ([0-9]+)$/\1 \2 \3 \4 \5/p' <<<"$ground")
        if [ -z "${gi:-}" ] || [ "$gi" -eq 0 ] || [ "$gs" -lt 2 ] || [ "$gf" -ne 0 ] || [ "$gb" -ne 0 ] || [ "$gw" -ne 0 ]; then
            echo "FAIL $name: instances off the level's surfaces"; failed=1
        fi
    fi
    if [ "$ex" = stipple_zoom ]; then
        # Figure 1's story: the image at 1x, its shadowed edge at 30x and inside one texel
        # at 1000x, and no dot that was in view ever left while zooming in.
        grep -E '^rwt-smoke: zoom' "$out/$name.log" || true
        for shot in 1x 30x; do
            [ -s "$out/${name}_$shot.png" ] || { echo "FAIL $name: no $shot screenshot"; failed=1; }
        done
        if grep -E '^rwt-smoke: zoom' "$out/$name.log" | grep -vqE ', 0 left while in view$' \
            || [ "$(grep -cE '^rwt-smoke: zoom' "$out/$name.log")" -ne 3 ]; then
            echo "FAIL $name: dots in view left while zooming in"; failed=1
        fi
    fi
    if [ $docs = 1 ] && [ $failed = 0 ]; then
        mkdir -p docs/screenshots
        # The README's first pictures full size; the others at half.
        if [ "$ex" = open_world ] || [ "$ex" = mesh_ground ]; then
            cp "$png" "docs/screenshots/$name.png"
        else
            python3 scripts/png_stats.py "$png" --half "docs/screenshots/$name.png" >/dev/null
            for extra in "$out/${name}"_*x.png; do
                [ -s "$extra" ] || continue
                python3 scripts/png_stats.py "$extra" --half "docs/screenshots/$(basename "$extra")" >/dev/null
            done
        fi
    fi
done
exit $failed
