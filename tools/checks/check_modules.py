#!/usr/bin/env python3
"""Fails when the module graph of a crate has a circle, at any level.

For every folder that is a module (a crate's `src/` and each `src/<mod>/`),
its children are the modules directly inside it (`a.rs` or `a/`). Child A
depends on child B when any file under A names B by a path: `crate::<path to
the folder>::B`, or `super::B` from a file directly inside the folder (or a
`super::super::B` from one level deeper, and so on). Code after a
`#[cfg(test)]` line (the unit-test module at the end of a file) is left out:
tests may reach across. Re-exports count like any other use.

Usage: tools/checks/check_modules.py [CRATE_SRC ...]   (default: every crate's src/)
       tools/checks/check_modules.py --self-test
Prints each circle as `crate folder: a -> b -> a` and exits 1 if any.
"""
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CRATES = ["src", "cli/src", "evidence/src", "fmu/src", "fmu-pack/src"]
IDENT = r"[A-Za-z_][A-Za-z0-9_]*"


def strip(text):
    """Source without comments, strings, and the trailing test module."""
    m = re.search(r"^\s*#\[cfg\(test\)\]", text, re.M)
    if m:
        text = text[: m.start()]
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r'"(?:\\.|[^"\\])*"', '""', text)
    return text


def child_of(folder, path):
    """The child module of `folder` that the file `path` belongs to."""
    rel = path.relative_to(folder)
    first = rel.parts[0]
    return first[:-3] if first.endswith(".rs") else first


def module_folders(src):
    """Folders that are modules: `src` and every sub-folder holding .rs files."""
    yield src, []
    for d in sorted(src.rglob("*")):
        if d.is_dir() and any(d.glob("*.rs")):
            yield d, list(d.relative_to(src).parts)


def children(folder):
    names = set()
    for p in folder.iterdir():
        if p.is_file() and p.suffix == ".rs" and p.stem not in ("mod", "lib", "main"):
            names.add(p.stem)
        elif p.is_dir() and any(p.rglob("*.rs")):
            names.add(p.name)
    return names


def edges(src, folder, mod_path):
    kids = children(folder)
    graph = {k: set() for k in kids}
    prefix = "crate::" + "".join(m + "::" for m in mod_path)
    for f in folder.rglob("*.rs"):
        if f.name in ("mod.rs", "lib.rs", "main.rs") and f.parent == folder:
            continue
        if "bin" in f.relative_to(src).parts:
            continue
        a = child_of(folder, f)
        if a not in graph:
            continue
        text = strip(f.read_text())
        # depth of the file below the folder, in modules: a.rs -> 1, a/b.rs -> 2
        depth = len(f.relative_to(folder).parts)
        if f.name == "mod.rs":
            depth -= 1
        pats = [re.escape(prefix) + "(" + IDENT + ")"]
        pats.append(r"(?<![A-Za-z0-9_:])" + "super::" * depth + "(" + IDENT + ")")
        # braces: `use crate::x::{a, b}` / `use super::{a, b}`
        for head in (re.escape(prefix), r"(?<![A-Za-z0-9_:])" + "super::" * depth):
            for group in re.findall(head + r"\{([^}]*)\}", text):
                for name in re.findall(r"(?:^|,)\s*(" + IDENT + ")", group):
                    if name in graph and name != a:
                        graph[a].add(name)
        for pat in pats:
            for name in re.findall(pat, text):
                if name in graph and name != a:
                    graph[a].add(name)
    return graph


def cycles(graph):
    """Every elementary circle found by DFS, each reported once (by its node set)."""
    seen, out = set(), []
    colour = {}

    def dfs(n, stack):
        colour[n] = 1
        stack.append(n)
        for m in sorted(graph[n]):
            if colour.get(m) == 1:
                cyc = stack[stack.index(m):] + [m]
                key = frozenset(cyc)
                if key not in seen:
                    seen.add(key)
                    out.append(cyc)
            elif colour.get(m) is None:
                dfs(m, stack)
        stack.pop()
        colour[n] = 2

    for n in sorted(graph):
        if n not in colour:
            dfs(n, [])
    return out


def check(src):
    found = []
    for folder, mod_path in module_folders(src):
        for cyc in cycles(edges(src, folder, mod_path)):
            found.append(f"{folder.relative_to(ROOT) if folder.is_relative_to(ROOT) else folder}: "
                         + " -> ".join(cyc))
    return found


def self_test():
    import tempfile
    with tempfile.TemporaryDirectory() as t:
        src = Path(t) / "src"
        (src / "m").mkdir(parents=True)
        (src / "lib.rs").write_text("pub mod a;\npub mod b;\npub mod m;\n")
        (src / "a.rs").write_text("use crate::b::X;\n")
        (src / "b.rs").write_text("pub struct X;\n#[cfg(test)]\nmod tests { use crate::a; }\n")
        (src / "m" / "mod.rs").write_text("mod p;\nmod q;\n")
        (src / "m" / "p.rs").write_text("use super::{q, other};\n")
        (src / "m" / "q.rs").write_text("// use super::p;\nconst S: &str = \"super::p\";\n")
        assert check(src) == [], check(src)
        (src / "b.rs").write_text("use crate::a; // b -> a\n")
        (src / "m" / "q.rs").write_text("fn f() { crate::m::p::g() }\n")
        got = check(src)
        assert len(got) == 2 and any("a -> b -> a" in g for g in got) \
            and any("p -> q -> p" in g for g in got), got
    print("check_modules self-test: ok")


def main(argv):
    if argv[1:] == ["--self-test"]:
        self_test()
        return 0
    srcs = [Path(a).resolve() for a in argv[1:]] or [ROOT / c for c in CRATES]
    bad = []
    for src in srcs:
        if src.is_dir():
            bad += check(src)
    for b in bad:
        print(f"import circle: {b}")
    if bad:
        return 1
    print(f"module graphs of {len(srcs)} crates have no circle")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
