#!/bin/sh
# No circle of includes inside src/compare (docs/architecture.md, "Where a new metric goes"):
# each file belongs to its module (metrics.c and metrics.h: "metrics"); an `#include
# "compare/X.h"` in a file of module M is an edge M -> X. The graph must be a DAG, so that a
# header never includes, directly or through others, a module that includes it back (before
# the registry, metrics.h included flip.h and structure.h while flip.c and structure.c included
# metrics.h). A cycle is printed. Also: each module's .c includes its own header first.
src=${GODRAYS_SOURCE_DIR:?GODRAYS_SOURCE_DIR is not set (run through ctest)}
command -v python3 >/dev/null || { echo "FAIL: python3 not found"; exit 1; }
python3 - "$src/src/compare" <<'PY'
import os, re, sys
d = sys.argv[1]
files = sorted(f for f in os.listdir(d) if f.endswith(('.c', '.h')))
if len(files) < 10:
    print("FAIL: only %d files under %s (pattern broken?)" % (len(files), d)); sys.exit(1)
inc = re.compile(r'^\s*#\s*include\s*"compare/([A-Za-z0-9_]+)\.h"', re.M)
edges, fail = {}, 0
for f in files:
    mod = f.rsplit('.', 1)[0]
    text = open(os.path.join(d, f), encoding='utf-8').read()
    deps = inc.findall(text)
    for x in deps:
        if not os.path.exists(os.path.join(d, x + '.h')):
            print("FAIL: %s includes compare/%s.h, which does not exist" % (f, x)); fail = 1
        if x != mod:
            edges.setdefault(mod, set()).add(x)
    if f.endswith('.c') and os.path.exists(os.path.join(d, mod + '.h')) and (not deps or deps[0] != mod):
        print("FAIL: %s does not include compare/%s.h first" % (f, mod)); fail = 1
# depth-first search for a back edge
state, stack = {}, []
def visit(m):
    global fail
    state[m] = 1
    stack.append(m)
    for x in sorted(edges.get(m, ())):
        if state.get(x) == 1:
            print("FAIL: circle of includes: " + " -> ".join(stack[stack.index(x):] + [x])); fail = 1
        elif x not in state:
            visit(x)
    stack.pop()
    state[m] = 2
for m in sorted(set(f.rsplit('.', 1)[0] for f in files)):
    if m not in state:
        visit(m)
n = sum(len(v) for v in edges.values())
if not fail:
    print("ok: %d modules, %d include edges inside src/compare, no circle" % (len(state), n))
sys.exit(fail)
PY
