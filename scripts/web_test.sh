#!/usr/bin/env bash
# The browser test: serves the site `scripts/web.sh` builds (target/web; built first when
# missing) on 127.0.0.1 and drives headless Chromium through it, once with WebGL2 and once
# with WebGPU (`scripts/web_test.mjs`, Playwright). Each page must log
# `rwt-web: backend=B instances=N frames=F frame_ms=T` with N > 0, no console error and no
# panic; its screenshot (target/web-test/B.png) must not be blank (luminance variance >= 20).
# Installs Debian's chromium and npm's playwright-core when missing.
#
#   scripts/web_test.sh              # both backends
#   scripts/web_test.sh webgpu       # one
set -euo pipefail
cd "$(dirname "$0")/.."
backends=(webgl2 webgpu)
[ $# -gt 0 ] && backends=("$@")
[ -f target/web/index.html ] || scripts/web.sh
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
if ! command -v chromium >/dev/null; then
    echo "installing chromium"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium >/dev/null
fi
node_dir=target/web-tools/node
if [ ! -d "$node_dir/node_modules/playwright-core" ]; then
    echo "installing playwright-core"
    mkdir -p "$node_dir"
    npm install -s --prefix "$node_dir" --no-audit --no-fund playwright-core@1.64 >/dev/null
fi
out=target/web-test
rm -rf "$out" && mkdir -p "$out"
cp scripts/web_test.mjs "$node_dir/"
node "$node_dir/web_test.mjs" target/web "$out" "${backends[@]}"
for backend in "${backends[@]}"; do
    read -r w h variance < <(python3 scripts/png_stats.py "$out/$backend.png")
    echo "rwt-web-test: $backend screenshot ${w}x${h} variance $variance"
    python3 -c "import sys; sys.exit(0 if float('$variance') >= 20 else 1)" \
        || { echo "rwt-web-test: $backend screenshot is blank"; exit 1; }
done
