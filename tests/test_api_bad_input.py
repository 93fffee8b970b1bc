"""Bad input through the Python API: five inputs that could pass silently are refused with one line
naming what is wrong (a SpacepolError, the same message the command line prints with exit status 2), and their
controls are accepted."""

import numpy as np
import pytest

import spacepol
from spacepol.errors import SpacepolError
from spacepol.physics.geometry import default_grid


def one_line(excinfo, *words):
    message = str(excinfo.value)
    assert "\n" not in message.strip(), message
    for word in words:
        assert word in message, (word, message)


def test_a_row_of_only_separators_and_a_stokes_row_above_s0(tmp_path):
    separators = tmp_path / "separators.csv"
    separators.write_text("theta_i,theta_r,dop\n10,20,0.1\n,,\n30,20,0.2\n")
    with pytest.raises(SpacepolError) as excinfo:
        spacepol.load(separators)
    one_line(excinfo, "separators.csv", "only separators")
    blank = tmp_path / "blank.csv"
    blank.write_text("theta_i,theta_r,dop\n10,20,0.1\n\n30,20,0.2\n")
    assert len(spacepol.load(blank)) == 2  # the control: a blank line is skipped
    stokes = tmp_path / "stokes.csv"
    stokes.write_text("theta_i,theta_r,s0,s1,s2,s3\n10,20,1.0,0.6,0.0,0.9\n")
    with pytest.raises(SpacepolError) as excinfo:
        spacepol.load(stokes)
    one_line(excinfo, "stokes.csv")
    stokes.write_text("theta_i,theta_r,s0,s1,s2,s3\n10,20,1.0,0.6,0.0,0.8\n")  # exactly fully polarized: read
    assert len(spacepol.load(stokes)) == 1


def test_reflectances_outside_zero_one_and_outputs_that_overflow():
    geometry = default_grid()
    for name in ("ks", "rho_d"):
        with pytest.raises(SpacepolError) as excinfo:
            spacepol.forward("paper", geometry, {name: 1.5})
        one_line(excinfo, name, "[0, 1]")
    with pytest.raises(SpacepolError) as excinfo:
        spacepol.forward("paper", geometry, {"n": 1e300})
    one_line(excinfo, "n", "no finite output")
    with pytest.raises(SpacepolError) as excinfo:
        spacepol.synth("paper", {"k": 1e300})
    one_line(excinfo, "k", "no finite output")
    assert np.all(np.isfinite(spacepol.forward("paper", geometry, {"ks": 1.0}).dop))  # the control: the bound itself


def test_a_sky_direction_that_is_not_a_number():
    with pytest.raises(SpacepolError) as excinfo:
        spacepol.sky(10.0, 0.0, "2026-11-22T12:00Z", directions=["30,nan"])
    one_line(excinfo, "azimuth")
    assert spacepol.sky(10.0, 0.0, "2026-11-22T12:00Z", directions=["30,40"]) is not None
