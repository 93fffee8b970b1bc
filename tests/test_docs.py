"""The documentation builds with warnings as errors (every page, the API reference from the docstrings, the CLI
reference from the parser, the table of effects from the registry)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_the_documentation_builds_without_a_warning(tmp_path):
    pytest.importorskip("sphinx")
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(ROOT / "docs"),
                          str(tmp_path / "html")], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-4000:]
    effects = (tmp_path / "html" / "effects.html").read_text()
    from spacepol.physics.registry import registry

    assert all(f">{name}<" in effects for name in registry.names())  # the table is the registry's
    assert "--wavelength-um" in (tmp_path / "html" / "cli.html").read_text()  # the reference is the parser's
