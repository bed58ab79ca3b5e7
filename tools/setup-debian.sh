#!/usr/bin/env bash
# Installs the Debian packages vkhair needs, only those that are missing:
# lavapipe (mesa-vulkan-drivers), the Vulkan loader, the validation layers,
# Debian's static shaderc/glslang/SPIRV-Tools libraries (libshaderc-dev;
# build.rs links them instead of building shaderc from source), spirv-val, and
# the DejaVu font `vkhair plot` labels its charts with, and for the windowed
# viewer (examples/viewer, tests/viewer.rs) a virtual X server and the X11
# libraries winit loads at run time.
set -euo pipefail

packages=(mesa-vulkan-drivers libvulkan1 vulkan-validationlayers libshaderc-dev glslc spirv-tools fonts-dejavu-core xvfb libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6)
missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done

if ((${#missing[@]})); then
    echo "setup: installing ${missing[*]}"
    sudo=""
    if [ "$(id -u)" != 0 ]; then
        sudo="sudo"
    fi
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if ! command -v cargo >/dev/null 2>&1; then
    echo "setup: cargo not found; install a Rust toolchain (1.87 or newer) with rustup first" >&2
    exit 1
fi
