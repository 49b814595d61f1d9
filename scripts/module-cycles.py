#!/usr/bin/env python3
"""Prints each crate's module import graph, its cycles and the renderer's upward imports.

One node per source file. An edge A -> B means a file of module A names `crate::B...` or
`super::B...` (in a `use` or a path). Test-only code (`#[cfg(test)] mod tests` blocks, a
crate's src/tests/, src/testing.rs and src/testing/) is left out: tests may look anywhere.

Every crate of the repository is read (the workspace's, the Python module's and the fuzz
targets'). In glint-render the modules also sit in layers (LAYERS below, lowest first); an
edge from a module to one in a higher layer is an upward import.

Exit status 1 if any crate has a cycle or the renderer has an upward import.

    scripts/module-cycles.py            every crate
    scripts/module-cycles.py --quiet    only the findings and the summary line
    scripts/module-cycles.py DIR        the crates of the checkout at DIR
"""

import re
import sys
from pathlib import Path

ARGS = [a for a in sys.argv[1:] if not a.startswith("--")]
REPO = Path(ARGS[0]) if ARGS else Path(__file__).resolve().parent.parent

# Every crate's source root; a binary crate's root file is main.rs, a library's lib.rs.
CRATES = {
    "glint-render": "crates/render/src",
    "glint-io": "crates/io/src",
    "glint (cli)": "crates/cli/src",
    "glint-gpu": "crates/gpu/src",
    "glint-wasm": "web/glint-wasm/src",
    "glint-python": "python/src",
    "fuzz targets": "fuzz/fuzz_targets",
}

# glint-render's layers, lowest first: a module may import from its own layer and those
# below. A module's layer is that of the longest entry that prefixes its path; a module
# named by no entry is reported.
LAYERS = [
    # Numbers, rays, sample sequences and memory: depend on nothing else of the crate.
    ["math", "ray", "sampling", "pages"],
    # What a scene is made of, each on its own.
    ["geometry", "camera", "film", "texture", "material", "medium", "light", "bvh"],
    # The ray engine: kernels, trees, walks, packets and their build.
    ["accel"],
    # The scene: geometry, its trees and what shades it.
    ["scene"],
    # What renders a scene: light selection over the scene's emitters, the integrators.
    ["light::sampler", "integrator"],
    # The render loop and the benchmark surface above it.
    ["pipeline", "bench", "crate"],
]


def module_of(root: Path, path: Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return "::".join(parts) or "crate"


def read_modules(root: Path) -> dict:
    files = {}
    for path in sorted(root.rglob("*.rs")):
        rel = path.relative_to(root).as_posix()
        if rel.startswith(("tests/", "testing/")) or rel == "testing.rs":
            continue
        text = path.read_text()
        # Drop the unit-test module at the end of a file.
        cut = re.search(r"#\[cfg\(test\)\]\s*mod tests\b", text)
        if cut:
            text = text[: cut.start()]
        # Comments name modules without depending on them.
        text = re.sub(r"//[^\n]*", "", text)
        files[module_of(root, path)] = text
    return files


def graph(files: dict) -> dict:
    modules = set(files)

    def resolve(name: str) -> str:
        """The longest known module that prefixes `name`."""
        parts = name.split("::")
        for k in range(len(parts), 0, -1):
            candidate = "::".join(parts[:k])
            if candidate in modules:
                return candidate
        return parts[0]

    def add(module: str, target: str, edges: set) -> None:
        if (
            target in modules
            and target != module
            and not module.startswith(target + "::")
        ):
            edges.add(target)

    edges = {m: set() for m in modules}
    path_re = r"((?:[a-z_][a-z0-9_]*::)*[a-z_][a-z0-9_]*)"
    for module, text in files.items():
        # `crate::a::b::c` paths, and every path inside `use crate::{...};` groups.
        for match in re.finditer(r"crate::" + path_re, text):
            add(module, resolve(match.group(1)), edges[module])
        for match in re.finditer(r"use crate::\{([^;]*)\};", text, re.DOTALL):
            for item in re.findall(path_re, match.group(1)):
                add(module, resolve(item), edges[module])
        # `super::x` names a sibling of this module, or of the crate root's children.
        parent = module.rsplit("::", 1)[0] if "::" in module else None
        for match in re.finditer(r"super::" + path_re, text):
            name = match.group(1)
            target = resolve(parent + "::" + name) if parent else resolve(name)
            add(module, target, edges[module])
        for match in re.finditer(r"use super::\{([^;]*)\};", text, re.DOTALL):
            for item in re.findall(path_re, match.group(1)):
                target = resolve(parent + "::" + item) if parent else resolve(item)
                add(module, target, edges[module])
    return edges


def cycles_of(edges: dict) -> list:
    """Tarjan's strongly connected components of more than one module."""
    index, low, on_stack, stack, found, counter = {}, {}, set(), [], [], [0]

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
                found.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def layer_of(module: str):
    best, best_len = None, -1
    for level, names in enumerate(LAYERS):
        for name in names:
            covers = module == name or module.startswith(name + "::")
            if covers and len(name) > best_len:
                best, best_len = level, len(name)
    return best


def main() -> int:
    quiet = "--quiet" in sys.argv[1:]
    findings = 0
    total_modules = 0
    for crate, src in CRATES.items():
        root = REPO / src
        if not root.is_dir():
            continue
        files = read_modules(root)
        edges = graph(files)
        total_modules += len(files)
        if not quiet:
            print(f"# {crate} ({src})")
            for module in sorted(edges):
                print(f"{module} -> {', '.join(sorted(edges[module])) or '(nothing)'}")
        for component in cycles_of(edges):
            print(f"{crate}: cycle among: {', '.join(component)}")
            findings += 1
        if crate == "glint-render":
            for module in sorted(edges):
                level = layer_of(module)
                if level is None:
                    print(
                        f"{crate}: module {module} is in no layer (scripts/module-cycles.py)"
                    )
                    findings += 1
                    continue
                for target in sorted(edges[module]):
                    target_level = layer_of(target)
                    if target_level is not None and target_level > level:
                        print(f"{crate}: upward import: {module} -> {target}")
                        findings += 1
    if findings:
        print(
            f"{findings} import circles or upward imports among {total_modules} modules"
        )
        return 1
    print(f"no import circle and no upward import among {total_modules} modules")
    return 0


if __name__ == "__main__":
    sys.exit(main())
