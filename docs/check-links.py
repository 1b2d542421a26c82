#!/usr/bin/env python3
"""Checks the documentation's references, from the repository root:

    python3 docs/check-links.py

1. Every relative link in README.md and docs/*.md names a file that exists
   (and, with #anchor, a heading of that Markdown file, as GitHub makes anchors).
2. Every "SPEC §n" cited in a *.rs, *.py or *.toml file (ranges and lists
   too) names a section of docs/spec.md.
3. No Markdown file links outside the repository (../shared/...).
Exits 1 and lists what is wrong.
"""

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def anchors(md: pathlib.Path) -> set:
    out, fence = set(), False
    for line in md.read_text(encoding="utf-8").splitlines():
        if line.startswith("```"):
            fence = not fence
        if fence or not line.startswith("#"):
            continue
        title = line.lstrip("#").strip().lower()
        title = re.sub(r"[^\w\- ]", "", title)
        out.add(title.replace(" ", "-"))
    return out


def tracked(pattern: str) -> list:
    names = subprocess.run(
        ["git", "ls-files", pattern], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.split()
    return [ROOT / n for n in names]


def main() -> int:
    bad = []
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    for page in pages:
        text = re.sub(r"```.*?```", "", page.read_text(encoding="utf-8"), flags=re.S)
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target):
                continue  # https:, mailto:
            path, _, anchor = target.partition("#")
            dest = (page.parent / path).resolve() if path else page
            if not dest.exists() or ROOT not in [dest, *dest.parents]:
                bad.append(f"{page.relative_to(ROOT)}: {target}: no such file in the repository")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                bad.append(f"{page.relative_to(ROOT)}: {target}: no such heading")
    for md in tracked("*.md"):
        if "../shared/" in md.read_text(encoding="utf-8"):
            bad.append(f"{md.relative_to(ROOT)}: links to ../shared/ (outside a clone)")
    spec = (ROOT / "docs" / "spec.md").read_text(encoding="utf-8")
    sections = set(re.findall(r"^## (\d+)\. ", spec, flags=re.M))
    cite = re.compile(r"SPEC(?:\.md)? \(?(§\d+(?:\s*(?:,|–|-|and)\s*§\d+)*)")
    for src in tracked("*.rs") + tracked("*.py") + tracked("*.toml"):
        for group in cite.findall(src.read_text(encoding="utf-8")):
            for n in re.findall(r"§(\d+)", group):
                if n not in sections:
                    bad.append(f"{src.relative_to(ROOT)}: SPEC §{n} is not a section of docs/spec.md")
    print("\n".join(bad) if bad else f"ok: {len(pages)} pages, every link and SPEC § resolves")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
