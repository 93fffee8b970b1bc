"""Modules of at most 400 lines and functions of at most 80, so that one concept stays readable in one sitting."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "spacepol"
MODULE_LINES, FUNCTION_LINES = 400, 80


def too_long(package: Path = SRC) -> set[str]:
    """Modules over MODULE_LINES lines and functions over FUNCTION_LINES, as "path" and "path:function"."""
    out = set()
    for path in sorted(package.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        name = path.relative_to(package).as_posix()
        if len(text.splitlines()) > MODULE_LINES:
            out.add(name)
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                    node.end_lineno - node.lineno + 1 > FUNCTION_LINES:
                out.add(f"{name}:{node.name}")
    return out


def test_no_module_or_function_is_too_long():
    assert too_long() == set()


def test_the_check_sees_a_long_module_and_function(tmp_path):
    """Negative control: a module of 401 lines holding an 81-line function is found twice."""
    body = "def f():\n" + "    x = 1\n" * 80 + "\n" * (401 - 81)
    (tmp_path / "m.py").write_text(body)
    assert too_long(tmp_path) == {"m.py", "m.py:f"}
