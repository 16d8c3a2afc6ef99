#!/usr/bin/env python3
"""Checks that the modules of the engine crate depend on each other one way: no cycles.

A module's dependencies are the top-level modules its code names as `crate::m` (in paths and
`use crate::{...}` lists), an item lib.rs re-exports (`crate::World`) counting as its module;
comments and doc links do not count, nor do unit-test files (`*_tests.rs`, `tests.rs`, files
under a `tests/` folder, `test_support.rs`),
which may use the whole crate. Prints the graph and exits 1 on a cycle.
Usage: scripts/module-cycles.py [crates/impulse/src]
"""
import glob
import os
import re
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "crates/impulse/src"
modules = {
    os.path.relpath(p, root).split(os.sep)[0].removesuffix(".rs")
    for p in glob.glob(os.path.join(root, "**", "*.rs"), recursive=True)
} - {"lib"}
# Items lib.rs re-exports, by the module they come from.
reexported = {}
with open(os.path.join(root, "lib.rs"), encoding="utf-8") as f:
    lib = f.read()
for module, items in re.findall(r"pub use (\w+)::\{([^}]*)\}", lib, re.S):
    for item in items.split(","):
        reexported[item.strip()] = module
for module, item in re.findall(r"pub use (\w+)::(\w+);", lib):
    reexported[item] = module
graph = {}
for path in glob.glob(os.path.join(root, "**", "*.rs"), recursive=True):
    module = os.path.relpath(path, root).split(os.sep)[0].removesuffix(".rs")
    name = os.path.basename(path)
    if module == "lib" or name.endswith("_tests.rs") or name == "test_support.rs":
        continue
    if name == "tests.rs" or "tests" in os.path.relpath(path, root).split(os.sep)[:-1]:
        continue
    with open(path, encoding="utf-8") as f:
        code = "\n".join(l for l in f if not l.strip().startswith("//"))
    names = set(re.findall(r"crate::([A-Za-z_]+)", code))
    for group in re.findall(r"use crate::\{([^}]*)\}", code, re.S):
        names.update(p.strip().split("::")[0] for p in group.split(",") if p.strip())
    names = {reexported.get(n, n) for n in names} & modules
    names.discard(module)
    graph.setdefault(module, set()).update(names)

def reachable(start):
    seen, stack = set(), [start]
    while stack:
        for n in graph.get(stack.pop(), ()):
            if n not in seen:
                seen.add(n)
                stack.append(n)
    return seen

for module in sorted(graph):
    print(f"{module} -> {', '.join(sorted(graph[module])) or '(nothing)'}")
cycles = sorted((a, b) for a in graph for b in graph[a] if a in reachable(b))
if cycles:
    print("cycles through:", ", ".join(f"{a} -> {b}" for a, b in cycles))
    sys.exit(1)
print("no cycles")
