#!/usr/bin/env python3
"""Checks that the files of each crate depend on each other one way: no import circles.

Every `.rs` file reached from a crate root (`lib.rs`, `main.rs`, `bin/*.rs`) through `mod`
declarations is a node, inline modules (`mod m { ... }`) belonging to their file. File A
depends on file B when A's code names an item that B defines:
- a `use` of an item (`use crate::x::Item;`, `use super::{A, B};`, `use super::*;`);
- a path in code (`crate::x::f()`, `super::Item`, `child::f()`, `alias::f()` after `use x as alias`),
  or in an attribute's string (`#[serde(from = "json::Shape")]`).
A path is resolved along the module tree; a name a module imports or re-exports (`pub use`)
is followed to the file that defines it, so a re-export is a facade, not a dependency of its
own: a `pub use` line counts only when its module's code also uses the name. A `use` of a
module (`use crate::scene;`) counts through the paths that follow it. Comments, strings and
test code (`#[cfg(test)]` items and the files they declare) do not count.

A circle is a strongly connected set of files; each is printed with its files and, for every
dependency inside it, the line that makes it. The same check runs once more on the crate's
top-level modules (a folder such as `solver/` or a file such as `island.rs` beside `lib.rs`):
module A depends on module B when a file of A depends on a file of B, so two folders whose
files import each other one way but in both directions are a circle too. Exits 1 on a circle
of either kind.
Usage: scripts/module-cycles.py [--graph] [CRATE_SRC ...]   (default: every crates/*/src)
       scripts/module-cycles.py --self-test                 (checks this script on fixtures)
"""
import glob
import os
import re
import sys
import tempfile

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
ITEM_KINDS = r"fn|struct|enum|trait|type|const|static|union|macro_rules!"
PATH = IDENT + r"(::" + IDENT + r")*"
# Attribute arguments whose string is a path the code depends on (serde's and the like).
ATTRIBUTE_PATH = r"\b(from|into|try_from|with|serialize_with|deserialize_with|default)\s*=\s*$"


def strip_code(text):
    """The text with comments and the contents of string and char literals blanked, newlines kept."""
    out = []
    i, n = 0, len(text)

    def blank(segment):
        return "".join(c if c == "\n" else " " for c in segment)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
        elif (m := re.compile(r'b?r(#*)"').match(text, i)) and (i == 0 or not re.match(r"\w", text[i - 1])):
            end = '"' + m.group(1)
            j = text.find(end, m.end())
            j = n if j < 0 else j + len(end)
            out.append('""' + blank(text[i + 2 : j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            content = text[i + 1 : j - 1]
            if re.search(ATTRIBUTE_PATH, text[max(0, i - 40) : i]) and re.fullmatch(PATH, content):
                out.append(" " + content + " ")  # a path in an attribute: code, not text
            else:
                out.append('""' + blank(text[i + 2 : j]))
            i = j
        elif c == "'":
            # A char literal ('a', '\n', '\u{1F}'), else a lifetime or label ('a).
            m = re.compile(r"'(\\u\{[0-9a-fA-F]+\}|\\.|[^\\'])'").match(text, i)
            if m:
                out.append("''" + " " * (m.end() - i - 2))
                i = m.end()
            else:
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def item_end(code, start):
    """The end of the item starting at `start`: after its `;` or its balanced `{...}` body."""
    depth, j, n = 0, start, len(code)
    is_use = re.compile(r"\s*(pub(\([^)]*\))?\s+)?use\b").match(code, start) is not None
    while j < n:
        c = code[j]
        if c in "([":
            depth += 1
        elif c in ")]":
            depth -= 1
        elif c == ";" and depth == 0:
            return j + 1
        elif c == "{" and depth == 0 and not is_use:
            level = 0
            while j < n:
                if code[j] == "{":
                    level += 1
                elif code[j] == "}":
                    level -= 1
                    if level == 0:
                        return j + 1
                j += 1
            return n
        j += 1
    return n


def blank_test_items(code):
    """`code` with every `#[cfg(test)]` item (and `#[cfg(all(test, ...))]`) blanked."""
    pattern = re.compile(r"#\[cfg\(([^\]]*)\)\]")
    while True:
        for m in pattern.finditer(code):
            condition = m.group(1)
            if re.search(r"\btest\b", condition) and not re.search(r"not\(\s*test", condition):
                break
        else:
            return code
        j = m.end()
        while (a := re.compile(r"\s*#\[").match(code, j)) :
            j = item_end(code, a.end() - 1)  # skips the attribute's [...]
        end = item_end(code, j)
        code = code[: m.start()] + "".join(c if c == "\n" else " " for c in code[m.start() : end]) + code[end:]


def matching_brace(code, open_index):
    level = 0
    for j in range(open_index, len(code)):
        if code[j] == "{":
            level += 1
        elif code[j] == "}":
            level -= 1
            if level == 0:
                return j
    return len(code) - 1


def line_of(code, index):
    return code.count("\n", 0, index) + 1


def parse_use_tree(text, base_offset):
    """The imports of a `use` tree: (segments, alias or None for a glob, offset of the leaf)."""
    tokens = [(m.group(), m.start() + base_offset) for m in re.finditer(IDENT + r"|::|[{},*]", text)]
    results = []
    position = 0

    def tree(prefix):
        nonlocal position
        path = list(prefix)
        while position < len(tokens):
            token, offset = tokens[position]
            if token == "::":
                position += 1
            elif token == "{":
                position += 1
                while position < len(tokens) and tokens[position][0] != "}":
                    if tokens[position][0] == ",":
                        position += 1
                        continue
                    tree(path)
                position += 1
                return
            elif token == "*":
                position += 1
                results.append((path, None, offset))
                return
            elif token in (",", "}"):
                return
            else:
                position += 1
                if position < len(tokens) and tokens[position][0] == "as":
                    alias = tokens[position + 1][0] if position + 1 < len(tokens) else token
                    position += 2
                    results.append((path + [token], alias, offset))
                    return
                if position < len(tokens) and tokens[position][0] == "::":
                    path.append(token)
                    continue
                if token == "self" and path:
                    results.append((path, path[-1], offset))
                else:
                    results.append((path + [token], token, offset))
                return

    tree([])
    return results


class Module:
    def __init__(self, path, file, child_dir):
        self.path = path  # tuple of names from the crate root
        self.file = file
        self.child_dir = child_dir
        self.children = {}  # name -> module path
        self.defined = set()  # names of items defined here
        self.imports = {}  # name -> (segments, line, is_reexport)
        self.globs = []  # (segments, line, is_reexport)
        self.code = ""  # this module's code, other modules' spans blanked


class Crate:
    def __init__(self, src):
        self.src = src
        self.modules = {}
        self.texts = {}  # file -> code with comments, strings and tests blanked
        # Each root is a crate of its own: the library's modules are the root (), a binary's
        # sit under a name no module can have.
        roots = [os.path.join(src, "lib.rs"), os.path.join(src, "main.rs")]
        roots += sorted(glob.glob(os.path.join(src, "bin", "*.rs")))
        library = os.path.exists(roots[0])
        for path in roots:
            if os.path.exists(path):
                name = "" if path == roots[0] or not library and path == roots[1] else f"<{path}>"
                self.load_file((name,) if name else (), path, os.path.dirname(path))
        self.edges = {}  # (from file, to file) -> [evidence]
        for module in self.modules.values():
            self.collect(module)

    def load_file(self, module_path, file, child_dir):
        with open(file, encoding="utf-8") as f:
            code = blank_test_items(strip_code(f.read()))
        self.texts[file] = code
        self.modules.setdefault(module_path, Module(module_path, file, child_dir))
        spans = []  # inline modules of this file
        owner = [module_path] * len(code)
        for m in re.finditer(r"\bmod\s+(" + IDENT + r")\s*([;{])", code):
            enclosing = owner[m.start()]
            directory = child_dir
            for name in enclosing[len(module_path) :]:
                directory = os.path.join(directory, name)
            name = m.group(1)
            child = enclosing + (name,)
            if m.group(2) == "{":
                close = matching_brace(code, m.end() - 1)
                for k in range(m.end(), close):
                    if len(owner[k]) <= len(enclosing):
                        owner[k] = child
                spans.append(child)
                self.add_module(enclosing, child, file, os.path.join(directory, name))
                continue
            path_file = self.path_attribute(file, m.start())
            if path_file is not None:
                target = os.path.join(os.path.dirname(file), path_file)
                child_directory = os.path.dirname(target)
            else:
                flat = os.path.join(directory, name + ".rs")
                target = flat if os.path.exists(flat) else os.path.join(directory, name, "mod.rs")
                child_directory = os.path.join(directory, name)
            if os.path.exists(target):
                self.add_module(enclosing, child, target, child_directory)
                self.load_file(child, target, child_directory)
        for path in [module_path] + spans:
            self.modules[path].code = "".join(
                c if owner[k] == path or c == "\n" else " " for k, c in enumerate(code)
            )

    def path_attribute(self, file, index):
        with open(file, encoding="utf-8") as f:
            raw = f.read()
        before = strip_code(raw)[:index]
        m = re.search(r"#\[path\s*=\s*\"\"\s*\]\s*$", before)
        if not m:
            return None
        value = re.compile(r'#\[path\s*=\s*"([^"]*)"\s*\]').match(raw, m.start())
        return value.group(1) if value else None

    def add_module(self, parent, child, file, child_dir):
        self.modules[parent].children[child[-1]] = child
        self.modules[child] = Module(child, file, child_dir)

    def collect(self, module):
        code = module.code
        use_spans = []
        for m in re.finditer(r"\b(pub(\s*\([^)]*\))?\s+)?use\s+", code):
            end = code.find(";", m.end())
            end = len(code) if end < 0 else end
            use_spans.append((m.start(), end))
            reexport = m.group(1) is not None
            for segments, alias, offset in parse_use_tree(code[m.end() : end], m.end()):
                if segments and segments[0] == "":
                    continue
                line = line_of(code, offset)
                if alias is None:
                    module.globs.append((segments, line, reexport))
                else:
                    module.imports[alias] = (segments, line, reexport)
        module.use_spans = use_spans
        module.defined = set(re.findall(r"\b(?:" + ITEM_KINDS + r")\s+(" + IDENT + ")", code))

    def resolve(self, module_path, segments, seen=None):
        """(module path of the defining module, is the path a module) or None when external."""
        seen = set() if seen is None else seen
        key = (module_path, tuple(segments))
        if key in seen or not segments:
            return None
        seen.add(key)
        module = self.modules[module_path]
        first, rest = segments[0], list(segments[1:])
        if first == "crate":
            current = self.crate_root(module_path)
        elif first == "self":
            current = module_path
        elif first == "super":
            current = module_path[:-1]
            while rest and rest[0] == "super":
                current, rest = current[:-1], rest[1:]
        elif first in module.children:
            current = module.children[first]
        elif first in module.imports:
            target = self.resolve(module_path, module.imports[first][0], seen)
            if target is None:
                return None
            if not rest:
                return target
            if not target[1]:
                return target  # Item::associated
            current = target[0]
        elif first in module.defined:
            return (module_path, False)
        else:
            return None  # std, an external crate or a local name
        return self.walk(current, rest, seen)

    def walk(self, current, rest, seen):
        while rest and rest[0] in self.modules[current].children:
            current, rest = self.modules[current].children[rest[0]], rest[1:]
        if not rest:
            return (current, True)
        module = self.modules[current]
        name = rest[0]
        if name in module.defined:
            return (current, False)
        if name in module.imports:
            target = self.resolve(current, module.imports[name][0] + rest[1:], seen)
            return target if target is not None else (current, False)
        for segments, _, _ in module.globs:
            target = self.resolve(current, segments, seen)
            if target is not None and target[1]:
                inner = self.walk(target[0], rest, seen)
                if inner is not None and inner[0] != target[0] or name in self.modules[target[0]].defined:
                    return inner
        return (current, False)

    def crate_root(self, module_path):
        return module_path[:1] if module_path[:1] and module_path[0].startswith("<") else ()

    def depends(self, module, target, line, evidence):
        if target is None:
            return
        source_file, target_file = module.file, self.modules[target[0]].file
        if source_file != target_file and target_file is not None:
            self.edges.setdefault((source_file, target_file), []).append((line, evidence))

    def build(self):
        for module in list(self.modules.values()):
            if module.file is None:
                continue
            code = module.code
            outside_uses = list(code)
            for start, end in module.use_spans:
                for k in range(start, end):
                    if outside_uses[k] != "\n":
                        outside_uses[k] = " "
            outside_uses = "".join(outside_uses)
            # A `mod name` declaration names a module, not an item imported under that name.
            outside_uses = re.sub(r"\bmod\s+" + IDENT, lambda m: " " * len(m.group()), outside_uses)
            for alias, (segments, line, reexport) in module.imports.items():
                if reexport and not re.search(r"\b" + re.escape(alias) + r"\b", outside_uses):
                    continue
                target = self.resolve(module.path, segments)
                if target is not None and not target[1]:
                    self.depends(module, target, line, "use " + "::".join(segments))
            for segments, line, reexport in module.globs:
                if reexport:
                    continue
                target = self.resolve(module.path, segments)
                if target is not None:
                    self.depends(module, (target[0], False), line, "use " + "::".join(segments) + "::*")
            for m in re.finditer(r"(?<![\w:])(" + IDENT + r"(?:\s*::\s*" + IDENT + r")+)", outside_uses):
                segments = re.split(r"\s*::\s*", m.group(1))
                target = self.resolve(module.path, segments)
                if target is not None:
                    self.depends(module, (target[0], False), line_of(code, m.start()), "::".join(segments))
        return self.edges

    def relative(self, file):
        return os.path.relpath(file, os.path.dirname(self.src))


def circles(graph):
    """Strongly connected sets of more than one node (Tarjan), each sorted."""
    index, low, stack, on_stack, result = {}, {}, [], set(), []
    nodes = sorted(set(graph) | {b for bs in graph.values() for b in bs})

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, ())):
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
                result.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in nodes:
        if v not in index:
            visit(v)
    return sorted(result)


def shortest_cycle(graph, component):
    """One shortest circle through the first file of `component`, as a list of files."""
    start, members = component[0], set(component)
    parents, frontier = {start: None}, [start]
    while frontier:
        following = []
        for v in frontier:
            for w in sorted(graph.get(v, ())):
                if w == start:
                    path = [v]
                    while parents[path[-1]] is not None:
                        path.append(parents[path[-1]])
                    return list(reversed(path)) + [start]
                if w in members and w not in parents:
                    parents[w] = v
                    following.append(w)
        frontier = following
    return component


def top_level_modules(crate):
    """Each file's top-level module: `solver` for `solver/rows.rs`, `island` for `island.rs`; a
    crate root (`lib.rs`, `main.rs`, `bin/x.rs`) is a node of its own, named by its file."""
    shortest = {}
    for path, module in crate.modules.items():
        if module.file is not None and len(path) < len(shortest.get(module.file, path + ("",))):
            shortest[module.file] = path
    result = {}
    for file, path in shortest.items():
        binary = path[:1] if path[:1] and path[0].startswith("<") else ()
        below = path[len(binary) :]
        # The node's name: the top-level module's file, or its folder when it has one.
        top_file = crate.modules[binary + below[:1]].file
        folder = os.path.join(crate.src, below[0]) if below else None
        result[file] = crate.relative(folder) + "/" if folder and os.path.isdir(folder) else crate.relative(top_file)
    return result


def report_circles(src, graph, evidence_edges, name, kind, out):
    """Prints each circle of `graph` (nodes named by `name`) with the lines that make it."""
    found = circles(graph)
    for component in found:
        cycle = shortest_cycle(graph, component)
        print(f"{src}: circle of {kind}: {' -> '.join(name(f) for f in cycle)}", file=out)
        if len(component) > len(cycle) - 1:
            print(f"  all {kind} of the circle: {', '.join(name(f) for f in component)}", file=out)
        members = set(component)
        for (a, b, where, target), evidence in sorted(evidence_edges.items()):
            if a in members and b in members:
                for line, text in sorted(set(evidence)):
                    print(f"  {where}:{line}: {text}  (-> {target})", file=out)
    return found


def check(src, show_graph=False, out=sys.stdout):
    """Prints `src`'s circles between files and between top-level modules (and the file graph
    if asked); returns the number of circles of both kinds."""
    crate = Crate(src)
    edges = crate.build()
    graph = {}
    for a, b in edges:
        graph.setdefault(a, set()).add(b)
    if show_graph:
        for file in sorted(crate.texts):
            targets = sorted(crate.relative(b) for b in graph.get(file, ()))
            print(f"  {crate.relative(file)} -> {', '.join(targets) or '(nothing)'}", file=out)
    file_evidence = {(a, b, crate.relative(a), crate.relative(b)): e for (a, b), e in edges.items()}
    found = report_circles(src, graph, file_evidence, crate.relative, "files", out)
    top = top_level_modules(crate)
    module_graph, module_evidence = {}, {}
    for (a, b), evidence in edges.items():
        if top[a] != top[b]:
            module_graph.setdefault(top[a], set()).add(top[b])
            module_evidence[(top[a], top[b], crate.relative(a), crate.relative(b))] = evidence
    found_modules = report_circles(src, module_graph, module_evidence, str, "top-level modules", out)
    if not found and not found_modules:
        print(
            f"{src}: {len(crate.texts)} files, {len(edges)} dependencies, "
            f"{len(set(top.values()))} top-level modules, no circles",
            file=out,
        )
    return len(found) + len(found_modules)


FIXTURES = {
    # A circle through `super::` and a re-export; comments, strings and test code do not count.
    "circle": {
        "lib.rs": "mod shape;\nmod validate;\npub use shape::Shape;\n",
        "shape.rs": "use crate::validate::check;\npub struct Shape;\n"
        "pub fn build() -> Shape { check(); Shape }\n",
        "validate.rs": "pub fn check() { let _ = crate::Shape; }\n",
    },
    # A circle through a path in an attribute's string.
    "attribute": {
        "lib.rs": "mod json;\n#[serde(from = \"json::ShapeJson\")]\npub struct Shape;\n",
        "json.rs": "pub struct ShapeJson;\nimpl From<ShapeJson> for super::Shape {}\n",
    },
    # The same files with the shared piece moved one way; the back references live in
    # comments, a string and a test module only.
    "acyclic": {
        "lib.rs": "mod shape;\nmod validate;\npub use shape::Shape;\n#[cfg(test)]\nmod tests;\n",
        "shape.rs": "use crate::validate::check;\npub struct Shape;\n"
        "pub fn build() -> Shape { check(); Shape }\n",
        "validate.rs": "// crate::shape::Shape\n/// [`crate::Shape`]\npub fn check() {\n"
        "    let _ = \"crate::Shape\";\n}\n#[cfg(test)]\nmod tests {\n    use crate::shape::Shape;\n}\n",
        "tests.rs": "use crate::validate::check;\nuse crate::Shape;\n",
    },
    # Sub-modules: a circle between a parent's mod.rs and its child through `super::*`.
    "nested": {
        "main.rs": "mod plot;\nfn main() {}\n",
        "plot/mod.rs": "mod axis;\nuse axis::Ticks;\npub struct Plot { ticks: Ticks }\n",
        "plot/axis.rs": "use super::*;\npub struct Ticks;\nfn of(p: &Plot) {}\n",
    },
    # A parent re-exporting its children's items (a facade) is not in a circle with them.
    "facade": {
        "lib.rs": "pub mod solver;\n",
        "solver/mod.rs": "mod pgs;\nmod sweep;\npub use pgs::solve;\npub use sweep::Sweep;\n",
        "solver/sweep.rs": "pub struct Sweep;\n",
        "solver/pgs.rs": "use super::Sweep;\npub fn solve(_: Sweep) {}\n",
    },
    # Files one way, folders both ways: `a/x.rs` uses `b/p.rs`, `b/q.rs` uses `a/y.rs`.
    "folders": {
        "lib.rs": "mod a;\nmod b;\n",
        "a/mod.rs": "mod x;\npub mod y;\n",
        "a/x.rs": "use crate::b::p::P;\nfn f(_: P) {}\n",
        "a/y.rs": "pub struct Y;\n",
        "b/mod.rs": "pub mod p;\nmod q;\n",
        "b/p.rs": "pub struct P;\n",
        "b/q.rs": "use crate::a::y::Y;\nfn g(_: Y) {}\n",
    },
    # The same folders with the shared type moved below both (a file beside lib.rs).
    "folders-one-way": {
        "lib.rs": "mod a;\nmod b;\nmod shared;\n",
        "a/mod.rs": "mod x;\n",
        "a/x.rs": "use crate::b::p::P;\nfn f(_: P) {}\n",
        "b/mod.rs": "pub mod p;\nmod q;\n",
        "b/p.rs": "pub struct P;\n",
        "b/q.rs": "use crate::shared::Y;\nfn g(_: Y) {}\n",
        "shared.rs": "pub struct Y;\n",
    },
}
# A circle between files of two top-level modules is a circle of both kinds.
EXPECTED = {"circle": 2, "attribute": 2, "acyclic": 0, "nested": 1, "facade": 0, "folders": 1, "folders-one-way": 0}


def self_test():
    failures = 0
    for name, files in FIXTURES.items():
        with tempfile.TemporaryDirectory() as directory:
            src = os.path.join(directory, name, "src")
            for path, text in files.items():
                os.makedirs(os.path.dirname(os.path.join(src, path)), exist_ok=True)
                with open(os.path.join(src, path), "w", encoding="utf-8") as f:
                    f.write(text)
            found = check(src, out=open(os.devnull, "w"))
        status = "ok" if found == EXPECTED[name] else "FAILED"
        failures += status != "ok"
        print(f"self-test {name}: {found} circle(s), expected {EXPECTED[name]}: {status}")
    return failures


def main(args):
    if args == ["--self-test"]:
        return 1 if self_test() else 0
    show_graph = "--graph" in args
    sources = [a for a in args if a != "--graph"] or sorted(glob.glob("crates/*/src"))
    found = sum(check(src.rstrip("/"), show_graph) for src in sources)
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
