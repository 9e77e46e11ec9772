#!/usr/bin/env bash
# Builds the `web` example for the browser, once for WebGL2 and once for WebGPU, and writes a
# static site into target/web: index.html, webgl2/ and webgpu/ (each the wasm-bindgen JS and
# the .wasm, shrunk by wasm-opt), and assets/ (the asset pack, written natively first:
# a page has no files to write). Prints each module's size. Serve target/web over HTTP
# (`scripts/web_test.sh` does, and tests it in headless Chromium).
#
# Toolchain: rustup's where its wasm32 target is installed (`rustup target add
# wasm32-unknown-unknown`); otherwise Debian's rustc-web with the standard library's sources
# (rust-web-src), built with `-Zbuild-std` and linked by wasm-ld (lld-22), installed here when
# missing. wasm-bindgen-cli comes from crates.io at the lockfile's version, wasm-opt from
# binaryen 116 or newer (on PATH, else npm's; without either the module is not shrunk).
#
#   scripts/web.sh                   # both backends
#   scripts/web.sh webgl2            # one
#   RWT_WEB_OPT=0 scripts/web.sh     # without wasm-opt (faster; the module twice as large)
set -euo pipefail
cd "$(dirname "$0")/.."
backends=(webgl2 webgpu)
[ $# -gt 0 ] && backends=("$@")
site=target/web
tools=target/web-tools
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"

apt_install() {
    local need=()
    for p in "$@"; do dpkg -s "$p" >/dev/null 2>&1 || need+=("$p"); done
    [ ${#need[@]} -eq 0 ] && return
    echo "installing ${need[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
}

# The wasm32 toolchain: `cargo_wasm ARGS...` builds for wasm32-unknown-unknown (its own
# RUSTFLAGS: set for native builds too, they would rebuild those from scratch).
wasm_flags="${RUSTFLAGS:-} --cfg getrandom_backend=\"wasm_js\""
if rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
    cargo_wasm() { RUSTFLAGS="$wasm_flags" cargo build --target wasm32-unknown-unknown "$@"; }
else
    apt_install rustc-web cargo-web rust-web-src lld-22
    # Debian's cargo and rustc (beside rustup's, which stay first on PATH) build the standard
    # library from its sources; its own dependencies come from crates.io.
    cargo_wasm() {
        RUSTFLAGS="$wasm_flags" RUSTC=/usr/bin/rustc RUSTDOC=/usr/bin/rustdoc RUSTC_BOOTSTRAP=1 \
            CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER=wasm-ld-22 \
            /usr/bin/cargo build -Zbuild-std=std,panic_abort --target wasm32-unknown-unknown "$@"
    }
fi

# wasm-bindgen's CLI must be the version of the wasm-bindgen crate the module links.
bindgen_version=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/version = |"/, ""); print}' Cargo.lock)
if [ "$("$tools/bin/wasm-bindgen" --version 2>/dev/null | awk '{print $2}')" != "$bindgen_version" ]; then
    echo "installing wasm-bindgen-cli $bindgen_version"
    cargo install -q wasm-bindgen-cli --version "$bindgen_version" --root "$tools"
fi
# wasm-opt from binaryen 116 or newer: older ones (Debian 12's 108) give wasm-bindgen's
# function table a type its JS cannot fill. npm's binaryen otherwise, else none.
wasm_opt=""
if [ "${RWT_WEB_OPT:-1}" = 0 ]; then
    echo "rwt-web-build: not shrinking the modules (RWT_WEB_OPT=0)"
elif [ "$(wasm-opt --version 2>/dev/null | grep -o '[0-9]\+' | head -1)" -ge 116 ] 2>/dev/null; then
    wasm_opt=wasm-opt
elif command -v npm >/dev/null; then
    [ -x "$tools/node/node_modules/.bin/wasm-opt" ] ||
        npm install -s --prefix "$tools/node" --no-audit --no-fund binaryen@132 >/dev/null
    wasm_opt="$tools/node/node_modules/.bin/wasm-opt"
fi

# The asset pack, written natively (the page loads it over HTTP).
cargo run -q --example pack

rm -rf "$site"
mkdir -p "$site/assets/generated"
cp examples/web/index.html "$site/"
cp -r assets/generated/pack "$site/assets/generated/"
for backend in "${backends[@]}"; do
    t0=$(date +%s)
    cargo_wasm --profile web --example web --no-default-features --features "$backend" \
        --target-dir target/web-build
    wasm=target/web-build/wasm32-unknown-unknown/web/examples/web.wasm
    "$tools/bin/wasm-bindgen" --target web --no-typescript --out-dir "$site/$backend" \
        --out-name rwt_web "$wasm"
    module="$site/$backend/rwt_web_bg.wasm"
    if [ -n "$wasm_opt" ]; then
        "$wasm_opt" -Os "$module" -o "$module.opt" && mv "$module.opt" "$module"
    fi
    echo "rwt-web-build: $backend $(stat -c %s "$module") bytes ($(( $(stat -c %s "$module") / 1048576 )) MiB, $(gzip -9c "$module" | wc -c) gzipped) in $(( $(date +%s) - t0 )) s"
done
echo "rwt-web-build: site in $site"
