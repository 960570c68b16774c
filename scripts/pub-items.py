#!/usr/bin/env python3
"""Public items of the continuum library, counted from rustdoc's JSON (nightly):

  cargo +nightly rustdoc -p continuum-core --lib -- -Z unstable-options --output-format json
  scripts/pub-items.py target/doc/continuum.json

An item counts when a crate that depends on continuum can name it: every entry of
`paths` from this crate (modules, types, functions, traits, constants, macros),
plus public fields, variants, methods and associated items of those types."""
import json
import sys
from collections import Counter

doc = json.load(open(sys.argv[1]))
index, paths = doc["index"], doc["paths"]
crate = doc["root"]
named = {i for i, p in paths.items() if p.get("crate_id") == 0 and p["kind"] != "variant"}
kinds = Counter(paths[i]["kind"] for i in named)
members = 0
for i in named:
    item = index.get(str(i)) or index.get(i)
    if not item:
        continue
    inner = item["inner"]
    for kind in ("struct", "enum", "union", "trait"):
        if kind not in inner:
            continue
        body = inner[kind]
        fields = body.get("kind", {})
        if isinstance(fields, dict) and "plain" in fields:
            members += sum(1 for f in fields["plain"].get("fields", [])
                           if index.get(str(f), {}).get("visibility") == "public")
        members += len(body.get("variants", []))
        members += len(body.get("items", []))
        for imp in body.get("impls", []):
            imp_item = index.get(str(imp), {})
            ii = imp_item.get("inner", {}).get("impl", {})
            if ii.get("trait") is None:
                members += sum(1 for x in ii.get("items", [])
                               if index.get(str(x), {}).get("visibility") == "public")
print(json.dumps({"named_items": len(named), "by_kind": dict(kinds.most_common()),
                  "public_members": members, "total": len(named) + members}))
