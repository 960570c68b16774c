#!/usr/bin/env python3
"""Module floors and cycles of the workspace's crates (CI runs it; exit 1 on a finding).

  scripts/floors.py [CRATE_SRC_DIR ...]   (default: every crate of the workspace)

For every crate: the graph of its modules, an edge for each `crate::a::b` path and
`use super::x` in non-test code and doc comments (`#[cfg(test)]` items left out), and
every cycle in it. For a crate whose lib.rs says `// floors:` (core), also the
floor rule: a top-level module may import only modules declared before it in
lib.rs, so lib.rs's order is the order of the floors."""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CRATES = ["core/src", "hardcases/src", "server/src", "viewer/src", "tests/src"]


def strip(text):
    """Non-test code without plain comments. Doc comments stay: an intra-doc
    link to a module above is a reference up the floors too (string contents
    are kept as well; paths in strings are rare and would only add edges)."""
    text = re.sub(r"//(?![/!])[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    # Drop each `#[cfg(test)]` item: the attribute, then up to its matching brace.
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]", text):
        if m.start() < i:
            continue
        out.append(text[i:m.start()])
        j = text.find("{", m.end())
        semi = text.find(";", m.end())
        if j < 0 or (0 <= semi < j):
            i = semi + 1
            continue
        depth = 0
        for k in range(j, len(text)):
            depth += {"{": 1, "}": -1}.get(text[k], 0)
            if depth == 0:
                i = k + 1
                break
        else:
            i = len(text)
    out.append(text[i:])
    return "".join(out)


def modname(src, p):
    parts = list(p.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return "::".join(parts) or "crate"


def graph(src):
    mods = {modname(src, p): p for p in src.rglob("*.rs")}
    names = set(mods)

    def resolve(path):
        segs = path.split("::")
        for k in range(len(segs), 0, -1):
            cand = "::".join(segs[:k])
            if cand in names:
                return cand
        return None

    edges = set()
    for m, p in mods.items():
        text = strip(p.read_text(errors="replace"))
        targets = []
        for u in re.findall(r"(?<![$\w])crate::([A-Za-z0-9_:]+(?:::\{[^}]*\})?)", text):
            base = u.split("::{")[0]
            if "::{" in u:
                inner = u.split("::{", 1)[1].rstrip("}")
                targets += [base + "::" + x.strip().split(" ")[0] for x in inner.split(",") if x.strip()]
            else:
                targets.append(base)
        parent = m.rsplit("::", 1)[0] if "::" in m else ""
        for sub in re.findall(r"\bsuper::([A-Za-z0-9_]+)", text):
            targets.append(f"{parent}::{sub}" if parent else sub)
        for t in targets:
            r = resolve(t.replace("::self", ""))
            if r and r != m and not m.startswith(r + "::") and not r.startswith(m + "::"):
                edges.add((m, r))
    return names, edges


def cycles(names, edges):
    adj = {m: sorted(b for a, b in edges if a == m) for m in names}
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in adj[v]:
            if w not in index:
                strong(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    for v in sorted(names):
        if v not in index:
            strong(v)
    return comps


def floor_order(src):
    lib = src / "lib.rs"
    if not lib.exists():
        return None
    text = lib.read_text()
    if "// floors:" not in text:
        return None
    return re.findall(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+([a-z0-9_]+)\s*;", text, re.M)


def main():
    dirs = [Path(a) for a in sys.argv[1:]] or [ROOT / c for c in CRATES]
    failures = 0
    for src in dirs:
        names, edges = graph(src)
        for comp in cycles(names, edges):
            inner = sorted(f"{a} -> {b}" for a, b in edges if a in comp and b in comp)
            print(f"{src}: module cycle: {', '.join(comp)}\n    " + "\n    ".join(inner))
            failures += 1
        order = floor_order(src)
        if order is None:
            continue
        rank = {m: i for i, m in enumerate(order)}
        top = lambda m: m.split("::")[0]
        for a, b in sorted(edges):
            ta, tb = top(a), top(b)
            if ta in rank and tb in rank and ta != tb and rank[tb] > rank[ta]:
                print(f"{src}: {a} imports {b}, declared after it in lib.rs (a floor above)")
                failures += 1
        unranked = sorted({top(m) for m in names} - set(rank) - {"crate"})
        for m in unranked:
            print(f"{src}: module {m} is not declared in lib.rs")
            failures += 1
        print(f"{src}: {len(names)} modules, {len(edges)} imports, {len(order)} floors-ordered top-level modules")
    if failures:
        print(f"{failures} finding(s)")
        return 1
    print("no module cycles; every import points down a floor")
    return 0


if __name__ == "__main__":
    sys.exit(main())
