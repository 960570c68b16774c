#!/usr/bin/env python3
"""Instructions and mispredicted branches of one frame, counted by valgrind's callgrind:
a deterministic before/after measure where timings drown in a shared machine's noise.

  scripts/instructions.py SCENE ALGORITHM LABEL=BINARY ... [--blocks N] [-- FUNCTION]

Runs `BINARY compare --scenes SCENE --algorithms ALGORITHM --size 1920x1080 --threads 1
--repeat 1` under callgrind (its conditional-branch model on), all binaries side by side,
counting only inside FUNCTION and what it calls (default `continuum::render::render_cancellable`:
the warm-up frame and the timed one, scene loading left out; a kernel's name such as
`continuum::binning::test_samples::on_avx2` narrows it). Prints per binary the instructions
(Ir), conditional branches (Bc) and those the model mispredicts (Bcm). The model is a simple
two-bit predictor, not the CPU's: read its counts as where branches are unpredictable, and
confirm a change with alternated timings (scripts/ab.py). Needs valgrind (Debian: valgrind);
each binary takes about a minute on the dragon.

--blocks N also prints, per binary, the N runs of straight-line code that cost the most
instructions: consecutive instructions executed equally often, with how often (for a shading
block, the number of eights through it), how many instructions, and the mispredicted branches
in them; name an address with `addr2line -i -f -C -e BINARY ADDRESS` or read it with
`objdump -d --start-address=ADDRESS BINARY`. It found a per-eight memcpy and an 800-
instruction background fill in the shading."""
import subprocess
import sys
import tempfile
from pathlib import Path


def main(args):
    function = "continuum::render::render_cancellable"
    blocks = 0
    if "--blocks" in args:
        at = args.index("--blocks")
        if at + 1 >= len(args) or not args[at + 1].isdigit():
            sys.exit("--blocks takes a count\n\n" + __doc__)
        blocks = int(args[at + 1])
        args = args[:at] + args[at + 2:]
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
            detail = ["--dump-instr=yes", "--compress-pos=no", "--compress-strings=no"] if blocks else []
            command = ["valgrind", "--tool=callgrind", "--branch-sim=yes", "--collect-atstart=no", *detail,
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
            for run in heaviest_runs(out, blocks):
                print("   ", run)


def read_totals(path):
    """The `events:` and `summary:` lines of a callgrind output file, as a dict."""
    events, summary = [], []
    for line in path.read_text().splitlines():
        if line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("summary:") or line.startswith("totals:"):
            summary = [int(v) for v in line.split()[1:]]
    return dict(zip(events, summary)) | {k: 0 for k in ("Ir", "Bc", "Bcm") if k not in events}


def heaviest_runs(path, n):
    """The `n` costliest runs of consecutive instructions executed equally often, from a
    callgrind file written with --dump-instr=yes --compress-pos=no --compress-strings=no."""
    if n == 0:
        return []
    events, positions, fn, after_call = [], 1, None, False
    cost = {}  # (function, address) -> [Ir, Bcm]
    for line in path.read_text().splitlines():
        if line.startswith("positions:"):
            positions = len(line.split()[1:])  # `instr line`: the address, then the source line
        elif line.startswith("events:"):
            events = line.split()[1:]
        elif line.startswith("fn="):
            fn = line[3:].strip()
        elif line.startswith("calls="):
            after_call = True  # the next cost line is the call's inclusive cost
        elif line.startswith("0x"):
            if after_call:
                after_call = False
                continue
            fields = line.split()
            values = dict(zip(events, (int(v) for v in fields[positions:])))
            c = cost.setdefault((fn, int(fields[0], 16)), [0, 0])
            c[0] += values.get("Ir", 0)
            c[1] += values.get("Bcm", 0)
    runs = []  # [function, first, last, times, instructions, Bcm]
    for (fn, address), (ir, bcm) in sorted(cost.items()):
        last = runs[-1] if runs else None
        # x86 instructions are at most 15 bytes long: a gap of 16 or more is not the next one.
        if last and last[0] == fn and last[3] == ir and address - last[2] < 16:
            last[2], last[4], last[5] = address, last[4] + 1, last[5] + bcm
        else:
            runs.append([fn, address, address, ir, 1, bcm])
    runs.sort(key=lambda r: -r[3] * r[4])
    return [f"{r[3] * r[4]:>13,} Ir  {r[3]:>10,}x {r[4]:>4} instructions  Bcm {r[5]:>9,}  "
            f"{hex(r[1])}-{hex(r[2])}  {r[0][:90]}" for r in runs[:n]]


if __name__ == "__main__":
    main(sys.argv[1:])
