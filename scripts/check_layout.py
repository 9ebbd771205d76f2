#!/usr/bin/env python3
"""Checks the workspace's layout rules (ARCHITECTURE.md, "Layout"):

1. no cycle between the files (modules) of one crate: the graph whose edges are the
   `crate::a::b` / `super::x` / `self::x` paths a file names;
2. no paper crate depends on another paper crate (only on `wscg-math` and external crates).

Prints each violation and exits 1 if there is one. Usage: scripts/check_layout.py [ROOT]
"""

import pathlib
import re
import sys
import tomllib

ROOT = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parent.parent)

# Crates that may depend on paper crates: the command line, the bindings and the umbrella.
AGGREGATORS = {"wscg-cli", "wscg-py", "wscg"}
SHARED = {"wscg-math"}

PATH_RE = re.compile(r"\b(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)+)")
COMMENT_RE = re.compile(r"//[^\n]*")


def module_files(src: pathlib.Path):
    """Maps each module path (tuple of names) of a crate to its file."""
    mods = {}
    for f in src.rglob("*.rs"):
        rel = f.relative_to(src).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] in ("mod", "lib", "main"):
            parts = parts[:-1]
        mods[tuple(parts)] = f
    return mods


def resolve(mods, here, kind, names):
    """The longest module prefix of a path, as a key of `mods`, or None."""
    if kind == "crate":
        base = []
    elif kind == "self":
        base = list(here)
    else:
        base = list(here[:-1])
        while names and names[0] == "super":
            base = base[:-1]
            names = names[1:]
    path = base + names
    for n in range(len(path), -1, -1):
        key = tuple(path[:n])
        if key in mods:
            return key
    return None


def file_cycles(src: pathlib.Path):
    mods = module_files(src)
    edges = {m: set() for m in mods}
    for m, f in mods.items():
        text = COMMENT_RE.sub("", f.read_text())
        # A `mod.rs` (or lib.rs) that declares its children is their parent, not a user.
        for kind, rest in PATH_RE.findall(text):
            names = [n for n in rest.split("::") if n]
            target = resolve(mods, m, kind, names)
            if target is None or target == m:
                continue
            # Paths into a submodule of this file, or out to an ancestor's declarations only,
            # are the module tree itself: an ancestor names its children.
            if target[: len(m)] == m:
                continue
            if m[: len(target)] == target:
                # A child naming an item of its parent: a real use only if the parent names
                # the child back, which the cycle search then finds.
                pass
            edges[m].add(target)
    # Ancestors implicitly contain their children; a child using its ancestor while the
    # ancestor uses the child's items is a cycle as well.
    cycles = []
    index, low, stack, on_stack = {}, {}, [], set()
    counter = [0]

    def strongconnect(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in edges[v]:
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(str(mods[c].relative_to(ROOT)) for c in comp))

    sys.setrecursionlimit(10000)
    for v in edges:
        if v not in index:
            strongconnect(v)
    return cycles


def main():
    problems = []
    crates = {}
    for manifest in sorted((ROOT / "crates").glob("*/Cargo.toml")) + [ROOT / "py" / "Cargo.toml"]:
        data = tomllib.loads(manifest.read_text())
        name = data["package"]["name"]
        crates[name] = (manifest.parent, data)
    paper = {n for n in crates if n.startswith("wscg-") and n not in AGGREGATORS | SHARED}
    for name, (folder, data) in crates.items():
        deps = set(data.get("dependencies", {}))
        if name in paper:
            for d in sorted(deps & paper):
                problems.append(f"paper crate {name} depends on paper crate {d}")
        src = folder / "src"
        if src.is_dir():
            for cyc in file_cycles(src):
                problems.append(f"{name}: files import each other in a cycle: {' <-> '.join(cyc)}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} layout problem(s)")
        sys.exit(1)
    print("layout: no file cycles, no paper crate depends on another")


if __name__ == "__main__":
    main()
