#!/usr/bin/env python3
"""No call circles in the library: who calls whom, read off the object files.

An object file A depends on B when A leaves a symbol undefined that B defines
(nm). The test fails on any circle between files, and on any circle between the
stage folders of src/ (core, scene, ...), and prints each stage's callees.
Objects whose source is gone (a stale build tree) are ignored.
Usage: check_deps.py NM SOURCE_ROOT OBJECT_DIR..."""
import os
import subprocess
import sys


def symbols(nm, path):
    out = subprocess.run([nm, path], capture_output=True, text=True, check=True).stdout
    defined, undefined = set(), set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 2 and parts[0] == "U":
            undefined.add(parts[1])
        elif len(parts) == 3 and parts[1] in "TDBR":  # global text, data, bss, read-only data
            defined.add(parts[2])
    return defined, undefined


def circles(graph):
    """Strongly connected components of more than one node, or a node calling itself."""
    index, low, on_stack, stack, found, counter = {}, {}, set(), [], [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
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
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def main():
    nm, top, dirs = sys.argv[1], sys.argv[2], sys.argv[3:]
    objs = []
    for d in dirs:
        for root, _, files in os.walk(d):
            for f in files:
                src = os.path.join(top, os.path.relpath(root, d), f[:-2])  # x.c.o -> x.c
                if f.endswith(".c.o") and os.path.exists(src):
                    objs.append(os.path.join(root, f))
    if not objs:
        print("no object files under", dirs)
        return 1
    owner, needs = {}, {}
    for o in objs:
        # .../src/<stage>/<file>.c.o -> <stage>/<file>
        parts = o.replace("\\", "/").split("/")
        name = parts[-2] + "/" + parts[-1].split(".")[0]
        defined, undefined = symbols(nm, o)
        for s in defined:
            owner[s] = name
        needs[name] = undefined
    files = {a: {owner[s] for s in u if s in owner and owner[s] != a} for a, u in needs.items()}
    stages = {}
    for a, callees in files.items():
        sa = a.split("/")[0]
        stages.setdefault(sa, set()).update(b.split("/")[0] for b in callees if b.split("/")[0] != sa)
    for s in sorted(stages):
        print("%-6s calls %s" % (s, ", ".join(sorted(stages[s])) or "nothing"))
    bad = circles(files) + circles(stages)
    for c in bad:
        print("circle:", " <-> ".join(c))
    print("%d files, %d stages, %d circles" % (len(files), len(stages), len(bad)))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
