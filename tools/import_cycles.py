#!/usr/bin/env python3
"""Finds import circles between the source files of the workspace's crates.

A file that takes a name defined in another file of the same crate (by `use crate::…`,
`use super::…`, `use self::…`, a `use` of a child module, or such a path written in code)
has an arrow to that file; a circle is a strongly connected set of two or more files
(Tarjan's algorithm). Re-exports are not followed: an importer of `crate::Name`, where
`lib.rs` has `pub use child::Name`, has its arrow to `lib.rs`, the file it names, not to the
file that defines `Name`; the re-export itself hands the name on and is not a use of it, so
it gives the re-exporting file no arrow (its other imports and paths in its code do). So a
file that takes names through its parent's re-exports while the parent's code uses it is a
circle. A glob import (`use super::*`) ties the file to the files that define, or re-export,
the identifiers it uses from the glob's module.

Arrows between crates are not followed: the crate graph is acyclic, so a circle stays inside
one crate. The crate roots are the `lib.rs` and `main.rs` of each source directory; modules
are found from their `mod name;` declarations.

Usage: python3 tools/import_cycles.py [--exclude PATH]... [SRC_DIR ...]

The source directories default to those of every crate of the workspace. `--exclude PATH`
drops the files under PATH (relative to the current directory) from the graph. Prints each
circle with the names that tie it and exits with status 1 if there is one, 0 otherwise.
Python 3 standard library only.
"""

import argparse
import os
import re
import sys

DEFAULT_DIRS = ["runtime/src", "symbolic/src", "jit/src", "macros/src", "src", "description/src", "python/src"]
ITEM_KEYWORDS = {"fn", "struct", "enum", "trait", "type", "const", "static", "union"}
TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*|::|[{}();,*!#=<>\[\]]|.", re.S)


def strip(source):
    """The source with comments, string and character literals replaced by spaces."""
    out = []
    i, n = 0, len(source)
    while i < n:
        c = source[i]
        nxt = source[i + 1] if i + 1 < n else ""
        if c == "/" and nxt == "/":
            j = source.find("\n", i)
            i = n if j < 0 else j
            continue
        if c == "/" and nxt == "*":
            depth, i = 1, i + 2
            while i < n and depth:
                if source.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif source.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
            out.append(" ")
            continue
        raw = re.match(r'b?r(#*)"', source[i:i + 260])
        if raw and (i == 0 or not (source[i - 1].isalnum() or source[i - 1] == "_")):
            end = '"' + raw.group(1)
            j = source.find(end, i + raw.end())
            i = n if j < 0 else j + len(end)
            out.append(' "" ')
            continue
        if c == '"' or (c == "b" and nxt == '"' and (i == 0 or not source[i - 1].isalnum())):
            i += 1 if c == '"' else 2
            while i < n and source[i] != '"':
                i += 2 if source[i] == "\\" else 1
            i += 1
            out.append(' "" ')
            continue
        if c == "'":
            char = re.match(r"'(\\.[^']*|[^\\'])'", source[i:i + 12])
            if char:
                i += char.end()
                out.append(" ' ")
                continue
            i += 1  # a lifetime
            out.append(" ")
            continue
        out.append(c)
        i += 1
    return "".join(out)


def tokens(source):
    return [t for t in TOKEN.findall(strip(source)) if not t.isspace()]


class Scope:
    """A module's body in a file: the file module itself or an inline `mod name { … }`."""

    def __init__(self, module, depth):
        self.module = module
        self.depth = depth


class FileInfo:
    def __init__(self, path, module, crate):
        self.path = path
        self.module = module
        self.crate = crate
        self.uses = []  # (context module, use tree as (path, alias or None, glob), public)
        self.code_paths = []  # (context module, path)
        self.idents = set()
        self.code_idents = set()  # identifiers outside the `use` declarations
        self.child_files = []  # (name, context module)


def parse_use_tree(toks, i, prefix, out):
    """Parses a use tree at toks[i]; appends (path, alias, glob) to out; returns the index
    after the tree."""
    path = list(prefix)
    while i < len(toks):
        t = toks[i]
        if t == "::":
            i += 1
        elif t == "{":
            i += 1
            while i < len(toks) and toks[i] != "}":
                i = parse_use_tree(toks, i, path, out)
                if i < len(toks) and toks[i] == ",":
                    i += 1
            return i + 1
        elif t == "*":
            out.append((path, None, True))
            return i + 1
        elif re.match(r"[A-Za-z_]", t):
            path.append(t)
            i += 1
            if i < len(toks) and toks[i] == "as":
                out.append((path, toks[i + 1], False))
                return i + 2
            if i >= len(toks) or toks[i] != "::":
                out.append((path, None, False))
                return i
        else:
            return i
    return i


def skip_test_items(toks):
    """The tokens without the items marked `#[cfg(test)]` (test modules and helpers): code
    compiled for the tests only does not constrain the library's layering."""
    out = []
    i = 0
    while i < len(toks):
        if toks[i:i + 7] == ["#", "[", "cfg", "(", "test", ")", "]"]:
            i += 7
            while i < len(toks) and toks[i] == "#":  # further attributes
                depth, i = 0, i + 1
                while i < len(toks):
                    depth += {"[": 1, "]": -1}.get(toks[i], 0)
                    i += 1
                    if depth == 0:
                        break
            depth = 0
            while i < len(toks):
                t = toks[i]
                i += 1
                if t in "([{":
                    depth += 1
                elif t in ")]}":
                    depth -= 1
                    if depth == 0 and t == "}":
                        break
                elif t == ";" and depth == 0:
                    break
            continue
        out.append(toks[i])
        i += 1
    return out


def scan(info, source):
    """Collects the items, `mod` declarations, `use` trees and `crate::`/`super::`/`self::`
    paths of one file, leaving out what is compiled for the tests only."""
    toks = skip_test_items(tokens(source))
    info.idents = {t for t in toks if re.match(r"[A-Za-z_]", t)}
    definitions = {}  # module -> set of names
    use_spans = []  # token ranges of the `use` declarations
    modules = []  # inline modules (module path)
    scopes = [Scope(info.module, 0)]
    depth = 0
    i = 0
    pending_inline = None
    while i < len(toks):
        t = toks[i]
        scope = scopes[-1]
        at_item_level = depth == scope.depth
        if t == "{":
            depth += 1
            if pending_inline is not None:
                scopes.append(Scope(pending_inline, depth))
                pending_inline = None
            i += 1
            continue
        if t == "}":
            if depth == scope.depth and len(scopes) > 1:
                scopes.pop()
            depth -= 1
            i += 1
            continue
        if t == "use" and (i == 0 or toks[i - 1] != "::"):
            public = i > 0 and (toks[i - 1] == "pub" or toks[i - 1] == ")")
            trees = []
            j = parse_use_tree(toks, i + 1, [], trees)
            for tree in trees:
                info.uses.append((scope.module, tree, public))
            use_spans.append((i, j))
            i = j
            continue
        if at_item_level and t == "mod" and i + 2 < len(toks):
            name = toks[i + 1]
            if toks[i + 2] == ";":
                info.child_files.append((name, scope.module))
                definitions.setdefault(scope.module, set())
            elif toks[i + 2] == "{":
                pending_inline = scope.module + (name,)
                modules.append(pending_inline)
            i += 2
            continue
        if at_item_level and t in ITEM_KEYWORDS and i + 1 < len(toks):
            name = toks[i + 1]
            if t == "const" and name == "fn":
                name = toks[i + 2]
            if re.match(r"[A-Za-z_]", name) and name not in ("fn", "unsafe", "extern"):
                definitions.setdefault(scope.module, set()).add(name)
        if at_item_level and t == "macro_rules" and i + 2 < len(toks) and toks[i + 1] == "!":
            definitions.setdefault(scope.module, set()).add(toks[i + 2])
        if t in ("crate", "super", "self") and i + 1 < len(toks) and toks[i + 1] == "::":
            if i > 0 and toks[i - 1] == "::":
                i += 1
                continue
            path = [t]
            j = i + 1
            while j + 1 < len(toks) and toks[j] == "::" and re.match(r"[A-Za-z_]", toks[j + 1]):
                path.append(toks[j + 1])
                j += 2
            info.code_paths.append((scope.module, path))
            i = j
            continue
        i += 1
    in_use = set()
    for a, b in use_spans:
        in_use.update(range(a, b))
    info.code_idents = {t for n, t in enumerate(toks)
                        if n not in in_use and re.match(r"[A-Za-z_]", t)}
    return definitions, modules


class Crate:
    def __init__(self, name):
        self.name = name
        self.module_files = {}  # module path -> file path
        self.items = {}  # (module, name) -> file path
        self.imports = {}  # module -> list of (path, alias, glob, context module, file, public)
        self.files = {}  # file path -> FileInfo
        # (re-exporting file, name) -> where the name comes from: a file's own code that uses
        # a name it re-exports takes it from there.
        self.reexported = {}


def load_crate(root_file, crate_name, excluded):
    crate = Crate(crate_name)
    queue = [(root_file, ())]
    while queue:
        path, module = queue.pop()
        if path in crate.files or excluded(path):
            continue
        info = FileInfo(path, module, crate)
        with open(path, encoding="utf-8") as f:
            definitions, inline = scan(info, f.read())
        crate.files[path] = info
        crate.module_files[module] = path
        for m in inline:
            crate.module_files[m] = path
        for m, names in definitions.items():
            for name in names:
                crate.items[(m, name)] = path
        base = os.path.dirname(path)
        stem = os.path.splitext(os.path.basename(path))[0]
        own_dir = base if stem in ("lib", "main", "mod") else os.path.join(base, stem)
        for name, context in info.child_files:
            directory = os.path.join(own_dir, *context[len(module):])
            for candidate in (os.path.join(directory, name + ".rs"),
                              os.path.join(directory, name, "mod.rs")):
                if os.path.exists(candidate):
                    queue.append((candidate, context + (name,)))
                    break
        for context, (upath, alias, glob), _public in info.uses:
            key = alias if alias else (upath[-1] if upath and not glob else None)
            crate.imports.setdefault(context, []).append(
                (upath, key, glob, context, path, _public))
    return crate


def start_module(crate, context, first):
    """The module a path beginning with `first` starts from, or None (another crate)."""
    if first == "crate":
        return ()
    if first == "self":
        return context
    if first == "super":
        return context[:-1]
    if context + (first,) in crate.module_files:
        return context + (first,)
    return None


def resolve_path(crate, context, path, seen):
    """Resolves a path used in module `context` to ("module", module) or ("item", file, name),
    or None when it leaves the crate."""
    if not path:
        return None
    first = path[0]
    module = start_module(crate, context, first)
    rest = path[1:]
    if module is None:
        # A name imported into `context` (a module alias, or an item whose associated
        # item the path names).
        target = resolve_name(crate, context, first, seen)
        if target is None:
            return None
        if target[0] == "item":
            return target
        module = target[1]
    elif first == "super":
        while rest and rest[0] == "super":
            module = module[:-1]
            rest = rest[1:]
    for k, seg in enumerate(rest):
        if module + (seg,) in crate.module_files:
            module = module + (seg,)
            continue
        target = resolve_name(crate, module, seg, seen)
        if target is None:
            return None
        if target[0] == "item":
            return target
        module = target[1]
    return ("module", module)


def resolve_name(crate, module, name, seen):
    """Where `name`, as seen from `module`, is defined: ("item", file, name), ("module", m)
    or None."""
    key = (module, name)
    if key in seen:
        return None
    seen = seen | {key}
    if module + (name,) in crate.module_files:
        return ("module", module + (name,))
    if key in crate.items:
        return ("item", crate.items[key], name)
    for upath, alias, glob, context, file, public in crate.imports.get(module, []):
        if glob:
            continue
        if alias == name:
            if upath[-1] == "self":
                upath = upath[:-1]
            target = resolve_path(crate, context, upath, seen)
            # A re-exported item is taken from the file that re-exports it.
            if public and target and target[0] == "item":
                crate.reexported[(file, name)] = target
                return ("item", file, name)
            return target
    for upath, alias, glob, context, file, public in crate.imports.get(module, []):
        if glob:
            target = resolve_path(crate, context, upath, seen)
            if target and target[0] == "module":
                found = resolve_name(crate, target[1], name, seen)
                if found:
                    if public and found[0] == "item":
                        crate.reexported[(file, name)] = found
                        return ("item", file, name)
                    return found
    return None


def arrows(crate):
    """The arrows `file -> {other file: names}` of one crate."""
    edges = {}

    def add(src, target):
        if not target or target[0] != "item":
            return
        # A name taken through a re-export ties the importer both to the file it names and
        # to the file that defines the name (for a file's own re-export, to the latter alone).
        origin = target
        while (origin[1], origin[2]) in crate.reexported:
            origin = crate.reexported[(origin[1], origin[2])]
        for t in {target, origin}:
            if t[1] != src:
                edges.setdefault(src, {}).setdefault(t[1], set()).add(t[2])

    for path, info in crate.files.items():
        named = {alias if alias else upath[-1]
                 for _context, (upath, alias, glob), _public in info.uses if upath and not glob}
        for context, (upath, alias, glob), public in info.uses:
            if upath and upath[-1] == "self":
                upath = upath[:-1]
            target = resolve_path(crate, context, upath, frozenset())
            if target is None:
                continue
            if glob:
                if target[0] != "module":
                    continue
                for ident in info.code_idents if public else info.idents:
                    # A name the file defines or imports by name shadows the glob's.
                    if crate.items.get((info.module, ident)) == path or ident in named:
                        continue
                    add(path, resolve_name(crate, target[1], ident, frozenset()))
            elif not public:
                add(path, target)
            else:
                # A re-export is no use of the name; the file's own code using it is.
                name = alias if alias else upath[-1]
                if name in info.code_idents:
                    add(path, target)
        for context, cpath in info.code_paths:
            add(path, resolve_path(crate, context, cpath, frozenset()))
    return edges


def strongly_connected(nodes, edges):
    """Tarjan's algorithm (iterative); the components of two or more nodes."""
    index, low, on_stack, stack, result = {}, {}, set(), [], []
    counter = [0]
    for root in nodes:
        if root in index:
            continue
        work = [(root, iter(sorted(edges.get(root, {}))))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, {})))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    result.append(sorted(component))
    return result


def find_circles(src_dirs, excluded_prefixes=()):
    """The circles of the crates under `src_dirs`: a list of (component, edges inside it)."""
    prefixes = [os.path.normpath(p) for p in excluded_prefixes]

    def excluded(path):
        path = os.path.normpath(path)
        return any(path == p or path.startswith(p + os.sep) for p in prefixes)

    circles = []
    for directory in src_dirs:
        for root in ("lib.rs", "main.rs"):
            root_file = os.path.join(directory, root)
            if not os.path.exists(root_file):
                continue
            crate = load_crate(root_file, root_file, excluded)
            edges = arrows(crate)
            for component in strongly_connected(sorted(crate.files), edges):
                inside = {
                    (a, b): sorted(names)
                    for a in component
                    for b, names in edges.get(a, {}).items()
                    if b in component
                }
                circles.append((component, inside))
    return circles


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("dirs", nargs="*", help="crate source directories")
    parser.add_argument("--exclude", action="append", default=[], metavar="PATH",
                        help="leave the files under PATH out of the graph")
    args = parser.parse_args(argv)
    dirs = args.dirs or DEFAULT_DIRS
    missing = [d for d in dirs if not os.path.isdir(d)]
    if missing:
        print(f"import_cycles: no such directory: {', '.join(missing)}", file=sys.stderr)
        return 2
    circles = find_circles(dirs, args.exclude)
    for component, inside in circles:
        print(f"import circle of {len(component)} files: {', '.join(component)}")
        for (a, b), names in sorted(inside.items()):
            print(f"  {a} -> {b}: {', '.join(names)}")
    if circles:
        print(f"{len(circles)} import circle(s)")
        return 1
    print(f"no import circle in {', '.join(dirs)}"
          + (f" (excluding {', '.join(args.exclude)})" if args.exclude else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
