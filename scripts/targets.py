#!/usr/bin/env python3
"""The speed targets of the frame and ray-casting issues, from `continuum compare` runs.

  scripts/targets.py RUN_DIR [RUN_DIR ...]

Each RUN_DIR holds the results.json of one run of the same command, e.g. three runs of

  continuum compare --scenes teapots,bunny,soup,DRAGON.glb,SPONZA.glb \\
      --size 1920x1080 --threads 2 --repeat 5 --out RUN_DIR

(built with `--features embree`, so that `peer-embree-stream` runs). Every ratio is taken
within one run and the median over the runs is printed; per scene and target, `ok` or
`MISS`. The targets (ratios of median times, one run at a time):

  fastest/es    the fastest CPU algorithm over peer-embree-stream        <= 0.5
  fastest/gpu   the same over gpu-raster                                 <= 0.5
  frame         (resolve + shading + store) / total, the largest share
                over the CPU algorithms                                  <= 0.15
  fig10         |measured / predicted ratio to 2dr-brute - 1|, the
                largest over the brute-force algorithms (paper Fig. 10)  <= 0.2
  obvhs/raycast peer-obvhs over raycast                                  >= 1.5
  full/es       3dr-full over peer-embree-stream        (>= 200k tris)   <= 1
  full/brute    3dr-full over 3dr-brute                 (>= 200k tris)   <  1
  B/tri         prepared-scene bytes per triangle       (>= 200k tris)   <= 150

Not here: the 1->2 thread speed-up (a `--threads 1,2` run: its rows' `speedup`) and the
occlusion-culling share (an `--oracles` run: the rows' node counters)."""
import json
import statistics
import sys
from pathlib import Path

LARGE = 200_000


def load(run_dir):
    rows = json.loads((Path(run_dir) / "results.json").read_text())["rows"]
    # The default cell of every scene: its first viewport, no AA, f32.
    rows = [r for r in rows if r["aa"] == "none" and r["precision"] == "f32" and "[" not in r["algorithm"]]
    by_scene = {}
    for r in rows:
        by_scene.setdefault(r["scene"], {}).setdefault(r["algorithm"], r)
    return by_scene


def is_cpu(algorithm):
    return not algorithm.startswith(("gpu-", "peer-"))


def frame_share(row):
    t = row.get("stage_ms") or {}
    total = t.get("total") or row["median_ms"]
    return (t.get("resolve", 0) + t.get("shading", 0) + t.get("store", 0)) / total


def measures(rows):
    """Every target's value on one scene of one run (None where a row is missing)."""
    ms = {a: r["median_ms"] for a, r in rows.items()}
    cpu = {a: t for a, t in ms.items() if is_cpu(a)}
    fastest = min(cpu, key=cpu.get)
    ratio = lambda a, b: ms[a] / ms[b] if a in ms and b in ms else None
    fig10 = [
        abs(r["ratio_to_2dr_brute"] / r["predicted_ratio"] - 1)
        for a, r in rows.items()
        if a.endswith("-brute") and is_cpu(a) and r.get("ratio_to_2dr_brute") and r.get("predicted_ratio")
    ]
    b_tri = [r["stats"].get("scene_bytes_per_triangle") for a, r in rows.items() if is_cpu(a)]
    b_tri = [b for b in b_tri if b]
    return fastest, {
        "fastest/es": ratio(fastest, "peer-embree-stream"),
        "fastest/gpu": ratio(fastest, "gpu-raster"),
        "frame": max(frame_share(rows[a]) for a in cpu),
        "fig10": max(fig10) if fig10 else None,
        "obvhs/raycast": ratio("peer-obvhs", "raycast"),
        "full/es": ratio("3dr-full", "peer-embree-stream"),
        "full/brute": ratio("3dr-full", "3dr-brute"),
        "B/tri": max(b_tri) if b_tri else None,
    }


TARGETS = {
    "fastest/es": (lambda v: v <= 0.5, False),
    "fastest/gpu": (lambda v: v <= 0.5, False),
    "frame": (lambda v: v <= 0.15, False),
    "fig10": (lambda v: v <= 0.2, False),
    "obvhs/raycast": (lambda v: v >= 1.5, False),
    "full/es": (lambda v: v <= 1.0, True),
    "full/brute": (lambda v: v < 1.0, True),
    "B/tri": (lambda v: v <= 150, True),
}


def main(dirs):
    if not dirs:
        sys.exit(__doc__)
    runs = [load(d) for d in dirs]
    scenes = [s for s in runs[0] if all(s in run for run in runs)]
    header = f"{'scene':<22} {'triangles':>9} {'fastest':<12}" + "".join(f" {name:>14}" for name in TARGETS)
    print(header)
    met = missed = 0
    for scene in scenes:
        per_run = [measures(run[scene]) for run in runs]
        names = [f for f, _ in per_run]
        fastest = max(set(names), key=names.count)
        triangles = next(iter(runs[0][scene].values())).get("scene_triangles", 0)
        cells = []
        for name, (ok, large_only) in TARGETS.items():
            values = [m[name] for _, m in per_run if m[name] is not None]
            if not values:
                cells.append("-")
                continue
            v = statistics.median(values)
            # Scenes written before `scene_triangles` was recorded: every target applies.
            if large_only and 0 < triangles < LARGE:
                cells.append(f"{v:.2f}")
                continue
            good = ok(v)
            met, missed = met + good, missed + (not good)
            cells.append(f"{v:.2f} {'ok' if good else 'MISS'}")
        print(f"{Path(scene).stem[:22]:<22} {triangles:>9} {fastest:<12}" + "".join(f" {c:>14}" for c in cells))
    print(f"\n{met} targets met, {missed} missed; medians of {len(runs)} runs")


if __name__ == "__main__":
    main(sys.argv[1:])
