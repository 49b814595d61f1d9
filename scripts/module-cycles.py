#!/usr/bin/env python3
"""Prints the import graph of glint-render's modules (one node per source file) and its cycles.

An edge A -> B means a file of module A names `crate::B...` (in a `use` or a path). Test-only
code (`#[cfg(test)] mod tests` blocks and src/tests/, src/testing.rs) is left out: tests may
look anywhere. Exit status 1 if there is a cycle.

    scripts/module-cycles.py [crates/render/src]
"""

import re
import sys
from pathlib import Path

root = Path(sys.argv[1] if len(sys.argv) > 1 else "crates/render/src")


def module_of(path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] in ("mod", "lib"):
        parts = parts[:-1]
    return "::".join(parts) or "crate"


files = {}
for path in sorted(root.rglob("*.rs")):
    rel = path.relative_to(root).as_posix()
    if rel.startswith("tests/") or rel == "testing.rs":
        continue
    text = path.read_text()
    # Drop the unit-test module at the end of a file.
    cut = re.search(r"#\[cfg\(test\)\]\s*mod tests\b", text)
    if cut:
        text = text[: cut.start()]
    # Comments name modules without depending on them.
    text = re.sub(r"//[^\n]*", "", text)
    files[module_of(path)] = text

modules = set(files)


def resolve(name: str) -> str:
    """The longest known module that prefixes `name`."""
    parts = name.split("::")
    for k in range(len(parts), 0, -1):
        candidate = "::".join(parts[:k])
        if candidate in modules:
            return candidate
    return parts[0]


edges = {m: set() for m in modules}
for module, text in files.items():
    # `use crate::{a::X, b::{Y, Z}}` and `crate::a::b::c` paths.
    for match in re.finditer(r"crate::((?:[a-z_][a-z0-9_]*::)*[a-z_][a-z0-9_]*)", text):
        target = resolve(match.group(1))
        if (
            target in modules
            and target != module
            and not module.startswith(target + "::")
        ):
            edges[module].add(target)
    for match in re.finditer(r"use crate::\{([^;]*)\};", text, re.DOTALL):
        for item in re.findall(
            r"([a-z_][a-z0-9_]*(?:::[a-z_][a-z0-9_]*)*)", match.group(1)
        ):
            target = resolve(item)
            if (
                target in modules
                and target != module
                and not module.startswith(target + "::")
            ):
                edges[module].add(target)
    # `super::x` inside a submodule.
    if "::" in module:
        parent = module.rsplit("::", 1)[0]
        for match in re.finditer(r"super::([a-z_][a-z0-9_]*)", text):
            target = resolve(parent + "::" + match.group(1))
            if target in modules and target != module:
                edges[module].add(target)

# Tarjan's strongly connected components.
index, low, on_stack, stack, cycles, counter = {}, {}, set(), [], [], [0]


def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
    stack.append(v)
    on_stack.add(v)
    for w in sorted(edges[v]):
        if w not in index:
            visit(w)
            low[v] = min(low[v], low[w])
        elif w in on_stack:
            low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        component = []
        while True:
            w = stack.pop()
            on_stack.discard(w)
            component.append(w)
            if w == v:
                break
        if len(component) > 1:
            cycles.append(sorted(component))


sys.setrecursionlimit(10000)
for v in sorted(modules):
    if v not in index:
        visit(v)

for module in sorted(modules):
    print(f"{module} -> {', '.join(sorted(edges[module])) or '(nothing)'}")
if cycles:
    for component in cycles:
        print("cycle among:", ", ".join(component))
    sys.exit(1)
print(f"no cycle among {len(modules)} modules")
