#!/usr/bin/env python3
"""The sim library's layering, checked from its source.

Each top-level module of sim/src may import only the modules listed before it in LAYERS (and
itself); inside a folder, files name their siblings by `super::` and those imports form no
circle. Exit code 1 with every offending import listed; 0 and a one-line summary otherwise.
"""
import pathlib
import re
import sys

LAYERS = ["toml_file", "error", "chart", "world", "airports", "scenario", "offline_map", "engine", "replay",
          "rosbag", "pcap", "studies", "campaign", "tune", "regress", "bench"]

def strip_comments(text):
    return "\n".join(line.split("//", 1)[0] for line in text.splitlines())

def main(root):
    src = pathlib.Path(root) / "sim" / "src"
    problems = []
    edges = {}
    for path in sorted(src.rglob("*.rs")):
        rel = path.relative_to(src)
        if rel.name == "lib.rs":
            continue
        top = rel.parts[0].removesuffix(".rs")
        if top not in LAYERS:
            problems.append(f"{rel}: module `{top}` is not in the layer list of .ci/check_layers.py")
            continue
        text = strip_comments(path.read_text())
        for m in re.finditer(r"\bcrate::([a-z_]+)", text):
            other = m.group(1)
            if other not in LAYERS:
                continue
            if other == top and len(rel.parts) == 2:
                problems.append(f"{rel}: names its own folder as `crate::{top}`: use `super::`")
            elif LAYERS.index(other) > LAYERS.index(top):
                problems.append(f"{rel}: imports `crate::{other}`, a layer above `{top}`")
        if len(rel.parts) > 1:
            folder = path.parent
            me = rel.stem if rel.stem != "mod" else None
            if me is None:
                continue
            for m in re.finditer(r"\bsuper::([a-z_]+)", text):
                sib = m.group(1)
                if (folder / f"{sib}.rs").exists() or (folder / sib / "mod.rs").exists():
                    edges.setdefault((folder, me), set()).add((folder, sib))
    # Circles between sibling files.
    state = {}
    def visit(node, stack):
        state[node] = 1
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                cycle = stack[stack.index(nxt):] + [nxt] if nxt in stack else [node, nxt]
                names = " -> ".join(n[1] for n in cycle)
                problems.append(f"{node[0].relative_to(src)}/: import circle {names}")
            elif state.get(nxt) is None:
                visit(nxt, stack + [nxt])
        state[node] = 2
    for node in sorted(edges):
        if state.get(node) is None:
            visit(node, [node])
    if problems:
        print("\n".join(sorted(set(problems))), file=sys.stderr)
        return 1
    print(f"ok: sim/src layered as {' < '.join(LAYERS)}; no import circle between sibling files")
    return 0

if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
