"""The README's core example runs and prints what the README says; the docs' links resolve."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path
from typing import NamedTuple

from support.paths import ROOT

FENCE = re.compile(r"^```([^\n`]*)\n(.*?)^```$", re.MULTILINE | re.DOTALL)
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
INLINE_CODE = re.compile(r"`[^`\n]*`")
HEADING = re.compile(r"^#{1,6} +(.+?) *$", re.MULTILINE)


class Block(NamedTuple):
    """A fenced block of a Markdown text: its info string and its text."""

    info: str
    text: str


def blocks(markdown: str) -> list[Block]:
    """The fenced code blocks, in order."""
    return [Block(m.group(1).strip(), m.group(2)) for m in FENCE.finditer(markdown)]


def prose(markdown: str) -> str:
    """The text outside fenced blocks and inline code."""
    return INLINE_CODE.sub("", FENCE.sub("", markdown))


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = heading.replace("`", "").strip().lower()
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """The anchors of every heading of a Markdown file."""
    return {slug(h) for h in HEADING.findall(FENCE.sub("", path.read_text(encoding="utf-8")))}


def markdown_files() -> list[Path]:
    """README.md, every guide under docs/ and every design page under docs/design/."""
    docs = ROOT / "docs"
    return [ROOT / "README.md", *sorted(docs.glob("*.md")), *sorted((docs / "design").glob("*.md"))]


def test_core_example_prints_what_the_readme_shows(tmp_path: Path) -> None:
    found = blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    python = [i for i, b in enumerate(found) if b.info == "python"]
    assert len(python) == 1, "the README has one Python example, its core example"
    example, shown = found[python[0]], found[python[0] + 1]
    assert shown.info == "", "the block after the example is its output"
    assert len(example.text.strip().splitlines()) <= 25
    out = subprocess.run(
        [sys.executable, "-c", example.text],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout == shown.text


def test_every_relative_link_points_to_an_existing_file_and_heading() -> None:
    broken = []
    for page in markdown_files():
        for target in LINK.findall(prose(page.read_text(encoding="utf-8"))):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # https:, mailto: ...
                continue
            name, _, anchor = target.partition("#")
            dest = (page.parent / name).resolve() if name else page
            rel = page.relative_to(ROOT)
            if not dest.exists():
                broken.append(f"{rel}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{rel}: {target} (no such heading)")
    assert broken == []


def test_the_readme_links_every_docs_page() -> None:
    readme = prose((ROOT / "README.md").read_text(encoding="utf-8"))
    linked = {t.partition("#")[0] for t in LINK.findall(readme)}
    pages = {f"docs/{p.name}" for p in sorted((ROOT / "docs").glob("*.md"))}
    assert pages - linked == set()


def test_the_development_guide_links_every_design_page() -> None:
    guide = ROOT / "docs" / "development.md"
    linked = {t.partition("#")[0] for t in LINK.findall(prose(guide.read_text(encoding="utf-8")))}
    pages = {f"design/{p.name}" for p in sorted((ROOT / "docs" / "design").glob("*.md"))}
    assert pages and pages - linked == set()


def test_slugs_follow_github() -> None:
    assert slug("Reproducing the thesis: `haptic-experiment`") == (
        "reproducing-the-thesis-haptic-experiment"
    )
    assert slug("PHANToM 1.5 and URDF arms") == "phantom-15-and-urdf-arms"
    assert slug("recorder_node") == "recorder_node"
