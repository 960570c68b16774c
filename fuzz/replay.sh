#!/usr/bin/env bash
# The fuzz targets built on stable Rust and their seed corpora replayed: each
# target is libFuzzer's driver around the loader (without coverage
# instrumentation, which needs the nightly flags `cargo fuzz` passes), run
# once over every seed file. A seed that crashes a loader or the renders after
# it fails this script. CI runs it; fuzzing itself: README.md here.
set -euo pipefail
cd "$(dirname "$0")"
cargo build --locked --bins
bin="${CARGO_TARGET_DIR:-target}/debug"
"$bin/gltf" ../scenes/assets/*.glb
"$bin/obj" seeds/obj/*
"$bin/scene_toml" seeds/toml/* ../scenes/*.toml
echo "fuzz: every seed of gltf, obj and scene_toml replayed"
