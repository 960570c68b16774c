#!/usr/bin/env bash
# Makes the two base images docker/Dockerfile names, on a machine where no
# image registry is reachable (the Debian mirror and crates.io are):
#   RUNTIME_IMAGE (default debian:bookworm-slim): debootstrap's minimal bookworm;
#   RUST_IMAGE (default rust:1.95-bookworm): that, with build tools, this
#     machine's Rust toolchain (the same release as the official image) in
#     /usr/local/rust, and this machine's extra CA certificates
#     (/usr/local/share/ca-certificates: a TLS-inspecting proxy's, say), so
#     cargo reaches crates.io from inside a build as it does outside.
# Where a registry is reachable, skip this: the defaults are the official images.
# The debootstrap tarball is cached in $CONTINUUM_DOCKER_CACHE (default
# ~/.cache/continuum-docker); an image that exists is left alone.
set -euo pipefail

RUNTIME_IMAGE="${RUNTIME_IMAGE:-debian:bookworm-slim}"
RUST_IMAGE="${RUST_IMAGE:-rust:1.95-bookworm}"
MIRROR="${DEBIAN_MIRROR:-http://deb.debian.org/debian}"
CACHE="${CONTINUUM_DOCKER_CACHE:-$HOME/.cache/continuum-docker}"
mkdir -p "$CACHE"

have() { docker image inspect "$1" >/dev/null 2>&1; }

if ! have "$RUNTIME_IMAGE"; then
    tarball="$CACHE/bookworm-minbase.tar"
    if [ ! -f "$tarball" ]; then
        echo "bootstrap: debootstrap bookworm (minbase) from $MIRROR"
        rootfs="$(mktemp -d)"
        trap 'rm -rf "$rootfs"' EXIT
        debootstrap --variant=minbase bookworm "$rootfs" "$MIRROR" >/dev/null
        rm -rf "$rootfs"/var/cache/apt/archives/*.deb "$rootfs"/var/lib/apt/lists/*
        tar -C "$rootfs" -cf "$tarball.tmp" . && mv "$tarball.tmp" "$tarball"
        rm -rf "$rootfs"
        trap - EXIT
    fi
    echo "bootstrap: importing $RUNTIME_IMAGE"
    docker import --change 'CMD ["/bin/bash"]' "$tarball" "$RUNTIME_IMAGE" >/dev/null
fi

if ! have "$RUST_IMAGE"; then
    sysroot="$(rustc --print sysroot)"
    echo "bootstrap: $RUST_IMAGE from $RUNTIME_IMAGE and $("$sysroot/bin/rustc" --version)"
    context="$(mktemp -d)"
    trap 'rm -rf "$context"' EXIT
    mkdir -p "$context/rust"
    # The toolchain without its documentation.
    for part in bin lib libexec etc; do
        if [ -e "$sysroot/$part" ]; then cp -a "$sysroot/$part" "$context/rust/"; fi
    done
    mkdir -p "$context/ca"
    cp /usr/local/share/ca-certificates/*.crt "$context/ca/" 2>/dev/null || true
    cat > "$context/Dockerfile" <<DOCKERFILE
FROM $RUNTIME_IMAGE
RUN apt-get update \\
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends build-essential pkg-config ca-certificates \\
 && rm -rf /var/lib/apt/lists/*
COPY rust /usr/local/rust
COPY ca /usr/local/share/ca-certificates
RUN update-ca-certificates >/dev/null
ENV PATH=/usr/local/rust/bin:/usr/local/cargo/bin:/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \\
    CARGO_HOME=/usr/local/cargo
RUN rustc --version && cargo --version
DOCKERFILE
    docker build -q -t "$RUST_IMAGE" "$context" >/dev/null
    rm -rf "$context"
    trap - EXIT
fi
echo "bootstrap: $RUNTIME_IMAGE and $RUST_IMAGE ready"
