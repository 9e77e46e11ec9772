#!/usr/bin/env bash
# The GPU benchmark (examples/gpu_bench/main.rs): open_world-like grass rendered headless at 1, 5
# and 10 M live blades, shadows off and on, one line per case:
#   gpu-bench: blades=B shadows=S cull=C fps_median=F frame_ms_p95=P adapter=NAME
#
#   scripts/gpu_bench.sh build        build the release binary, stripped and compressed, into
#                                     target/gpu-bench/gpu_bench.xz (any machine: no GPU needed)
#   scripts/gpu_bench.sh run [ARGS]   run it (a Linux x86-64 machine with a GPU, its driver and
#                                     the Vulkan loader; no network, no display); ARGS go to the
#                                     example (--blades 1,5,10 --frames 240 --size 1920x1080
#                                     --msaa 1|2|4 --tuft K --shadows on|off --cull on|off
#                                     --casters read|all --forest thinned|impostors
#                                     --latency 0..3 ...)
#   scripts/gpu_bench.sh split [ARGS] the 10 M case as open_world draws its grass (shadows
#                                     within 25 m, far blade from 30 m, culled, shadows on,
#                                     --detail) five times: as is, with --latency 0 (each
#                                     frame waits for its own drawing: CPU and GPU times
#                                     add up), with --msaa 1 (the pixels' share), with
#                                     --tuft 8 (a cost per instance) and with --casters all
#                                     (every blade in a cascade's box drawn into it); about
#                                     6 minutes
#
# Built once, target/gpu-bench/ (about 20 MB) is all the run needs beside the driver: copy
# it (or the working tree with it) to the GPU machine. The run stops after 470 s, inside 8
# minutes.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=target/gpu-bench

case "${1:-run}" in
build)
    cargo build --release --example gpu_bench
    rm -rf "$dir"
    mkdir -p "$dir"
    strip -o "$dir/gpu_bench" target/release/examples/gpu_bench
    xz -T0 -6 "$dir/gpu_bench"
    echo "gpu_bench: $(du -h "$dir/gpu_bench.xz" | cut -f1) in $dir; take that folder to the GPU machine"
    ;;
run)
    shift || true
    if [ ! -f "$dir/gpu_bench.xz" ]; then
        echo "gpu_bench: no $dir/gpu_bench.xz: run 'scripts/gpu_bench.sh build' first" >&2
        exit 1
    fi
    bin=$(mktemp -d)/gpu_bench
    if command -v xz >/dev/null; then
        xz -dc "$dir/gpu_bench.xz" >"$bin"
    else
        python3 -c 'import lzma, shutil, sys; shutil.copyfileobj(lzma.open(sys.argv[1]), open(sys.argv[2], "wb"))' "$dir/gpu_bench.xz" "$bin"
    fi
    chmod +x "$bin"
    # (No `grep -q`: it would stop reading early, and pipefail would fail the pipe.)
    if ! ldconfig -p | grep 'libvulkan\.so\.1' >/dev/null; then
        echo "gpu_bench: the Vulkan loader (libvulkan.so.1) is not installed: install libvulkan1" >&2
        exit 1
    fi
    # A driver installed outside the loader's search path (some containers mount NVIDIA's
    # under /usr/local/nvidia).
    nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    if [ -z "${VK_DRIVER_FILES:-}" ] && [ -f $nvidia_icd ] &&
        ! ls /usr/share/vulkan/icd.d/nvidia_icd*.json /etc/vulkan/icd.d/nvidia_icd*.json >/dev/null 2>&1; then
        export VK_DRIVER_FILES=$nvidia_icd
    fi
    export WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
    # No display: nothing in the bench opens a window.
    unset DISPLAY WAYLAND_DISPLAY
    if command -v nvidia-smi >/dev/null; then
        nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader || true
    fi
    exec timeout 470 "$bin" "$@"
    ;;
split)
    shift || true
    case_args=(--blades 10 --frames 120 --shadow-distance 25 --far-blade 30 --detail
        --shadows on --cull on)
    for variant in "" "--latency 0" "--msaa 1" "--tuft 8" "--casters all"; do
        echo "gpu-bench-split: ${variant:-as open_world draws it}"
        # shellcheck disable=SC2086 # the variant is two words or none
        "$0" run "${case_args[@]}" $variant "$@" || echo "gpu-bench-split: failed ($?)"
    done
    ;;
*)
    echo "usage: scripts/gpu_bench.sh build | run [--blades M,M,..] [--frames N] [--size WxH] | split" >&2
    exit 2
    ;;
esac
