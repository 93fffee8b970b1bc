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


ISSUE = re.compile(r"\bissue\s+#?\d+", re.IGNORECASE)
# a run's time quoted in a comment or docstring: "took 12 s", "1.5-4 s", "2 ms per step", "10 M/s"
TIMING = re.compile(r"(?<![\w.^-])\d+(?:\.\d+)?(?:-\d+(?:\.\d+)?)? ?(?:ms|us|s|min)\b(?!\^)|\bM/s\b")
# physical quantities, not run times: an exposure, a unit example, a standard error s, a fit parameter, UT1-UTC
PHYSICAL = ("1 s exposure", '"25 ms"', "2 s x PLUGIN", "3.13 s exp", "0.9 s by", "running 5 s after",
            "5 us for this pass", "20 s steps", ":10s}")
# the pages that carry measured figures, dated
MEASUREMENT_PAGES = ("benchmarks.md", "benchmarks-log.md", "changelog.md")


def _comments_and_docstrings(path: Path) -> list[tuple[int, str]]:
    import io
    import tokenize

    out = []
    for tok in tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline):
        if tok.type == tokenize.COMMENT or (tok.type == tokenize.STRING
                                            and tok.string.lstrip("rbuRBU")[:3] in ('"""', "'''")):
            out.append((tok.start[0], tok.string))
    return out


def quoted_times(text: str) -> list[str]:
    """The run times and issue numbers quoted in ``text`` (a comment or docstring), physical quantities aside."""
    found = []
    for m in list(ISSUE.finditer(text)) + list(TIMING.finditer(text)):
        context = text[max(0, m.start() - 30):m.end() + 15]
        if not any(p in context for p in PHYSICAL):
            found.append(m.group(0))
    return found


def test_no_run_times_or_issue_numbers_in_the_code_or_the_tests():
    paths = sorted((ROOT / "src").rglob("*.py")) + sorted((ROOT / "tests").rglob("*.py"))
    found = [f"{path.relative_to(ROOT)}:{line}: {hit}" for path in paths if path.name != "test_no_history.py"
             for line, text in _comments_and_docstrings(path) for hit in quoted_times(text)]
    assert found == []


def test_the_timing_check_sees_a_quoted_run_time():
    """Negative control: a comment quoting a run's time and a docstring naming an issue are found; a unit is not."""
    assert quoted_times("Fast (issue 12).") == ["issue 12"]
    assert quoted_times("# the fit took 12.5 s on PTFE, 2 ms per step") == ["12.5 s", "2 ms"]
    assert quoted_times("# photons m^-2 s^-1 at 30 deg") == []


def test_no_run_times_in_the_readme_or_the_docs_but_the_measurement_pages():
    pages = [ROOT / "README.md"] + [p for p in sorted((ROOT / "docs").glob("*.md")) if p.name not in MEASUREMENT_PAGES]
    found = [f"{page.relative_to(ROOT)}:{i}: {hit}" for page in pages
             for i, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1) for hit in quoted_times(line)]
    assert found == []
