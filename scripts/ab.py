#!/usr/bin/env python3
"""Two or more `continuum` binaries timed in alternated rounds, for before/after comparisons
on a noisy machine.

  scripts/ab.py SCENES ALGORITHMS ROUNDS LABEL=BINARY LABEL=BINARY ... [-- COMPARE_FLAGS]

Each round runs `BINARY compare --scenes SCENES --algorithms ALGORITHMS --size 1920x1080
--threads 2 --repeat 5 COMPARE_FLAGS` once per binary, in turn (each round starting with
the next binary), so that a machine that slows down slows every binary alike. Prints per scene, algorithm and binary the median
over the rounds of each row's median time, with its stages: setup (s), traversal +
coverage (t) and resolve + shading + store (f), in ms; and names every row whose hashes
differ between the binaries (a speed change keeps every image)."""
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path


def main(args):
    extra = []
    if "--" in args:
        at = args.index("--")
        args, extra = args[:at], args[at + 1:]
    if len(args) < 5:
        sys.exit(__doc__)
    scenes, algorithms, rounds = args[0], args[1], int(args[2])
    binaries = [a.split("=", 1) for a in args[3:]]
    flags = ["--size", "1920x1080", "--threads", "2", "--repeat", "5", *extra]
    times, hashes = {}, {}
    for round_ in range(rounds):
        # Each round starts with the next binary: whichever runs first in a
        # round (after the machine was idle, or after another program) is
        # not always the same one.
        shift = round_ % len(binaries)
        for label, binary in binaries[shift:] + binaries[:shift]:
            with tempfile.TemporaryDirectory() as out:
                command = [binary, "compare", "--scenes", scenes, "--algorithms", algorithms, *flags, "--out", out]
                subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                rows = json.loads((Path(out) / "results.json").read_text())["rows"]
            for r in rows:
                key = (Path(r["scene"]).stem, r["algorithm"])
                t = r.get("stage_ms") or {}
                stages = (
                    t.get("setup", 0),
                    t.get("traversal", 0) + t.get("coverage", 0),
                    t.get("resolve", 0) + t.get("shading", 0) + t.get("store", 0),
                )
                times.setdefault(key + (label,), []).append((r["median_ms"], *stages))
                hashes.setdefault(key, {})[label] = json.dumps(r.get("hashes"), sort_keys=True)
    for (scene, algorithm, label), v in sorted(times.items()):
        total, s, t, f = (statistics.median(x[i] for x in v) for i in range(4))
        print(f"{scene:<24} {algorithm:<20} {label:<10} {total:8.2f}  s {s:6.2f}  t {t:6.2f}  f {f:6.2f}")
    differ = [key for key, by_label in hashes.items() if len(set(by_label.values())) > 1]
    for scene, algorithm in differ:
        print(f"HASHES DIFFER: {scene} {algorithm}")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main(sys.argv[1:])
