"""Measurement files and the CLI: good input round-trips, bad input gets one line and exit 2."""


import numpy as np
import pytest

from spacepol.errors import InputFileError
from spacepol.io import read_measurements
from spacepol.paths import bundled
from spacepol.physics import Model
from cli_runner import run_cli

GOOD = "# material: test\n# wavelength_um: 1.55\ntheta_i,theta_r,dop,dop_err\n30,10,0.1,0.01\n30,40,0.2,0.01\n"


def cli(*args, cwd=None):
    """The command line in this process (``cli_runner``): its exit status, stdout and stderr."""
    return run_cli(*args, cwd=cwd)


def test_reads_metadata_and_defaults(tmp_path):
    f = tmp_path / "m.csv"
    f.write_text(GOOD)
    d = read_measurements(f)
    assert d.metadata == {"material": "test", "wavelength_um": "1.55"}
    np.testing.assert_array_equal(d.dphi, [180.0, 180.0])  # default: specular plane
    np.testing.assert_array_equal(d.wavelength_um, [1.55, 1.55])
    assert d.observables == ["dop"] and d.dop_err[0] == 0.01 and d.brdf is None


def test_reads_nist_mueller_layout():
    d = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv"))
    assert len(d) == 7296 and set(np.unique(d.wavelength_um)) == {0.351, 0.532, 0.633, 1.064}
    assert d.mueller.shape == (4, 4, 7296) and np.all(d.theta_i >= 0)
    sub = d.at_wavelength(0.633).in_plane()
    assert len(sub) == 108
    # NIST's phi_r = 0 is the forward direction: it must land on dphi = 180 (specular plane),
    # where PTFE's surface reflection makes S1 > 0 (s-polarized) at large angles.
    specular_side = sub.select((sub.dphi == 180.0) & (sub.theta_i >= 45) & (sub.theta_r >= 40))
    assert np.all(specular_side.stokes[1] > 0)
    np.testing.assert_allclose(sub.stokes[0], sub.brdf)
    np.testing.assert_allclose(sub.dop, np.hypot(np.hypot(sub.stokes[1], sub.stokes[2]), sub.stokes[3]) / sub.brdf)


BAD_FILES = {
    "missing column": ("theta_i,dop\n30,0.1\n", "missing required column 'theta_r'"),
    "text in number": ("theta_i,theta_r,dop\n30,10,0.1\n30,abc,0.2\n", "line 3, column 'theta_r': 'abc' is not a number"),
    "dop above one": ("theta_i,theta_r,dop\n30,10,1.2\n", "line 2, column 'dop': DOP 1.2 outside [0, 1]"),
    "grazing angle": ("theta_i,theta_r,dop\n90,10,0.2\n", "line 2, column 'theta_i': angle 90 deg"),
    "negative error": ("theta_i,theta_r,dop,dop_err\n30,10,0.2,-0.01\n", "line 2, column 'dop_err': negative uncertainty"),
    "empty": ("", "empty file"),
    "header only": ("theta_i,theta_r,dop\n", "header but no data rows"),
    "short row": ("theta_i,theta_r,dop\n30,10\n", "line 2: 2 fields, header has 3"),
    "unknown column": ("theta_i,theta_r,dop,dopp\n30,10,0.1,0.1\n", "unknown column 'dopp'"),
    "no observable": ("theta_i,theta_r\n30,10\n", "no observable column"),
    "partial stokes": ("theta_i,theta_r,s0,s1\n30,10,1,0.1\n", "need all of s0, s1, s2"),
}


@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_bad_files_raise_one_located_error(tmp_path, case):
    text, message = BAD_FILES[case]
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InputFileError) as err:
        read_measurements(f)
    assert message in str(err.value) and str(f) in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("case", ["text in number", "dop above one", "empty", "missing column"])
def test_cli_bad_file_exit_2_one_line_no_output(tmp_path, case):
    text, message = BAD_FILES[case]
    f = tmp_path / "bad.csv"
    f.write_text(text)
    out = tmp_path / "out.csv"
    # forward takes a geometry file (observables optional), so check through synth --geometry and forward
    run = cli("forward", f, "--model", "paper", "--out", out) if case != "dop above one" else cli("synth", "--geometry", f, "--out", out)
    assert run.returncode == 2
    assert "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1 and message.split(":")[-1].strip() in run.stderr
    assert not out.exists() and list(tmp_path.iterdir()) == [f]


@pytest.mark.parametrize("args,message", [
    (["--model", "paper+sparkle"], "unknown effect 'sparkle'"),
    (["--set", "sigma=-0.1"], "sigma = -0.1 is impossible"),
    (["--set", "rough=0.1"], "has no parameter 'rough'"),
    (["--set", "n"], "expected NAME=VALUE"),
    (["--set", "n=abc"], "'abc' is not a number"),
    (["--model", "specular+smith+shadowing"], "replaces 'shadowing'"),
    (["--noise-dop", "-1"], "argument --noise-dop: -1: must be >= 0"),
])
def test_cli_bad_arguments(tmp_path, args, message):
    out = tmp_path / "o.csv"
    run = cli("synth", *args, "--out", out)
    assert run.returncode == 2, run.stderr
    assert message in run.stderr and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_cli_usage_error_is_one_line():
    run = cli("synth")
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1


def test_forward_writes_the_design_columns(tmp_path):
    geo = tmp_path / "g.csv"
    geo.write_text("theta_i,theta_r,dphi\n30,10,180\n30,50,90\n0,0,0\n")
    out = tmp_path / "f.csv"
    run = cli("forward", geo, "--model", "paper+polarized_diffuse", "--set", "n=1.5", "--set", "rho_pd=0.2", "--out", out)
    assert run.returncode == 0, run.stderr
    body = "\n".join(line for line in out.read_text().splitlines() if not line.startswith("#"))
    table = np.genfromtxt(body.splitlines(), delimiter=",", names=True)
    for col in ("theta_i", "theta_r", "dphi", "s0", "s1", "s2", "s3", "dop", "aop", "brdf"):
        assert col in table.dtype.names
    model = Model.from_string("paper+polarized_diffuse")
    from spacepol.physics import Geometry

    expect = model.evaluate({"n": 1.5, "rho_pd": 0.2}, Geometry([30, 30, 0], [10, 50, 0], [180, 90, 0]))
    np.testing.assert_allclose(table["dop"], expect.dop, rtol=1e-12)
    np.testing.assert_allclose(table["brdf"], expect.brdf, rtol=1e-12)


def test_synth_is_reproducible_and_noise_has_the_stated_size(tmp_path):
    a, b, c = (tmp_path / f"{x}.csv" for x in "abc")
    for path, seed in ((a, 5), (b, 5), (c, 6)):
        assert cli("synth", "--model", "paper", "--set", "n=1.24", "--set", "k=6.6", "--noise-dop", "0.01",
                   "--seed", seed, "--out", path).returncode == 0
    assert a.read_text() == b.read_text() and a.read_text() != c.read_text()
    data = read_measurements(a)
    assert len(data) == 84 and data.metadata["truth_n"] == "1.24" and data.metadata["seed"] == "5"
    truth = Model.from_string("paper").evaluate({"n": 1.24, "k": 6.6}, data.geometry).dop
    resid = data.dop - truth
    # 84 draws of N(0, 0.01): the sample sd is within ~4 standard errors (0.01 / sqrt(2 * 84)) of 0.01
    assert abs(resid.std() - 0.01) < 4 * 0.01 / np.sqrt(2 * 84)
    assert abs(resid.mean()) < 4 * 0.01 / np.sqrt(84)
