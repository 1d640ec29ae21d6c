#!/usr/bin/env python3
"""Fails if a crate's module import graph has a circle (the house rule: the structure reads top to
bottom). An edge A -> B is any `crate::B…` or `super::B…` path (grouped `use` included) in the code of
module A, comments and `#[cfg(test)] mod tests` left out; modules are compared at depths 1 and 2.

    python3 .ci/check_imports.py            # every crate of the workspace
"""

import os
import re
import sys

CRATES = ["pt-spectra/src", "pt-spectra/src/bin/pt-spectra", "pt-kernels/src", "kernelgen/src",
          "kernelgen/core/src", "python/src"]


def module_path(root, path):
    parts = os.path.relpath(path, root)[:-3].split(os.sep)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return parts


def references(src):
    """The `crate::…` and `super::…` paths of the code, grouped imports expanded."""
    src = re.sub(r"#\[cfg\(test\)\]\s*mod tests\s*\{.*", "", src, flags=re.S)
    src = "\n".join(l for l in src.splitlines() if not l.strip().startswith("//"))
    found = []
    for g in re.finditer(r"\b(crate|super)::\{([^;]*)\}", src):
        depth, item, items = 0, "", []
        for ch in g.group(2):
            depth += (ch == "{") - (ch == "}")
            if ch == "," and depth == 0:
                items.append(item)
                item = ""
            else:
                item += ch
        items.append(item)
        found += [(g.group(1), it.strip().split("{")[0]) for it in items if it.strip()[:1].islower()]
    found += [(m.group(1), m.group(2)) for m in re.finditer(r"\b(crate|super)::([a-z_0-9]+(?:::[a-z_0-9]+)*)", src)]
    return found


def graph(root, depth):
    edges = {}
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if not (root.endswith("pt-spectra/src") and d == "bin")]
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(folder, f)
            parts = module_path(root, path)
            if "tests" in parts:
                continue
            me = "::".join(parts[:depth]) or "crate"
            for kind, target in references(open(path, encoding="utf-8").read()):
                names = target.split("::")
                if kind == "super":
                    names = parts[:-1] + names
                t = "::".join(names[:depth])
                if t and t != me and not me.startswith(t + "::") and not t.startswith(me + "::"):
                    edges.setdefault(me, set()).add(t)
    return edges


def circles(edges):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
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
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in list(edges):
        if v not in index:
            visit(v)
    return out


def main():
    bad = 0
    for root in CRATES:
        if not os.path.isdir(root):
            continue
        for depth in (1, 2):
            edges = graph(root, depth)
            for comp in circles(edges):
                bad += 1
                print(f"{root}: import circle among {comp}:")
                for a in comp:
                    for b in sorted(edges.get(a, ())):
                        if b in comp:
                            print(f"    {a} -> {b}")
    if bad:
        sys.exit(1)
    print("no import circles in", ", ".join(CRATES))


if __name__ == "__main__":
    main()
