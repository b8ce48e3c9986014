"""The manual's index (docs/index.md) links every page of docs/, and every relative link of the docs resolves."""

from __future__ import annotations

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)]*)?\)")


def _links(page: pathlib.Path) -> set[pathlib.Path]:
    return {(page.parent / target).resolve() for target in LINK.findall(page.read_text(encoding="utf-8"))
            if "://" not in target}


def test_index_links_every_page():
    pages = {p.resolve() for p in DOCS.rglob("*.md")} - {(DOCS / "index.md").resolve()}
    missing = sorted(p.relative_to(ROOT).as_posix() for p in pages - _links(DOCS / "index.md"))
    assert not missing, f"docs/index.md does not link {missing}"


def test_relative_links_of_the_docs_and_readme_resolve():
    broken = [f"{page.relative_to(ROOT)} → {target.relative_to(ROOT) if target.is_relative_to(ROOT) else target}"
              for page in [ROOT / "README.md", *DOCS.rglob("*.md")] for target in _links(page)
              if not target.exists()]
    assert not broken, "\n".join(sorted(broken))
