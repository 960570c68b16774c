#!/usr/bin/env bash
# Every image hash and counter of every built-in scene (its first camera) under every
# viewport, anti-aliasing family and precision, as one sorted JSON line per render:
# run it before and after a refactor or a speed change and diff the two outputs.
#   scripts/hash-matrix.sh [CONTINUUM_BINARY] > hashes.jsonl
# (default binary: target/release/continuum). Every algorithm by default, the GPU's on
# lavapipe taking far the longest; ALGORITHMS=cpu keeps to the CPU's (about a minute on two
# cores), or name them: ALGORITHMS=3dr-full,raycast.
set -euo pipefail
bin="${1:-${CARGO_TARGET_DIR:-target}/release/continuum}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
algorithms=()
case "${ALGORITHMS:-}" in
    "") ;;
    cpu) algorithms=(--algorithms 2dr-brute,2dr-bin,2dr-scanline,2dr-homogeneous,3dr-brute,3dr-bin,3dr-frustum-cull,3dr-frustum-split,3dr-full,raycast) ;;
    *) algorithms=(--algorithms "$ALGORITHMS") ;;
esac
"$bin" compare "${algorithms[@]}" --size 64x48 --repeat 1 --threads 2 \
    --viewports camera,orthographic,parabolic,latlong \
    --aa none,msaa:4,csaa:8x2,ssaa:4 --precision f32,f64,fixed \
    --out "$out" >/dev/null
python3 - "$out/results.json" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1]))["rows"]
keep = ("hashes", "coverage_samples", "shading_samples")
counters = ("edge_evaluations", "triangle_setups", "bvh_nodes_visited", "early_z_rejects",
            "tiles_tested", "nodes_culled_outside", "nodes_culled_occluded", "frusta_split",
            "coverage_histogram", "edge_tests_f64", "edge_tests_exact", "effects")
lines = []
for r in rows:
    if r["algorithm"].startswith("peer-") or r["algorithm"] == "gpu-raster":
        continue
    d = {k: r[k] for k in ("scene", "camera", "algorithm", "viewport", "aa", "precision") + keep}
    d["counters"] = {k: r["stats"][k] for k in counters}
    for e in d["counters"]["effects"]:
        e.pop("worker_ms", None)  # a time, not a count
    lines.append(json.dumps(d, sort_keys=True))
for line in sorted(lines):
    print(line)
print(f"{len(lines)} renders", file=sys.stderr)
PY
