#!/usr/bin/env python3
"""Fails on a file-level import loop inside a crate: a file that names
another (`crate::a::b`, `super::b`) which, directly or through others,
names it back. Each crate's files then form layers, the types at the
bottom (docs/architecture.md). `--strict` also counts a parent module's
plain `child::` paths. Test code (`#[cfg(test)]` onwards) is left out.
Usage: python3 .ci/import-loops.py [--strict] [ROOT]"""
import os, re, sys, itertools
strict = "--strict" in sys.argv
args = [a for a in sys.argv[1:] if a != "--strict"]
root = args[0] if args else "."
def crates():
    for dp, dn, fn in os.walk(root):
        if "target" in dp or "/fuzz" in dp or "/." in dp: continue
        if "Cargo.toml" in fn and os.path.isdir(os.path.join(dp, "src")):
            yield os.path.join(dp, "src")
def mod_of(src, path):
    rel = os.path.relpath(path, src)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib", "main"): rel = rel[:-1]
    return tuple(rel)
total = 0
for src in sorted(crates()):
    files = {}
    for dp, dn, fn in os.walk(src):
        for f in fn:
            if f.endswith(".rs"): files[mod_of(src, os.path.join(dp, f))] = os.path.join(dp, f)
    # Names a module re-exports from one of its children (`pub use
    # child::{A, B}`): a path through the re-export leads to the child.
    reexports = {}
    for m, p in files.items():
        text = re.sub(r"//[^\n]*", "", open(p).read())
        for child, names in re.findall(r"pub(?:\([a-z]+\))? use (?:self::)?([a-z_][a-z0-9_]*)::(\{[^}]*\}|[A-Za-z_][A-Za-z0-9_]*)", text):
            if m + (child,) not in files:
                continue
            for name in re.findall(r"[A-Za-z_][A-Za-z0-9_]*(?=\s*(?:,|\}|$))", names):
                reexports[m + (name,)] = m + (child,)
    edges = {m: set() for m in files}
    for m, p in files.items():
        text = open(p).read()
        cut = text.find("#[cfg(test)]")
        if cut >= 0: text = text[:cut]
        # strip comments
        text = re.sub(r"//[^\n]*", "", text)
        refs = set()
        for r in re.findall(r"crate((?:::[A-Za-z_][A-Za-z0-9_]*)+)", text):
            refs.add(tuple(r.split("::")[1:]))
        for r in re.findall(r"\bsuper((?:::[a-z_][a-z0-9_]*)*)", text):
            base = m[:-1] if not p.endswith("mod.rs") else m[:-1]
            refs.add(base + tuple(x for x in r.split("::")[1:] if x))
        # also `use crate::{a, b::c}` groups
        for g in re.findall(r"crate::\{([^}]*)\}", text):
            for item in g.split(","):
                item = item.strip()
                if item: refs.add(tuple(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", item.split("{")[0])))
        for c in (files if strict else []):
            if len(c) == len(m) + 1 and c[:-1] == m and re.search(r"(?<![:\w])(self::)?" + c[-1] + r"::", text):
                refs.add(c)
        for r in refs:
            # longest prefix that is a file module
            for k in range(len(r), 0, -1):
                target = r[:k] if r[:k] in files else reexports.get(r[:k])
                if target is not None:
                    if target != m:
                        edges[m].add(target)
                    break
    # find cycles of length 2 (and report SCCs)
    index = {}; low = {}; st = []; on = set(); sccs = []; c = [0]
    sys.setrecursionlimit(10000)
    def strong(v):
        index[v] = low[v] = c[0]; c[0] += 1; st.append(v); on.add(v)
        for w in edges[v]:
            if w not in index: strong(w); low[v] = min(low[v], low[w])
            elif w in on: low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = st.pop(); on.discard(w); comp.append(w)
                if w == v: break
            if len(comp) > 1: sccs.append(comp)
    for v in edges:
        if v not in index: strong(v)
    for comp in sccs:
        # ignore parent-child (mod.rs declares child; child uses super) loops? count them but mark
        total += 1
        print(src, ["::".join(x) or "<root>" for x in comp])
print(f"import loops: {total}")
sys.exit(1 if total else 0)
