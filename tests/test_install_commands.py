"""The README's two commands, `.ci/run` and the constraints file agree: the test command CI runs is the README's,
both commands install under `constraints.txt`, and the packages that move seeded results are the pinned versions
(so a seeded test decides the same on every fresh install)."""

import re
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _pins() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, _, pinned = line.partition("==")
            assert pinned, f"constraints.txt: '{line}' is not an exact pin (NAME==VERSION)"
            pins[name.strip()] = pinned.strip()
    return pins


def _commands(text: str) -> list[str]:
    return [line.strip() for line in text.splitlines() if line.strip().startswith("python3.11 -m venv")]


def test_ci_runs_the_readme_test_command():
    readme = _commands((ROOT / "README.md").read_text())
    ci = _commands((ROOT / ".ci" / "run").read_text())
    assert len(ci) == 1 and ci[0] in readme, (ci, readme)
    assert any(c.endswith("invert-mcmc demo") for c in readme)
    for command in readme[:2]:
        assert "-c constraints.txt" in command, command


def test_the_packages_that_move_seeded_results_are_pinned_and_installed_as_pinned():
    pins = _pins()
    for name in ("numpy", "scipy", "jax", "jaxlib", "emcee", "arviz", "numpyro", "nautilus-sampler", "hypothesis"):
        assert name in pins, f"constraints.txt does not pin {name}"
    wrong = []
    for name, pinned in pins.items():
        try:
            installed = version(name)
        except PackageNotFoundError:
            continue  # an optional extra this environment did not install
        if re.sub(r"\+.*", "", installed) != pinned:
            wrong.append(f"{name} {installed} (pinned {pinned})")
    assert not wrong, "installed without -c constraints.txt? " + ", ".join(wrong)
