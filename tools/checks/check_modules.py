#!/usr/bin/env python3
"""Fails when the module graph of a crate has a circle, at any level.

For every folder that is a module (a crate's `src/` and each `src/<mod>/`),
its children are the modules directly inside it (`a.rs` or `a/`). Child A
depends on child B when any file under A names B by a path: `crate::<path to
the folder>::B`, or `super::B` from a file directly inside the folder (or a
`super::super::B` from one level deeper, and so on). Code after a
`#[cfg(test)]` line (the unit-test module at the end of a file) is left out:
tests may reach across. Re-exports count like any other use.

Second rule, the FMU's sibling front ends (`SIBLINGS`): no file under
`fmu/src/fmi3/` names the FMI 2.0 front end (`crate::fmi2`, the old
`crate::ffi`, an `fmi2...` C function or type), and no file under
`fmu/src/fmi2/` names the FMI 3.0 one; both build on the version-neutral
`shell/` and `instance/`, as modelica/Reference-FMUs' `fmi2Functions.c` and
`fmi3Functions.c` build on one `model.h`. Comments and strings do not count
(a message may name the other version's function).

Third rule, layers (LAYERS, `layer_violations`): in a folder listed there, each child
module has a rank, and a child may name only children of a lower rank
(children of one rank are peers that must not name each other); a child
missing from the table is an error too. `src/mpm`: the machinery below the
laws, the laws below the integrators, the integrators below the driver.

Usage: tools/checks/check_modules.py [CRATE_SRC ...]   (default: every crate's src/)
       tools/checks/check_modules.py --self-test
Prints each circle as `crate folder: a -> b -> a`, each sibling import as
`file: names ...`, each import against the layers as `folder: a -> b (layer
...)`, and exits 1 if any.
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


# ---- layers: (crate src, folder) -> {child: rank}; a child names only lower ranks
LAYERS = {
    ("src", "mpm"): {
        "error": 0,
        "machinery": 1,  # grid, node pools, particles, transfer, spin, SIMD
        "laws": 2,  # the physical laws
        "explicit": 3,  # the integrators: peers, none names another
        "implicit_grid": 3,
        "implicit_vertex": 3,
        "driver": 4,  # YarnSim
    },
}


def layer_violations(src, crate):
    """Imports against LAYERS in the crate at `src` (`crate`: its key)."""
    found = []
    for (c, rel), ranks in LAYERS.items():
        folder = src / rel
        if c != crate or not folder.is_dir():
            continue
        graph = edges(src, folder, list(Path(rel).parts))
        name = f"{crate}/{rel}"
        for a in sorted(graph):
            if a not in ranks:
                found.append(f"{name}: {a} has no layer (add it to LAYERS)")
                continue
            for b in sorted(graph[a]):
                rb = ranks.get(b)
                if rb is None:
                    continue
                if rb > ranks[a]:
                    found.append(f"{name}: {a} -> {b} (layer {ranks[a]} names layer {rb} above it)")
                elif rb == ranks[a]:
                    found.append(f"{name}: {a} -> {b} (peers of layer {rb} name each other)")
    return found


def layer_self_test():
    import tempfile
    with tempfile.TemporaryDirectory() as t:
        src = Path(t) / "src"
        m = src / "mpm"
        for d in ("machinery", "laws", "explicit", "implicit_grid", "driver"):
            (m / d).mkdir(parents=True)
            (m / d / "mod.rs").write_text("pub mod x;\n")
        (m / "mod.rs").write_text("pub mod error;\n")
        (m / "error.rs").write_text("pub struct E;\n")
        (m / "machinery" / "x.rs").write_text("use crate::mpm::error::E;\n")
        (m / "laws" / "x.rs").write_text("use crate::mpm::machinery::x;\n// crate::mpm::driver\n")
        (m / "explicit" / "x.rs").write_text("use crate::mpm::laws::x;\n")
        (m / "implicit_grid" / "x.rs").write_text(
            "use crate::mpm::laws::x;\n#[cfg(test)]\nmod t { use crate::mpm::explicit; }\n")
        (m / "driver" / "x.rs").write_text("use crate::mpm::{explicit, implicit_grid};\n")
        assert layer_violations(src, "src") == [], layer_violations(src, "src")
        (m / "machinery" / "x.rs").write_text("use crate::mpm::laws::x;\n")
        (m / "implicit_grid" / "x.rs").write_text("use crate::mpm::explicit::x;\n")
        (m / "laws" / "x.rs").write_text("fn f() { crate::mpm::driver::x::g() }\n")
        (m / "extra.rs").write_text("\n")
        got = layer_violations(src, "src")
        want = ["machinery -> laws", "implicit_grid -> explicit", "laws -> driver",
                "extra has no layer"]
        assert len(got) == 4 and all(any(w in g for g in got) for w in want), got
    print("check_modules layer self-test: ok")


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
    layer_self_test()


# The FMU's FMI front ends: (folder, what no file in it may name).
SIBLINGS = [
    ("fmu/src/fmi3", r"\bcrate::(?:fmi2|ffi)\b|(?<![A-Za-z0-9_:])(?:super::)+fmi2\b|\bfmi2[A-Z][A-Za-z0-9_]*"),
    ("fmu/src/fmi2", r"\bcrate::fmi3\b|(?<![A-Za-z0-9_:])(?:super::)+fmi3\b|\bfmi3[A-Z][A-Za-z0-9_]*"),
]


def sibling_imports(root=ROOT, table=SIBLINGS):
    """Files of one FMI front end that name the other (see SIBLINGS)."""
    found = []
    for folder, pattern in table:
        for f in sorted((root / folder).rglob("*.rs")):
            names = sorted(set(re.findall(pattern, strip(f.read_text()))))
            if names:
                found.append(f"{f.relative_to(root)}: names {', '.join(names)}")
    return found


def self_test_siblings():
    import tempfile
    with tempfile.TemporaryDirectory() as t:
        root = Path(t)
        (root / "fmu/src/fmi2").mkdir(parents=True)
        (root / "fmu/src/fmi3").mkdir(parents=True)
        (root / "fmu/src/fmi2/mod.rs").write_text(
            "use crate::shell::call;\n// fmi3DoStep in a comment\nconst M: &str = \"not fmi3DoStep\";\n")
        (root / "fmu/src/fmi3/mod.rs").write_text(
            "use crate::shell::free_instance;\nconst M: &str = \"made by fmi2Instantiate\";\n")
        assert sibling_imports(root) == [], sibling_imports(root)
        (root / "fmu/src/fmi3/common.rs").write_text(
            "unsafe { crate::ffi::fmi2FreeInstance(i) }\nuse super::super::fmi2::X;\n")
        (root / "fmu/src/fmi2/cosim.rs").write_text("use crate::fmi3::values;\n")
        got = sibling_imports(root)
        assert got == [
            "fmu/src/fmi3/common.rs: names crate::ffi, fmi2FreeInstance, super::super::fmi2",
            "fmu/src/fmi2/cosim.rs: names crate::fmi3",
        ], got
    print("check_modules sibling self-test: ok")


def main(argv):
    if argv[1:] == ["--self-test"]:
        self_test()
        self_test_siblings()
        return 0
    srcs = [Path(a).resolve() for a in argv[1:]] or [ROOT / c for c in CRATES]
    bad = []
    for src in srcs:
        if src.is_dir():
            bad += check(src)
    for b in bad:
        print(f"import circle: {b}")
    siblings = [] if argv[1:] else sibling_imports()
    for b in siblings:
        print(f"FMI front end names its sibling: {b}")
    layered = []
    for src in srcs:
        if src.is_dir() and src.is_relative_to(ROOT):
            layered += layer_violations(src, str(src.relative_to(ROOT)))
    for v in layered:
        print(f"import against the layers: {v}")
    if bad or siblings or layered:
        return 1
    print(f"module graphs of {len(srcs)} crates have no circle and keep their layers"
          + ("" if argv[1:] else "; the FMU's fmi2/ and fmi3/ do not name each other"))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
