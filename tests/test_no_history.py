"""The project speaks of itself only: no development history ("session <number>") in any tracked text file (the
package, the tests, studies, benchmarks, README, docs, reports). Measured figures carry their date on the benchmarks
page."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TEXT = {".py", ".md", ".txt", ".toml", ".cfg", ".csv", ".json", ".html", ".sh", ""}
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


def tracked_text_files() -> list[Path]:
    """The files git tracks whose suffix marks text (the whole tree but .venv and build outputs, outside a checkout)."""
    listed = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True)
    if listed.returncode == 0:
        paths = [ROOT / name for name in listed.stdout.splitlines()]
    else:
        paths = [p for p in ROOT.rglob("*") if not {".venv", ".git", "_build", "__pycache__"} & set(p.parts)]
    return [p for p in paths if p.is_file() and p.suffix in TEXT]


def test_no_session_numbers_in_any_tracked_text_file():
    files = tracked_text_files()
    assert len(files) > 100 and any(p.name == "README.md" for p in files)
    found = history_lines(files)
    assert not found, "\n".join(found[:30])


def test_the_check_finds_a_session_number(tmp_path):
    """Negative control: a line naming a session by its number is found, one naming none is not."""
    bad, good = tmp_path / "bad.md", tmp_path / "ok.md"
    bad.write_text("fixed in Sess" + "ion 12\n", encoding="utf-8")
    good.write_text("one session of sampling, 12 chains\n", encoding="utf-8")
    assert len(history_lines([bad])) == 1 and not history_lines([good])
