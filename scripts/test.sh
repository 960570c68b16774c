#!/usr/bin/env bash
# Every test of the workspace, on a fresh machine too: installs what the tests
# need when it is missing, then runs `cargo test --workspace` (extra arguments
# go to cargo test, e.g. `scripts/test.sh -p continuum-core`).
#
# What the tests need beyond the Rust toolchain (Debian package names):
#   Vulkan on the CPU (Mesa's lavapipe)  mesa-vulkan-drivers libvulkan1 vulkan-tools
#   the web page's browser test          chromium chromium-driver
#   the viewer's real window             xvfb xauth and the X11 client libraries
#   C/C++ for -sys crates (FLIP)         build-essential pkg-config
# They are installed with apt-get as root, or through sudo when it needs no
# password; otherwise the script names the missing packages and stops.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential pkg-config ca-certificates
          mesa-vulkan-drivers libvulkan1 vulkan-tools
          chromium chromium-driver
          xvfb xauth libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0)

# 1. System packages.
if command -v dpkg-query >/dev/null; then
    missing=()
    for p in "${packages[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        if [ "$(id -u)" -eq 0 ]; then
            sudo=()
        elif command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
            sudo=(sudo)
        else
            echo "error: missing Debian packages: ${missing[*]}" >&2
            echo "install them (as root): apt-get update && apt-get install -y ${missing[*]}" >&2
            exit 1
        fi
        echo "== installing ${missing[*]}"
        "${sudo[@]}" apt-get update -qq
        "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
    fi
else
    echo "warning: not a Debian system; the tests need: ${packages[*]} (or your system's equivalents)" >&2
fi

# 2. A private runtime folder for Mesa (it complains on every device it opens without one).
if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
    XDG_RUNTIME_DIR="$(mktemp -d)"
    export XDG_RUNTIME_DIR
fi
chmod 0700 "$XDG_RUNTIME_DIR" 2>/dev/null || true

# 3. An X server for the viewer's real window when there is no display. Xvfb picks a free display
# itself and writes its number to fd 3 only once it accepts clients (-displayfd), so nothing here
# races its start.
xvfb_pid=""
cleanup() { [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null || true; }
trap cleanup EXIT
if [ -z "${DISPLAY:-}" ]; then
    displayfile="$(mktemp)"
    Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>"$displayfile" >/dev/null 2>&1 &
    xvfb_pid=$!
    for _ in $(seq 200); do [ -s "$displayfile" ] && break; sleep 0.1; done
    n="$(tr -dc 0-9 <"$displayfile")"
    rm -f "$displayfile"
    [ -n "$n" ] || { echo "error: Xvfb did not start" >&2; exit 1; }
    export DISPLAY=":$n"
fi

# 4. Vulkan must be there: the GPU tests fail loudly without it, and this says why first.
# vulkaninfo runs without DISPLAY (only devices are asked for, not window surfaces) and its output
# is read whole before grep (`grep -q` quitting early would SIGPIPE it and fail the pipe).
vulkan="$(env -u DISPLAY vulkaninfo --summary 2>&1 || true)"
if ! grep -qE "deviceName" <<<"$vulkan"; then
    echo "error: no Vulkan device (Debian: mesa-vulkan-drivers libvulkan1); vulkaninfo said:" >&2
    tail -n 20 <<<"$vulkan" >&2
    exit 1
fi

# 5. The tests.
cargo test --workspace "$@"
