#!/usr/bin/env python3
"""Instructions and mispredicted branches of one frame, counted by valgrind's callgrind:
a deterministic before/after measure where timings drown in a shared machine's noise.

  scripts/instructions.py SCENE ALGORITHM LABEL=BINARY ... [-- FUNCTION]

Runs `BINARY compare --scenes SCENE --algorithms ALGORITHM --size 1920x1080 --threads 1
--repeat 1` under callgrind (its conditional-branch model on), all binaries side by side,
counting only inside FUNCTION and what it calls (default `continuum::render::render_cancellable`:
the warm-up frame and the timed one, scene loading left out; a kernel's name such as
`continuum::binning::test_samples::on_avx2` narrows it). Prints per binary the instructions
(Ir), conditional branches (Bc) and those the model mispredicts (Bcm). The model is a simple
two-bit predictor, not the CPU's: read its counts as where branches are unpredictable, and
confirm a change with alternated timings (scripts/ab.py). Needs valgrind (Debian: valgrind);
each binary takes about a minute on the dragon."""
import subprocess
import sys
import tempfile
from pathlib import Path


def main(args):
    function = "continuum::render::render_cancellable"
    if "--" in args:
        at = args.index("--")
        args, rest = args[:at], args[at + 1:]
        if len(rest) != 1:
            sys.exit(__doc__)
        function = rest[0]
    if len(args) < 3:
        sys.exit(__doc__)
    scene, algorithm = args[0], args[1]
    binaries = [a.split("=", 1) for a in args[2:]]
    if any(len(b) != 2 for b in binaries):
        sys.exit("each binary is LABEL=PATH\n\n" + __doc__)
    with tempfile.TemporaryDirectory() as work:
        runs = []
        for label, binary in binaries:
            out = Path(work) / f"{label}.callgrind"
            command = ["valgrind", "--tool=callgrind", "--branch-sim=yes", "--collect-atstart=no",
                       f"--toggle-collect={function}", f"--callgrind-out-file={out}",
                       binary, "compare", "--scenes", scene, "--algorithms", algorithm,
                       "--size", "1920x1080", "--threads", "1", "--repeat", "1",
                       "--out", str(Path(work) / label)]
            runs.append((label, out, subprocess.Popen(command, stdout=subprocess.DEVNULL,
                                                      stderr=subprocess.PIPE, text=True)))
        for label, out, run in runs:
            _, err = run.communicate()
            if run.returncode != 0:
                sys.exit(f"{label}: callgrind failed:\n{err[-2000:]}")
            totals = read_totals(out)
            if totals["Ir"] == 0:
                sys.exit(f"{label}: nothing counted: is '{function}' a function of the binary?")
            print(f"{label:<12} Ir {totals['Ir']:>15,}  Bc {totals['Bc']:>13,}  Bcm {totals['Bcm']:>11,}")


def read_totals(path):
    """The `events:` and `summary:` lines of a callgrind output file, as a dict."""
    events, summary = [], []
    for line in path.read_text().splitlines():
        if line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("summary:") or line.startswith("totals:"):
            summary = [int(v) for v in line.split()[1:]]
    return dict(zip(events, summary)) | {k: 0 for k in ("Ir", "Bc", "Bcm") if k not in events}


if __name__ == "__main__":
    main(sys.argv[1:])
