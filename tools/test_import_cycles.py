#!/usr/bin/env python3
"""Tests of tools/import_cycles.py on small synthetic crates written to a temporary
directory. Run: python3 tools/test_import_cycles.py (standard library only)."""

import contextlib
import io
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import import_cycles  # noqa: E402


def write_tree(root, files):
    for path, text in files.items():
        full = os.path.join(root, path)
        os.makedirs(os.path.dirname(full), exist_ok=True)
        with open(full, "w", encoding="utf-8") as f:
            f.write(text)


def run(files, *args):
    """Writes `files` under a temporary `src/`, runs the checker on it and returns
    (exit status, output)."""
    with tempfile.TemporaryDirectory() as root:
        write_tree(root, files)
        out = io.StringIO()
        cwd = os.getcwd()
        os.chdir(root)
        try:
            with contextlib.redirect_stdout(out):
                status = import_cycles.main(["src", *args])
        finally:
            os.chdir(cwd)
        return status, out.getvalue()


# A crate whose lib.rs re-exports its children's names: `b` takes `crate::A`, which is
# defined in `a.rs`, and `a` takes nothing back. Re-exports, a glob import, comments,
# strings and a test module that imports the other way must not make a circle.
LAYERED = {
    "src/lib.rs": "mod a;\nmod b;\nmod c;\npub use a::A;\npub use b::{B, helper};\n"
                  "pub use c::*;\n",
    "src/a.rs": "//! Mentions crate::b::B in a comment only.\n"
                "pub struct A;\n"
                "pub fn make() -> &'static str { \"crate::b::B in a string\" }\n"
                "#[cfg(test)]\nmod tests {\n    use crate::b::B;\n    fn t(_: B) {}\n}\n",
    "src/b.rs": "use crate::A;\npub struct B(pub A);\npub fn helper() {}\n",
    "src/c/mod.rs": "mod d;\npub use d::D;\n",
    "src/c/d.rs": "use super::super::*;\npub struct D(pub B);\n",
}


class ImportCycles(unittest.TestCase):
    def test_layered_crate_has_no_circle(self):
        status, out = run(LAYERED)
        self.assertEqual(status, 0, out)
        self.assertIn("no import circle", out)

    def test_a_reexported_name_ties_to_the_file_named_and_the_file_defining_it(self):
        with tempfile.TemporaryDirectory() as root:
            write_tree(root, LAYERED)
            cwd = os.getcwd()
            os.chdir(root)
            try:
                crate = import_cycles.load_crate("src/lib.rs", "src/lib.rs", lambda p: False)
                edges = import_cycles.arrows(crate)
            finally:
                os.chdir(cwd)
        # `crate::A` and, through the glob, `B`: to lib.rs, which names them, and to the
        # files that define them; D is d.rs's own.
        self.assertEqual(edges["src/c/d.rs"], {"src/lib.rs": {"B"}, "src/b.rs": {"B"}})
        self.assertEqual(edges["src/b.rs"], {"src/lib.rs": {"A"}, "src/a.rs": {"A"}})
        # A re-export hands names on and uses none: lib.rs and c/mod.rs have no arrows.
        self.assertNotIn("src/lib.rs", edges)
        self.assertNotIn("src/c/mod.rs", edges)
        # The comment, the string and the test module of a.rs are not imports.
        self.assertNotIn("src/a.rs", edges)

    def test_siblings_through_their_parents_reexports_are_a_circle(self):
        files = dict(LAYERED)
        # a.rs now takes `B` (through the root's re-export) and `D` by a path in code
        # (through a grouped use of the module): a -> b -> a, and a -> d -> b -> a.
        files["src/a.rs"] = ("use crate::{B, c::{self as cc}};\npub struct A;\n"
                             "pub fn f(_: B) { let _ = crate::c::D; let _ = cc::D; }\n")
        status, out = run(files)
        self.assertEqual(status, 1, out)
        self.assertIn("import circle of 3 files: src/a.rs, src/b.rs, src/c/d.rs", out)
        self.assertIn("src/a.rs -> src/b.rs: B", out)
        self.assertIn("src/a.rs -> src/c/d.rs: D", out)
        self.assertIn("src/b.rs -> src/a.rs: A", out)

    def test_a_file_through_its_parents_reexport_is_a_circle_when_the_parent_uses_it(self):
        files = dict(LAYERED)
        # lib.rs's own code now uses `A` (which it re-exports from a.rs) and b.rs's `B` by
        # a path; b.rs takes `A` through lib.rs: lib -> b -> lib, and lib -> a.
        files["src/lib.rs"] = (LAYERED["src/lib.rs"]
                               + "pub fn make() -> crate::b::B { crate::b::B(A) }\n")
        status, out = run(files)
        self.assertEqual(status, 1, out)
        self.assertIn("import circle of 2 files: src/b.rs, src/lib.rs", out)
        self.assertIn("src/b.rs -> src/lib.rs: A", out)
        self.assertIn("src/lib.rs -> src/b.rs: B", out)
        # a.rs imports nothing: it is in no circle.
        self.assertNotIn("src/a.rs ->", out)

    def test_super_path_in_code_and_exclusion(self):
        files = {
            "src/lib.rs": "mod x;\nmod y;\n",
            "src/x.rs": "pub fn fx() { super::y::fy(); }\n",
            "src/y.rs": "pub fn fy() {}\npub fn g() { self::fy(); crate::x::fx(); }\n",
        }
        status, out = run(files)
        self.assertEqual(status, 1, out)
        self.assertIn("src/x.rs -> src/y.rs: fy", out)
        self.assertIn("src/y.rs -> src/x.rs: fx", out)
        status, out = run(files, "--exclude", "src/y.rs")
        self.assertEqual(status, 0, out)

    def test_tarjan_finds_separate_components(self):
        edges = {1: {2: 0}, 2: {1: 0}, 3: {4: 0}, 4: {5: 0}, 5: {3: 0}, 6: {1: 0}}
        components = import_cycles.strongly_connected([1, 2, 3, 4, 5, 6], edges)
        self.assertEqual(sorted(components), [[1, 2], [3, 4, 5]])


if __name__ == "__main__":
    unittest.main()
