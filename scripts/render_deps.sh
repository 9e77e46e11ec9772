#!/usr/bin/env bash
# Installs what a headless real renderer needs (Xvfb and Mesa's lavapipe Vulkan driver),
# only when missing. Used by scripts/smoke.sh (and its --docs screenshots).
set -euo pipefail
need=()
command -v Xvfb >/dev/null || need+=(xvfb)
ls /usr/share/vulkan/icd.d/lvp_icd*.json >/dev/null 2>&1 || need+=(mesa-vulkan-drivers)
if [ ${#need[@]} -gt 0 ]; then
    sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    echo "installing ${need[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${need[@]}" xauth >/dev/null
fi
