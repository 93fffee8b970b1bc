"""The code speaks of itself only: no development history ("session <number>") in the package, the tests, the
studies or the benchmarks' scripts. Measured figures and how they came about belong on the benchmarks page."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("src", "tests", "studies", "benchmarks")
HISTORY = re.compile(r"\bsession\s+\d+", re.IGNORECASE)


def history_lines(paths) -> list[str]:
    """'path:line: text' for each line of the text files in ``paths`` that names a session by its number."""
    found = []
    for path in paths:
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue
        found += [f"{path}:{i}: {line.strip()}" for i, line in enumerate(text.splitlines(), 1)
                  if HISTORY.search(line)]
    return found


def test_no_session_numbers_in_the_code():
    files = [p for folder in FOLDERS for p in (ROOT / folder).rglob("*")
             if p.is_file() and p.suffix in {".py", ".md", ".txt", ".toml", ".cfg"} and "__pycache__" not in p.parts]
    assert len(files) > 50
    found = history_lines(files)
    assert not found, "\n".join(found)


def test_the_check_finds_a_session_number(tmp_path):
    """Negative control: a line naming a session by its number is found, one naming none is not."""
    bad, good = tmp_path / "bad.md", tmp_path / "ok.md"
    bad.write_text("fixed in Sess" + "ion 12\n", encoding="utf-8")
    good.write_text("one session of sampling, 12 chains\n", encoding="utf-8")
    assert len(history_lines([bad])) == 1 and not history_lines([good])
