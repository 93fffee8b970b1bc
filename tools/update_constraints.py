"""Rewrite constraints.txt with the versions installed in this environment, for the packages it already names.

    .venv/bin/python tools/update_constraints.py

Move the pins deliberately: upgrade in a fresh environment, run the whole suite (``-m slow`` included), then run this
and commit the file with the figures that changed.
"""

from __future__ import annotations

import sys
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

PATH = Path(__file__).resolve().parents[1] / "constraints.txt"


def main() -> int:
    lines, missing = [], []
    for line in PATH.read_text().splitlines():
        name = line.split("#")[0].split("==")[0].strip()
        if not name:
            lines.append(line)
            continue
        try:
            lines.append(f"{name}=={version(name)}")
        except PackageNotFoundError:
            missing.append(name)
            lines.append(line)
    PATH.write_text("\n".join(lines) + "\n")
    if missing:
        print(f"update_constraints: not installed here, kept as pinned: {', '.join(missing)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
