"""Every process pool in the repository is spawned, not forked.

A forked child of a process that has started JAX's thread pool can inherit a lock held by a thread that does not
exist in the child, and wait on it forever. So each ``ProcessPoolExecutor`` names its ``mp_context`` (``spacepol._runtime.spawned_pool`` is the one to call) and
no code asks for the fork context or a bare ``multiprocessing.Pool`` (which forks on Linux)."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FOLDERS = ("src", "tests", "benchmarks", "studies")


def _name(func: ast.expr) -> str:
    return func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else ""


def forked_pools(source: str) -> list[int]:
    """Line numbers of calls in ``source`` that make a process pool with the platform's default start method (fork
    on Linux) or ask for fork by name."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.Call):
            continue
        name, keywords = _name(node.func), {k.arg for k in node.keywords}
        if name == "ProcessPoolExecutor" and "mp_context" not in keywords:
            lines.append(node.lineno)
        elif name == "Pool" and isinstance(node.func, ast.Attribute) and _name(node.func.value) == "multiprocessing":
            lines.append(node.lineno)
        elif (name in ("get_context", "set_start_method") and node.args and isinstance(node.args[0], ast.Constant)
              and node.args[0].value == "fork"):
            lines.append(node.lineno)
    return sorted(lines)


def test_every_process_pool_is_spawned():
    found = {}
    for folder in FOLDERS:
        for path in (ROOT / folder).rglob("*.py"):
            lines = forked_pools(path.read_text(encoding="utf-8"))
            if lines:
                found[str(path.relative_to(ROOT))] = lines
    assert not found, f"process pools that fork (file: lines): {found}"


def test_the_check_sees_a_forked_pool():
    """Negative control: the default start method, fork by name and multiprocessing.Pool are found; spawn is not."""
    forked = """
from concurrent.futures import ProcessPoolExecutor
import multiprocessing
a = ProcessPoolExecutor(2)
b = multiprocessing.Pool(2)
c = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("fork"))
"""
    assert forked_pools(forked) == [4, 5, 6]
    spawned = "import multiprocessing\nfrom concurrent.futures import ProcessPoolExecutor\n" \
              "p = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context('spawn'))\n"
    assert forked_pools(spawned) == []
