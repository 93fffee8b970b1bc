"""The Python API: what it exports, and that it rejects what the command line rejects with the same line (the CLI
only adds ``invert-mcmc: error:`` and exit status 2)."""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import spacepol
from spacepol import cli
from spacepol.errors import SpacepolError

import test_bad_input
from test_bad_input import GOOD_CSV, expect_error

here = test_bad_input.here  # the same working-folder fixture


def test_every_exported_name_resolves_and_is_documented():
    for name in spacepol.__all__:
        if name == "__version__":
            continue
        value = getattr(spacepol, name)
        if inspect.isfunction(value) or inspect.isclass(value):
            assert inspect.getdoc(value), name
    with pytest.raises(AttributeError):
        spacepol.not_a_name  # control: a name outside the API is an AttributeError, not None


COMMAS = GOOD_CSV + ",,\n"
STOKES = "theta_i,theta_r,s0,s1,s2\n" + "".join(f"{ti},{tr},1.0,{1.2 if tr == 50 else 0.3},0.1\n"
                                                 for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65))


@pytest.mark.parametrize("case", ["commas", "stokes", "stokes_q", "forward_ks", "synth_rho_d", "forward_n", "sky_nan"])
def test_the_api_rejects_what_the_cli_rejects_with_the_same_line(capsys, here, case):
    (here / "commas.csv").write_text(COMMAS)
    (here / "stokes.csv").write_text(STOKES)
    calls = {
        "commas": (lambda: spacepol.load("commas.csv"), ["run", "commas.csv", "--out", "r"]),
        "stokes": (lambda: spacepol.load("stokes.csv"), ["run", "stokes.csv", "--out", "r"]),
        "stokes_q": (lambda: spacepol.invert("stokes.csv", observables="q"), ["run", "stokes.csv", "--out", "r", "--observables", "q"]),
        "forward_ks": (lambda: spacepol.forward("paper", "good.csv", {"ks": 1e300}),
                       ["forward", "good.csv", "--set", "ks=1e300", "--out", "f.csv"]),
        "synth_rho_d": (lambda: spacepol.synth("paper", {"rho_d": 1e300}), ["synth", "--set", "rho_d=1e300", "--out", "s.csv"]),
        "forward_n": (lambda: spacepol.forward("paper", "good.csv", {"n": 1e300}),
                      ["forward", "good.csv", "--set", "n=1e300", "--out", "f.csv"]),
        "sky_nan": (lambda: spacepol.sky(10, 0, "2026-11-22T12:00Z", ["30,nan"]),
                    ["sky", "--lat", "10", "--lon", "0", "--time", "2026-11-22T12:00Z", "--direction", "30,nan"]),
    }
    call, args = calls[case]
    line = expect_error(capsys, here, args)
    with pytest.raises(SpacepolError) as caught:
        call()
    assert line == f"invert-mcmc: error: {caught.value}"
    assert len(str(caught.value).splitlines()) == 1


def test_controls_good_input_passes_the_same_calls(here):
    """The same calls on good input return what they promise (so the rejections above are about the input)."""
    data = spacepol.load("good.csv")
    assert len(data) == 15
    prediction = spacepol.forward("paper", data, {"ks": 0.5})
    assert np.all((prediction.dop >= 0) & (prediction.dop <= 1))
    synthetic = spacepol.synth("paper", {"rho_d": 0.3}, noise_dop=0.01, seed=3)
    assert len(synthetic) == 84 and synthetic.metadata["truth_rho_d"] == 0.3
    again = spacepol.synth("paper", {"rho_d": 0.3}, noise_dop=0.01, seed=3)
    np.testing.assert_array_equal(again.dop, synthetic.dop)  # one seed, one answer
    sky = spacepol.sky(10, 0, "2026-11-22T12:00Z", [(30, 45)])
    assert 0 <= sky.directions[0]["dop"] <= 1
    assert not (here / "reports").exists()  # nothing written without out=


def test_unknown_engine_and_bad_reference_are_one_line(here):
    with pytest.raises(SpacepolError, match="unknown engine 'hmc'"):
        spacepol.invert("good.csv", engine="hmc")
    with pytest.raises(SpacepolError, match="'zz' is not a free parameter"):
        spacepol.invert("good.csv", references={"zz": 1.0})


def test_dataset_concatenate_keeps_rows_and_refuses_a_missing_observable():
    a = spacepol.synth("paper", noise_dop=0.0, wavelength_um=0.5)
    b = spacepol.synth("paper", noise_dop=0.0, noise_brdf=0.0, wavelength_um=0.6)
    with pytest.raises(SpacepolError, match="has no 'brdf'"):
        spacepol.Dataset.concatenate([a, b])
    both = spacepol.Dataset.concatenate([a, spacepol.synth("paper", noise_dop=0.0, wavelength_um=0.6)])
    assert len(both) == 168 and sorted(set(both.wavelength_um)) == [0.5, 0.6]
    np.testing.assert_array_equal(both.dop[:84], a.dop)


def test_the_cli_module_imports_no_work_and_the_library_never_imports_the_cli():
    import ast
    from pathlib import Path

    package = Path(spacepol.__file__).parent
    for path in package.rglob("*.py"):
        if path.name in ("cli.py", "commands.py"):
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom):
                target = (node.module or "")
                names = [a.name for a in node.names]
                assert not (target.endswith("cli") or target.endswith("commands") or "cli" in names
                            or "commands" in names), f"{path.relative_to(package)} imports the command line"
    assert cli.main  # control: the command line module itself is there
