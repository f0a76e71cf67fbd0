"""The documents hold together: every relative link in README.md and docs/ names a file that exists, and every
decision record is listed in the decisions' index (a record missing from it is one nobody finds)."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"```.*?```", re.S)


def _documents() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]


def relative_links(document: Path) -> list[str]:
    """The targets of ``document``'s markdown links that name a file of the project (no scheme, not an anchor alone),
    outside fenced code."""
    text = FENCE.sub("", document.read_text(encoding="utf-8"))
    targets = [m.group(1) for m in LINK.finditer(text)]
    return [t for t in targets if not re.match(r"[a-z][a-z0-9+.-]*:", t) and not t.startswith("#")]


def test_every_relative_link_names_a_file_that_exists():
    broken = [
        f"{document.relative_to(ROOT)} -> {target}"
        for document in _documents()
        for target in relative_links(document)
        if not (document.parent / target.split("#")[0]).exists()
    ]
    assert len(_documents()) > 10
    assert not broken, "\n".join(broken)


def test_the_link_check_sees_a_broken_link(tmp_path):
    document = tmp_path / "page.md"
    (tmp_path / "there.md").write_text("x", encoding="utf-8")
    document.write_text(
        "[here](there.md) [gone](missing.md#part) [web](https://example.org) [anchor](#top)\n"
        "```\n[in code](nowhere.md)\n```\n",
        encoding="utf-8",
    )
    assert relative_links(document) == ["there.md", "missing.md#part"]


def test_every_decision_record_is_in_the_index():
    decisions = ROOT / "docs" / "decisions"
    listed = set(relative_links(decisions / "README.md"))
    records = sorted(p.name for p in decisions.glob("*.md") if p.name != "README.md")
    assert len(records) > 100
    assert [r for r in records if r not in listed] == []
