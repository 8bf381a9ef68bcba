#!/usr/bin/env python3
"""The workspace's module structure, checked from its source: no import circle in any crate, and
the sim library's layers in order.

    .ci/check_layers.py [ROOT]        # check the workspace at ROOT (default: the current folder)
    .ci/check_layers.py --self-test   # shows the check failing on a circle and passing without it

Exit code 1 with every offending import listed; 0 and a summary otherwise.

Which crates: every member of the workspace (ROOT/Cargo.toml's [workspace] members) that has a
src/ folder; src/lib.rs or src/main.rs is the crate's root module.

Modules: a file is a module (`a.rs` and `a/mod.rs` are both module `a`; `a.rs` beside a folder
`a/` is that folder's module). Inline modules (`mod tests { ... }`) belong to their file: what
they import is imported by the file's module.

Imports: every path in the code (comments, strings and character literals removed) that starts
with `crate::`, `self::`, `super::` (any number of them), or with the name of a child module the
file declares (`mod x;` then `use x::...`), in a `use` declaration (grouped trees `use
crate::{a::X, b::{Y, Z}}` expanded) or written out in the code (`crate::a::f()`). `$crate`,
`pub(in ...)` and other crates' paths (`mapper::...`) are not imports between modules of this
crate. A path is resolved from where it is written (`super::` inside `mod tests` in `a.rs` is
`a`) and names the deepest module, by file, that it spells out: `crate::map::RosOccupancy` names
`map` even when `map` only re-exports it (re-exports are not followed, so an import that must not
be a circle names the module that defines the item).

The rule, at module granularity: an import from module M to module T, when neither is inside the
other, is an edge between the two siblings under their deepest common parent that hold M and T
(`crate::odm` in `map/distance.rs` is the edge `map -> odm` at the crate's root). A circle is a
set of siblings each reaching the others by such edges; each is reported, with the imports that
make its edges. An import between a module and one inside it (a child naming its parent's items
with `super::`, or a folder's mod.rs naming its child's items) is no edge: the parent declares the
child, and a folder's files may share the folder's types that way. Test modules (`#[cfg(test)] mod
tests { ... }`, or `#[cfg(test)] mod x;` and what is inside it) make no edge either: nothing in the
library can name them, and a unit test may build its inputs with what a module above its own
provides (scan.rs's test reads `crate::workloads::parking_lot_scan`, a workload made of scans).

Layers: each top-level module of sim/src may import only the modules listed before it in LAYERS
(and itself), in its tests too; a file directly in a top-level folder names its own folder
`super::`, not `crate::<folder>`; every top-level module must be in LAYERS.

What it cannot see: names brought in by a glob (`use super::*`) and then used as path prefixes,
macros' output, `#[path]` attributes, and crates under src/bin/ (none of which this workspace's
crates use across modules).
"""
import bisect
import pathlib
import re
import sys
import tempfile
import tomllib

LAYERS = ["toml_file", "error", "chart", "world", "airports", "scenario", "offline_map", "engine", "replay",
          "rosbag", "pcap", "studies", "campaign", "tune", "regress", "bench"]

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
TOKEN = re.compile(rf"""
    (?P<inline>\bmod\s+(?P<iname>{IDENT})\s*\{{)
  | (?P<decl>\bmod\s+(?P<dname>{IDENT})\s*;)
  | (?P<use>\buse\s+(?P<tree>[^;]*);)
  | (?P<open>\{{)
  | (?P<close>\}})
  | (?P<path>(?<![\w$:])(?:{IDENT})(?:\s*::\s*{IDENT})+)
""", re.VERBOSE)
# `#[cfg(test)]`, other attributes and a visibility at the end of the text searched: a test `mod`.
CFG_TEST = re.compile(r"#\[\s*cfg\s*\(\s*test\s*\)\s*\]\s*(?:#\[[^\]]*\]\s*)*(?:pub\s*(?:\([^)]*\))?\s*)?\Z")
# Where a comment, a string or a character literal may start.
LITERAL_START = re.compile(r"""//|/\*|(?<![\w])b?r(\#*)"|(?<![\w])b?"|'""")
CHAR = re.compile(r"'(?:\\u\{[0-9a-fA-F]+\}|\\x[0-9a-fA-F]{2}|\\.|[^\\'\n])'")
STRING_END = re.compile(r'(?:\\.|[^"\\])*"', re.DOTALL)


def clean(text):
    """The source without comments, string and character literals; newlines kept (line numbers)."""
    out, i, n = [], 0, len(text)
    while (m := LITERAL_START.search(text, i)):
        out.append(text[i:m.start()])
        start, token = m.start(), m.group(0)
        if token == "//":
            j = text.find("\n", start)
            j = n if j < 0 else j
        elif token == "/*":
            depth, j = 1, start + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
        elif token.endswith('"') and m.group(1) is not None:  # raw string
            close = text.find('"' + m.group(1), m.end())
            j = n if close < 0 else close + 1 + len(m.group(1))
        elif token.endswith('"'):
            close = STRING_END.match(text, m.end())
            j = n if close is None else close.end()
        else:  # a quote: a character literal, or a lifetime's (kept)
            char = CHAR.match(text, start)
            if char is None:
                out.append("'")
                i = start + 1
                continue
            j = char.end()
        out.append(("''" if token == "'" else '""' if token.endswith('"') else "") + "\n" * text.count("\n", start, j))
        i = j
    out.append(text[i:])
    return "".join(out)


def split_top(text, sep=","):
    """`text` split at `sep` outside braces."""
    parts, depth, start = [], 0, 0
    for k, c in enumerate(text):
        if c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
        elif c == sep and depth == 0:
            parts.append(text[start:k])
            start = k + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


def use_paths(tree):
    """The paths a use tree names: `a::{b, c::{d, self}}` is a::b, a::c::d, a::c (lists of segments)."""
    tree = re.sub(r"\s+", " ", tree).strip()
    tree = re.sub(r"\s+as\s+" + IDENT + r"\s*$", "", tree)
    if "{" in tree:
        prefix, rest = tree.split("{", 1)
        inner = rest[: rest.rindex("}")]
        head = [s.strip() for s in prefix.split("::") if s.strip()]
        paths = []
        for part in split_top(inner):
            for sub in use_paths(part):
                paths.append(head + sub if sub != ["self"] else head)
        return paths
    segments = [s.strip() for s in tree.split("::") if s.strip()]
    segments = [s for s in segments if s != "*"]
    return [segments] if segments else []


class Crate:
    """A crate's modules by file: module path (tuple of names) -> file."""

    def __init__(self, src, label):
        self.src, self.label = src, label
        self.files = {}
        for path in sorted(src.rglob("*.rs")):
            rel = path.relative_to(src)
            if rel.parts[0] == "bin":
                continue  # each file there is a crate of its own
            if len(rel.parts) == 1 and rel.name in ("lib.rs", "main.rs"):
                module = ()
            elif rel.name == "mod.rs":
                module = rel.parts[:-1]
            else:
                module = rel.parts[:-1] + (rel.stem,)
            self.files[module] = path
        self.tests = set()  # file modules declared `#[cfg(test)] mod x;`, found by `imports`

    def module_of(self, absolute):
        """The deepest module, by file, that the absolute path spells out."""
        for k in range(len(absolute), -1, -1):
            if tuple(absolute[:k]) in self.files:
                return tuple(absolute[:k])
        return ()

    def imports(self, module):
        """(line, written path, absolute path, in a test module) of each import in the module's file.

        Also adds to `self.tests` the file modules this file declares `#[cfg(test)] mod x;`.
        """
        text = clean(self.files[module].read_text())
        text = re.sub(r"\bpub\s*\(\s*in\b[^)]*\)", lambda m: " " * len(m.group(0)), text)
        newlines = [k for k, c in enumerate(text) if c == "\n"]
        children = {m.group(1) for m in re.finditer(rf"\bmod\s+({IDENT})\s*[;{{]", text)}
        depth, inline = 0, []  # inline: (name, depth at which its body opened, a test module)
        found = []
        for m in TOKEN.finditer(text):
            if m.group("inline"):
                depth += 1
                test = bool(CFG_TEST.search(text, 0, m.start())) or any(t for _, _, t in inline)
                inline.append((m.group("iname"), depth, test))
            elif m.group("open"):
                depth += 1
            elif m.group("close"):
                if inline and inline[-1][1] == depth:
                    inline.pop()
                depth -= 1
            elif m.group("decl"):
                if not inline and CFG_TEST.search(text, 0, m.start()):
                    self.tests.add(module + (m.group("dname"),))
            else:
                line = bisect.bisect_left(newlines, m.start()) + 1
                here = module + tuple(name for name, _, _ in inline)
                test = any(t for _, _, t in inline)
                written = (use_paths(m.group("tree")) if m.group("use")
                           else [[s.strip() for s in m.group("path").split("::")]])
                for segments in written:
                    absolute = resolve(segments, here, set() if inline else children)
                    if absolute is not None:
                        found.append((line, "::".join(segments), absolute, test))
        return found

    def in_test(self, module):
        """Whether the module is, or is inside, a file module declared `#[cfg(test)]`."""
        return any(module[:k] in self.tests for k in range(1, len(module) + 1))


def resolve(segments, here, children):
    """The absolute module path a path names from module `here`; None for another crate's path."""
    if not segments:
        return None
    first = segments[0]
    if first == "crate":
        return list(segments[1:])
    if first in ("self", "super"):
        base = list(here)
        k = 0
        if first == "self":
            k = 1
        while k < len(segments) and segments[k] == "super":
            if not base:
                return None
            base.pop()
            k += 1
        return base + list(segments[k:])
    if first in children:
        return list(here) + list(segments)
    return None


def sibling_edge(source, target):
    """(parent, from, to) for an import between modules neither inside the other; else None."""
    k = 0
    while k < min(len(source), len(target)) and source[k] == target[k]:
        k += 1
    if k == len(source) or k == len(target):
        return None
    return source[:k], source[k], target[k]


def circles(edges):
    """Strongly connected components of more than one node (Tarjan), each sorted."""
    index, low, stack, on, out = {}, {}, [], set(), []
    nodes = sorted(set(edges) | {b for bs in edges.values() for b in bs})

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in nodes:
        if v not in index:
            visit(v)
    return sorted(out)


def one_cycle(component, edges):
    """A cycle through the component's first node, as a list of names ending where it started."""
    start, inside = component[0], set(component)
    paths = {start: [start]}
    queue = [start]
    while queue:
        v = queue.pop(0)
        for w in sorted(edges.get(v, ())):
            if w == start:
                return paths[v] + [start]
            if w in inside and w not in paths:
                paths[w] = paths[v] + [w]
                queue.append(w)
    return component + [start]


def check_crate(crate, root, problems):
    """Every circle between sibling modules of the crate, into `problems`; the crate's imports."""
    edges, why, imports = {}, {}, {}
    for module in crate.files:
        imports[module] = crate.imports(module)
    for module in crate.files:
        if crate.in_test(module):
            continue
        for line, written, absolute, test in imports[module]:
            if test:
                continue
            target = crate.module_of(absolute)
            edge = sibling_edge(module, target)
            if edge is None:
                continue
            parent, a, b = edge
            edges.setdefault(parent, {}).setdefault(a, set()).add(b)
            rel = crate.files[module].relative_to(root)
            why.setdefault((parent, a, b), []).append(f"{rel}:{line}: {written}")
    for parent in sorted(edges):
        for component in circles(edges[parent]):
            folder = "/".join((crate.label,) + parent) + "/"
            lines = [f"{folder}: import circle {' -> '.join(one_cycle(component, edges[parent]))}"]
            for a in component:
                for b in sorted(edges[parent].get(a, ())):
                    if b in component:
                        seen = why[(parent, a, b)]
                        more = f" (and {len(seen) - 3} more)" if len(seen) > 3 else ""
                        lines.append(f"    {a} -> {b}: " + "; ".join(seen[:3]) + more)
            problems.append("\n".join(lines))
    return imports


def check_layers(crate, imports, root, problems):
    """The sim library's layer order, into `problems`."""
    for module, path in sorted(crate.files.items()):
        if not module:
            continue
        rel = path.relative_to(root)
        top = module[0]
        if top not in LAYERS:
            problems.append(f"{rel}: module `{top}` is not in the layer list of .ci/check_layers.py")
            continue
        for line, written, absolute, _ in imports[module]:
            other = crate.module_of(absolute)
            if not other or other[0] not in LAYERS:
                continue
            if other[0] == top and written.startswith("crate::") and len(path.relative_to(crate.src).parts) == 2:
                problems.append(f"{rel}:{line}: names its own folder as `crate::{top}`: use `super::`")
            elif LAYERS.index(other[0]) > LAYERS.index(top):
                problems.append(f"{rel}:{line}: imports `crate::{other[0]}` ({written}), a layer above `{top}`")


def crates(root):
    """The workspace's crates with a src/ folder, in the order of its members."""
    members = tomllib.loads((root / "Cargo.toml").read_text())["workspace"]["members"]
    return [Crate(root / m / "src", f"{m}/src") for m in members if (root / m / "src").is_dir()]


def main(root, out=sys.stdout, err=sys.stderr):
    root = pathlib.Path(root)
    problems, counted = [], []
    for crate in crates(root):
        imports = check_crate(crate, root, problems)
        counted.append(f"{crate.label} ({len(crate.files)} modules)")
        if crate.label == "sim/src":
            check_layers(crate, imports, root, problems)
    if problems:
        print("\n".join(sorted(set(problems))), file=err)
        print(f"{len(set(problems))} problem(s) in the module structure (above)", file=err)
        return 1
    print(f"ok: no import circle between sibling modules in {len(counted)} crates: {', '.join(counted)}", file=out)
    if any(c.label == "sim/src" for c in crates(root)):
        print(f"ok: sim/src layered as {' < '.join(LAYERS)}", file=out)
    return 0


SELF_TEST_TREE = {
    "Cargo.toml": '[workspace]\nmembers = ["demo", "sim"]\n',
    "demo/src/lib.rs": "//! A crate.\npub mod leaf;\npub mod net;\npub mod shape;\npub use net::Net;\n",
    "demo/src/leaf.rs": "//! Leaf: names no module of the crate.\npub struct Leaf;\n",
    # A folder module as mod.rs: its files share its types, and it uses theirs.
    "demo/src/net/mod.rs": ("//! Net.\nmod build;\nmod route;\nuse build::Builder;\n"
                            "pub struct Net;\nimpl Net { fn b(&self) -> Builder { route::go(); Builder } }\n"),
    "demo/src/net/build.rs": ("//! Build.\nuse super::Net;\nuse crate::shape::Outline;\npub struct Builder;\n"
                              "// not an import: super::route::go\n"
                              "fn f(_: Net, _: Outline) -> &'static str { \"super::route::go crate::shape\" }\n"
                              "#[cfg(test)]\nmod tests {\n    use super::*;\n    use super::super::Net;\n}\n"),
    "demo/src/net/route.rs": ("//! Route.\nuse super::{build::Builder, Net};\n"
                              "pub fn go() { let _: Option<(Builder, Net)> = None; }\n"),
    # A folder module as shape.rs beside shape/.
    "demo/src/shape.rs": "//! Shape.\nmod outline;\npub use outline::Outline;\n",
    "demo/src/shape/outline.rs": "//! Outline.\npub struct Outline(pub crate::leaf::Leaf);\n",
    # Three of sim/src's layers: world above chart above error.
    "sim/src/lib.rs": "//! Sim.\npub mod chart;\npub mod error;\npub mod world;\n",
    "sim/src/error.rs": "//! Error.\npub struct Error;\n",
    "sim/src/chart.rs": "//! Chart.\npub struct Font;\n",
    "sim/src/world.rs": "//! World.\nuse crate::{chart::Font, error::Error};\npub struct World(Font, Error);\n",
}

# name, {file: (text to replace, replacement)}, exit code wanted, text the output must hold
SELF_TEST_CASES = [
    ("no circle", {}, 0, "no import circle between sibling modules in 2 crates: demo/src (7 modules)"),
    ("siblings in a folder: route -> build, build -> route", {
        "demo/src/net/build.rs": ("pub struct Builder;", "pub struct Builder;\nfn g() { super::route::go() }"),
    }, 1, "demo/src/net/: import circle build -> route -> build"),
    ("across levels, by a grouped crate:: use: net/build -> shape, shape/outline -> net", {
        "demo/src/shape/outline.rs": ("pub struct", "use crate::{leaf::Leaf, net::{Net}};\npub struct"),
    }, 1, "demo/src/: import circle net -> shape -> net"),
    ("through a third module: leaf -> net, net/build -> shape, shape/outline -> leaf", {
        "demo/src/leaf.rs": ("pub struct Leaf;", "pub struct Leaf;\nimpl Leaf { fn n(&self) -> crate::Net { crate::net::Net } }"),
    }, 1, "demo/src/: import circle leaf -> net -> shape -> leaf"),
    ("sim/src's layers: error (below chart) imports chart", {
        "sim/src/error.rs": ("pub struct", "use crate::{chart::Font};\npub struct"),
    }, 1, "sim/src/error.rs:2: imports `crate::chart` (crate::chart::Font), a layer above `error`"),
]


def self_test():
    """Runs the check on a small crate written to a temporary folder, with and without circles."""
    import io
    failures = 0
    for name, edits, want_code, want_text in SELF_TEST_CASES:
        with tempfile.TemporaryDirectory() as tmp:
            for rel, text in SELF_TEST_TREE.items():
                if rel in edits:
                    old, new = edits[rel]
                    assert old in text, (rel, old)
                    text = text.replace(old, new, 1)
                (pathlib.Path(tmp) / rel).parent.mkdir(parents=True, exist_ok=True)
                (pathlib.Path(tmp) / rel).write_text(text)
            out = io.StringIO()
            code = main(tmp, out, out)
            good = code == want_code and want_text in out.getvalue()
            failures += not good
            print(f"{'ok  ' if good else 'FAIL'} self-test {name}: exit {code} (want {want_code})")
            print("     " + out.getvalue().rstrip().replace("\n", "\n     "))
            if not good:
                print("     expected the output to contain: " + want_text)
    print(f"\n{'all' if not failures else 'NOT all'} {len(SELF_TEST_CASES)} self-test cases gave the verdict they should")
    return 1 if failures else 0


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
