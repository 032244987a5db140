#!/usr/bin/env python3
"""Check the relative links of the repository's Markdown files.

Fails (exit code 1, one line per broken link, `file:line: target: reason`)
on a relative link or image whose file or folder does not exist, and on a
`#anchor` (in the same page or in another Markdown file) that matches no
heading there. Anchors are GitHub's heading slugs: lower case, markup and
punctuation dropped, spaces turned into hyphens, `-1`, `-2`, ... appended
to repeated slugs. External links (`https:`, `mailto:`, ...) are not
checked. Links inside code blocks and code spans are not links.

Usage:
    python3 tools/checks/check_links.py              # every tracked *.md file
    python3 tools/checks/check_links.py FILE.md ...  # only these files
    python3 tools/checks/check_links.py --self-test  # the checker's own tests

Python 3.11, standard library only.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import unicodedata
from pathlib import Path
from urllib.parse import unquote

FENCE = re.compile(r"^ {0,3}(`{3,}|~{3,})")
HEADING = re.compile(r"^ {0,3}(#{1,6})[ \t]+(.*?)[ \t]*#*[ \t]*$")
# Inline links and images: [text](target "title") / ![alt](target).
# Text may hold one level of nested brackets (an image inside a link).
INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]\(\s*(<[^>]*>|[^\s()]*(?:\([^\s()]*\)[^\s()]*)*)(?:\s+\"[^\"]*\")?\s*\)")
# Reference definitions: [label]: target
REFDEF = re.compile(r"^ {0,3}\[[^\]]+\]:\s+(<[^>]*>|\S+)")
CODE_SPAN = re.compile(r"(`+)(?:.+?)\1")
HTML_ANCHOR = re.compile(r"<a\s+(?:name|id)=\"([^\"]+)\"", re.I)
SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def slug(text: str) -> str:
    """GitHub's anchor for a heading's text."""
    # Drop inline markup the way GitHub renders it: images and links keep
    # their text, code spans keep their content, emphasis markers go.
    text = re.sub(r"!\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = re.sub(r"<[^>]+>", "", text)
    text = text.lower()
    out = []
    for ch in text:
        if ch == " ":
            out.append("-")
        elif ch == "-" or ch == "_":
            out.append(ch)
        elif ch.isalnum():
            out.append(ch)
        else:
            cat = unicodedata.category(ch)
            if cat.startswith("L") or cat.startswith("N") or cat == "Mn":
                out.append(ch)
    return "".join(out)


def strip_code_spans(line: str) -> str:
    return CODE_SPAN.sub(lambda m: " " * len(m.group(0)), line)


def scan(text: str) -> tuple[list[tuple[int, str]], set[str]]:
    """(links as (line number, target), anchors) of a Markdown text."""
    links: list[tuple[int, str]] = []
    anchors: set[str] = set()
    seen: dict[str, int] = {}
    fence: str | None = None
    for number, line in enumerate(text.splitlines(), start=1):
        m = FENCE.match(line)
        if fence is not None:
            if m and m.group(1)[0] == fence[0] and len(m.group(1)) >= len(fence):
                fence = None
            continue
        if m:
            fence = m.group(1)
            continue
        h = HEADING.match(line)
        if h:
            base = slug(h.group(2))
            n = seen.get(base, 0)
            anchors.add(base if n == 0 else f"{base}-{n}")
            seen[base] = n + 1
        for a in HTML_ANCHOR.findall(line):
            anchors.add(a)
        plain = strip_code_spans(line)
        for lm in INLINE.finditer(plain):
            target = lm.group(1)
            if target.startswith("<") and target.endswith(">"):
                target = target[1:-1]
            links.append((number, target))
        rm = REFDEF.match(plain)
        if rm:
            target = rm.group(1)
            if target.startswith("<") and target.endswith(">"):
                target = target[1:-1]
            links.append((number, target))
    return links, anchors


class Checker:
    def __init__(self, root: Path):
        self.root = root.resolve()
        self.anchor_cache: dict[Path, set[str]] = {}

    def anchors_of(self, path: Path) -> set[str]:
        path = path.resolve()
        if path not in self.anchor_cache:
            self.anchor_cache[path] = scan(path.read_text(encoding="utf-8"))[1]
        return self.anchor_cache[path]

    def check_file(self, path: Path) -> list[str]:
        text = path.read_text(encoding="utf-8")
        links, anchors = scan(text)
        self.anchor_cache[path.resolve()] = anchors
        shown = os.path.relpath(path, self.root) if path.resolve().is_relative_to(self.root) else str(path)
        errors = []
        for number, target in links:
            reason = self.check_link(path, target, anchors)
            if reason:
                errors.append(f"{shown}:{number}: {target}: {reason}")
        return errors

    def check_link(self, page: Path, target: str, anchors: set[str]) -> str | None:
        if not target:
            return "empty link target"
        if SCHEME.match(target) or target.startswith("//"):
            return None  # external (https:, mailto:, ...): not checked
        file_part, _, anchor = target.partition("#")
        file_part = unquote(file_part.split("?", 1)[0])
        anchor = unquote(anchor)
        if file_part == "":
            if anchor not in anchors:
                return f"no heading with anchor #{anchor} in this page"
            return None
        if file_part.startswith("/"):
            dest = self.root / file_part.lstrip("/")
        else:
            dest = page.parent / file_part
        if not dest.exists():
            return "no such file or folder"
        if not dest.resolve().is_relative_to(self.root):
            return "points outside the repository"
        if anchor:
            if dest.is_file() and dest.suffix.lower() == ".md":
                if anchor not in self.anchors_of(dest):
                    return f"no heading with anchor #{anchor} in {file_part}"
            elif dest.is_dir():
                return "an anchor on a folder"
        return None


def tracked_markdown(root: Path) -> list[Path]:
    try:
        out = subprocess.run(
            ["git", "ls-files", "-z", "--cached", "--", "*.md"],
            cwd=root, check=True, capture_output=True,
        ).stdout.decode("utf-8")
        names = [n for n in out.split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = [str(p.relative_to(root)) for p in root.rglob("*.md")
                 if "target" not in p.parts and not any(s.startswith(".") for s in p.parts)]
    # a file deleted in the work tree but still in the index is not checked
    return [root / n for n in sorted(names) if (root / n).is_file()]


def run(root: Path, files: list[Path]) -> int:
    checker = Checker(root)
    errors = []
    for f in files:
        errors.extend(checker.check_file(f))
    for e in errors:
        print(f"error: {e}", file=sys.stderr)
    if errors:
        print(f"{len(errors)} broken link(s) in {len(files)} Markdown file(s)", file=sys.stderr)
        return 1
    print(f"links: {len(files)} Markdown file(s), every relative link and anchor resolves")
    return 0


def self_test() -> int:
    cases = {
        "Hello World": "hello-world",
        "The `yarnsim` command line": "the-yarnsim-command-line",
        'Adaptive substeps (`[time] dt = "auto"`)': "adaptive-substeps-time-dt--auto",
        "YarnBundle: the FMI 2.0 Co-Simulation FMU": "yarnbundle-the-fmi-20-co-simulation-fmu",
        "Skip what a scene doesn't need (`yarnsim bench skip`)": "skip-what-a-scene-doesnt-need-yarnsim-bench-skip",
        "Physical oracles (`tests/yarn_oracles.rs`, release)": "physical-oracles-testsyarn_oraclesrs-release",
        "Müller et al. 2007": "müller-et-al-2007",
        "A [link](x.md) here": "a-link-here",
    }
    failures = []
    for text, want in cases.items():
        got = slug(text)
        if got != want:
            failures.append(f"slug({text!r}) = {got!r}, expected {want!r}")
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        (root / "docs").mkdir()
        (root / "src").mkdir()
        (root / "src" / "lib.rs").write_text("// x\n")
        (root / "docs" / "b.md").write_text("# Page B\n\n## Same\n\n## Same\n\n```sh\n# not a heading\n```\n")
        (root / "README.md").write_text(
            "# Top\n\n## Part one\n\n"
            "[ok file](src/lib.rs) [ok dir](docs/) [ok anchor](#part-one)\n"
            "[ok other](docs/b.md#same-1) ![img](docs/b.md) [ext](https://example.org/x)\n"
            "`[not a link](nope.rs)`\n\n"
            "```md\n[in code](nope.rs)\n```\n\n"
            "[missing file](src/nope.rs)\n"
            "[missing anchor](#part-two)\n"
            "[missing other anchor](docs/b.md#not-a-heading)\n"
            "[repeat past the end](docs/b.md#same-2)\n"
        )
        checker = Checker(root)
        errors = checker.check_file(root / "README.md")
        want = [
            "README.md:13: src/nope.rs: no such file or folder",
            "README.md:14: #part-two: no heading with anchor #part-two in this page",
            "README.md:15: docs/b.md#not-a-heading: no heading with anchor #not-a-heading in docs/b.md",
            "README.md:16: docs/b.md#same-2: no heading with anchor #same-2 in docs/b.md",
        ]
        if errors != want:
            failures.append("broken links found:\n  " + "\n  ".join(errors) + "\nexpected:\n  " + "\n  ".join(want))
        (root / "ok.md").write_text("# Ok\n\n[back](README.md#part-one) [self](#ok)\n")
        if Checker(root).check_file(root / "ok.md"):
            failures.append("a page with only good links was reported")
    for f in failures:
        print(f"self-test failed: {f}", file=sys.stderr)
    if failures:
        return 1
    print(f"check_links self-test: {len(cases)} slugs and 2 pages as expected")
    return 0


def main(argv: list[str]) -> int:
    root = Path(__file__).resolve().parents[2]
    if argv[1:] == ["--self-test"]:
        return self_test()
    if any(a.startswith("-") for a in argv[1:]):
        print(__doc__, file=sys.stderr)
        return 2
    files = [Path(a) for a in argv[1:]] or tracked_markdown(root)
    return run(root, files)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
