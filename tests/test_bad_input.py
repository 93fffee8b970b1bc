"""Bad input, one category per test: one line naming what is wrong and where, exit status 2, no
traceback, nothing left behind.  The CLI runs in-process (fast); the snapshot of the working folder
before and after proves nothing was written."""

import os
import textwrap

import pytest

from spacepol import cli
from spacepol.paths import bundled

PTFE = str(bundled("ptfe", "ptfe_mueller_brdf.csv"))
GOOD_CSV = "theta_i,theta_r,dop\n" + "".join(f"{ti},{tr},0.{(ti + tr) % 9 + 1}\n" for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65))


def snapshot(folder):
    return sorted(os.path.relpath(os.path.join(d, f), folder) for d, ds, fs in os.walk(folder) for f in fs + ds)


def expect_error(capsys, folder, args, *words):
    """Run the CLI; it must fail with exit 2, one stderr line containing ``words``, and leave ``folder`` as it was."""
    before = snapshot(folder)
    try:
        rc = cli.main([str(a) for a in args])
    except SystemExit as exc:  # argparse
        rc = exc.code
    out, err = capsys.readouterr()
    lines = [line for line in err.splitlines() if line.strip()]
    assert rc == 2, (rc, err)
    assert len(lines) == 1, err
    assert "Traceback" not in err and "Traceback" not in out
    for word in words:
        assert word in lines[0], (word, lines[0])
    assert snapshot(folder) == before, "something was left behind"
    return lines[0]


@pytest.fixture
def here(tmp_path, monkeypatch):
    """A working folder with a good data file and a plain file; plug-ins registered here are forgotten after."""
    from spacepol.physics.registry import registry

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(registry, "_classes", dict(registry._classes))
    (tmp_path / "good.csv").write_text(GOOD_CSV)
    (tmp_path / "a_file").write_text("x")
    return tmp_path


@pytest.mark.parametrize("args, words", [
    (["run", "good.csv", "--out", "a_file"], ["a_file", "is a file"]),
    (["run", "good.csv", "--out", "a_file/sub"], ["a_file", "is a file"]),
    (["run", "good.csv", "--out", "/proc/spacepol_out"], ["/proc", "cannot write"]),
    (["forward", "good.csv", "--out", "."], ["--out", "folder"]),
    (["synth", "--out", "/proc/x.csv"], ["/proc", "cannot write"]),
    (["diagnose", "good.csv", "--json", ".", "--out", "d"], ["--json", "folder"]),
    (["ladder", "good.csv", "--add", "dop_bias", "--out", "a_file"], ["a_file", "is a file"]),
    (["compare", "good.csv", "--out", "a_file/x"], ["a_file", "is a file"]),
    (["sky", "--lat", "43", "--lon", "125", "--time", "2026-11-22T12:00Z", "--out", "a_file"], ["a_file"]),
    (["demo", "--out", "a_file"], ["a_file", "is a file"]),
])
def test_unusable_output_paths(capsys, here, args, words):
    expect_error(capsys, here, args, *words)


@pytest.mark.parametrize("args, words", [
    (["run", "good.csv", "--seed", "-1"], ["--seed", ">= 0"]),
    (["run", "good.csv", "--walkers", "0"], ["--walkers"]),
    (["run", "good.csv", "--walkers", "7"], ["--walkers 7", "even"]),
    (["run", "good.csv", "--steps", "10"], ["--steps"]),
    (["run", "good.csv", "--steps", "many"], ["--steps", "whole number"]),
    (["compare", "good.csv", "--seeds", "0"], ["--seeds"]),
    (["compare", "good.csv", "--methods", "de", "nlopt:NOT_AN_ALGO"], ["NOT_AN_ALGO"]),
    (["optimize", "good.csv", "--method", "simplex"], ["simplex"]),
    (["diagnose", "good.csv", "--json", "d.json", "--top", "0"], ["--top"]),
    (["contrast", ".", "--draws", "5"], ["--draws"]),
])
def test_seeds_and_counts(capsys, here, args, words):
    expect_error(capsys, here, args, *words)


@pytest.mark.parametrize("observables, words", [
    ("dop,dop", ["dop", "twice"]), ("dop,xyz", ["xyz"]), ("dop,", ["empty"]), ("q", ["'q'", "not in the data"]),
])
def test_observables(capsys, here, observables, words):
    expect_error(capsys, here, ["run", "good.csv", "--observables", observables], *words)


@pytest.mark.parametrize("args, words", [
    (["synth", "--noise-dop", "nan", "--out", "s.csv"], ["--noise-dop", "finite"]),
    (["synth", "--noise-dop", "-0.1", "--out", "s.csv"], ["--noise-dop"]),
    (["synth", "--noise-brdf", "inf", "--out", "s.csv"], ["--noise-brdf", "finite"]),
    (["synth", "--set", "n=nan", "--out", "s.csv"], ["n = nan"]),
    (["synth", "--set", "sigma=-1", "--out", "s.csv"], ["sigma"]),
    (["synth", "--wavelength-um", "0", "--out", "s.csv"], ["--wavelength-um"]),
    (["run", "good.csv", "--wavelength-um", "-0.5"], ["--wavelength-um"]),
    (["sky", "--lat", "nan", "--lon", "0", "--time", "2026-11-22T12:00Z"], ["--lat", "finite"]),
    (["sky", "--lat", "95", "--lon", "0", "--time", "2026-11-22T12:00Z"], ["--lat", "latitude"]),
    (["sky", "--lat", "10", "--lon", "0", "--time", "2026-11-22T12:00Z", "--p-max", "-1"], ["--p-max"]),
    (["sky", "--lat", "10", "--lon", "0", "--time", "2026-11-22T12:00Z", "--direction", "95,10"], ["--direction"]),
    (["sky", "--lat", "10", "--lon", "0", "--time", "2026-11-22T12:00Z", "--direction", "30,nan"], ["--direction", "azimuth"]),
    (["forward", "good.csv", "--set", "ks=1e300", "--out", "f.csv"], ["ks = 1e+300", "[0, 1]"]),
    (["synth", "--set", "rho_d=1e300", "--out", "s.csv"], ["rho_d = 1e+300", "[0, 1]"]),
    (["forward", "good.csv", "--set", "n=1e300", "--out", "f.csv"], ["n = 1e+300", "no finite output"]),
    (["synth", "--set", "k=1e300", "--out", "s.csv"], ["k = 1e+300", "no finite output"]),
    (["design", "good.csv", "--noise", "dop=-0.01"], ["--noise 'dop=-0.01'", "X > 0"]),
    (["design", "good.csv", "--noise", "dop=inf"], ["--noise 'dop=inf'", "X > 0"]),
    (["design", "good.csv", "--noise", "glitter=0.1"], ["--noise 'glitter=0.1'"]),
    (["design", "good.csv", "--noise", "dop"], ["--noise 'dop'", "dop=X"]),
    (["design", "good.csv", "--noise", "dop=lots"], ["--noise 'dop=lots'"]),
    (["diagnose", "good.csv", "--json", "d.json", "--criterion", "bic"], ["--criterion", "bic"]),
    (["diagnose", "good.csv", "--json", "d.json", "--workers", "0"], ["--workers"]),
])
def test_numbers_that_must_be_finite_or_positive(capsys, here, args, words):
    expect_error(capsys, here, args, *words)


@pytest.mark.parametrize("text, words", [
    ("# wavelength_um: 0\n" + GOOD_CSV, ["wavelength_um", "positive"]),
    ("# wavelength_um: -0.6\n" + GOOD_CSV, ["wavelength_um", "positive"]),
    ("theta_i,theta_r,dop,wavelength_um\n10,20,0.1,0\n", ["line 2", "wavelength_um", "positive"]),
])
def test_wavelengths(capsys, here, text, words):
    (here / "w.csv").write_text(text)
    expect_error(capsys, here, ["run", "w.csv"], *words)


def _nist(row_values):
    header = ("lambda,thetai,phi,thetar,phir,f_r11," + ",".join(f"f_r{i}{j}/f_r11" for i in range(1, 5) for j in range(1, 5)
                                                             if (i, j) != (1, 1)))
    return header + "\n" + "\n".join(",".join(map(str, r)) for r in row_values) + "\n"


def _row(lam=0.633, m21=0.0, m31=0.0, m22=0.5):
    m = [0.0] * 15
    m[3], m[4], m[7] = m21, m22, m31  # f_r21, f_r22, f_r31
    return [lam, -30.0, 0, 20.0, 0.0, 0.3] + m


@pytest.mark.parametrize("row, words", [
    (_row(m21=0.9, m31=0.9), ["line 2", "DOP", "> 1"]),
    (_row(m22=1.7), ["line 2", "f_r22/f_r11", "outside [-1, 1]"]),
    (_row(lam=0.0), ["line 2", "lambda", "positive"]),
    (_row(lam=-0.5), ["line 2", "lambda", "positive"]),
])
def test_nist_rows(capsys, here, row, words):
    (here / "n.csv").write_text(_nist([row]))
    expect_error(capsys, here, ["run", "n.csv"], *words)


@pytest.mark.parametrize("toml, words", [
    ("[n]\ndistribution = 'normal'\nmu = 100.0\nsigma = 0.01\nlower = 1.0\nupper = 2.0\n", ["[n]", "no probability"]),
    ("[k]\nfixed = nan\n", ["[k]", "fixed", "finite"]),
    ("[n]\nlower = 2.0\nupper = 1.0\n", ["[n]", "not below"]),
    ("[n]\nlower = 1.0\nupper = inf\n", ["[n]", "finite"]),
    ("[nope]\nfixed = 1.0\n", ["nope"]),
    ("[n]\nlowr = 1.0\nupper = 2.0\n", ["[n]", "lowr"]),
    ("[n\nlower = 1\n", ["p.toml"]),
    ("[n]\nlower = -1.0\nupper = 2.0\n", ["n", "physical"]),
])
def test_impossible_priors(capsys, here, toml, words):
    (here / "p.toml").write_text(toml)
    expect_error(capsys, here, ["run", "good.csv", "--prior", "p.toml", "--out", "r"], "p.toml", *words)


PLUGINS = {
    "raises": ("""
        def lobe(self, ctx):
            raise ValueError("boom")
    """, ["bad_effect", "ValueError", "boom"]),
    "nan": ("""
        def lobe(self, ctx):
            return ctx.depolarized(np.full(ctx.shape, np.nan))
    """, ["bad_effect", "non-finite"]),
    "exits": ("""
        def lobe(self, ctx):
            sys.exit(3)
    """, ["bad_effect", "sys.exit(3)"]),
    # written for numpy: JAX cannot trace these (the parameter sets are traced values)
    "numpy": ("""
        def lobe(self, ctx):
            return ctx.depolarized(np.exp(-np.asarray(ctx.geometry.cos_tr * ctx["ks"])))
    """, ["bad_effect", "cannot be compiled by JAX", "jax.numpy"]),
    "in_place": ("""
        def modify_stokes(self, ctx, total):
            total[1:] *= 0.5
            return total
    """, ["bad_effect", "in place", ".at[1:]"]),
    "branch": ("""
        def lobe(self, ctx):
            return ctx.depolarized(ctx.geometry.cos_tr) if float(ctx["ks"].max()) > 0.5 else None
    """, ["bad_effect", "cannot be compiled by JAX"]),
}


@pytest.mark.parametrize("kind", list(PLUGINS))
@pytest.mark.parametrize("command", ["run", "forward", "synth"])
def test_plugin_effects_that_raise_exit_or_return_nan(capsys, here, kind, command):
    body, words = PLUGINS[kind]
    (here / "bad.py").write_text("import sys\nimport numpy as np\nfrom spacepol.physics.effect import Effect\n\n"
                                 f"class Bad(Effect):\n    name = 'bad_effect'\n{textwrap.indent(textwrap.dedent(body), '    ')}")
    args = {"run": ["run", "good.csv", "--out", "r"], "forward": ["forward", "good.csv", "--out", "f.csv"],
            "synth": ["synth", "--out", "s.csv"]}[command]
    expect_error(capsys, here, ["--effect", "bad.py:Bad", *args, "--model", "paper+bad_effect"], *words)


@pytest.mark.parametrize("source, words", [
    ("raise RuntimeError('at import')\n", ["bad.py", "line 1", "RuntimeError"]),
    ("import sys\nsys.exit(0)\n", ["bad.py", "sys.exit"]),
    ("X = 1\n", ["bad.py", "Bad"]),
    ("Bad = 1\n", ["not an Effect"]),
])
def test_plugin_files_that_fail_to_load(capsys, here, source, words):
    (here / "bad.py").write_text(source)
    expect_error(capsys, here, ["--effect", "bad.py:Bad", "effects"], *words)


@pytest.mark.parametrize("toml, words", [
    ("[instrument]\npupil_area_m2 = nan\n", ["pupil_area_m2", "finite"]),
    ("[instrument]\nintegration_time_s = inf\n", ["integration_time_s", "finite"]),
    ("[instrument]\nband_low_um = 0.0001\nband_high_um = 0.0002\n", ["band", "flux"]),
    ("[site]\ntime = '2020-12-16 11:42'\n", ["time", "UTC offset"]),
    ("[site]\ntime = '0005-01-01T00:00Z'\n", ["time", "1000-3000"]),
    ("[site]\nlat_deg = 120\n", ["lat_deg"]),
    ("[[cases]]\nzenith_deg = nan\nazimuth_deg = 3\n", ["zenith_deg", "finite"]),
])
def test_scenarios(capsys, here, toml, words):
    (here / "s.toml").write_text(toml)
    expect_error(capsys, here, ["contrast", ".", "--scenario", "s.toml", "--out", "c"], "s.toml", *words)


@pytest.mark.parametrize("time", ["0001-01-01T00:00Z", "9999-12-31T23:59:59-05:00", "2020-02-30T00:00Z", "yesterday",
                                  "2026-11-22T12:00"])
def test_dates_outside_what_the_ephemeris_takes(capsys, here, time):
    expect_error(capsys, here, ["sky", "--lat", "43", "--lon", "125", "--time", time, "--out", "s"], "--time")


@pytest.mark.parametrize("text, words", [
    ("theta_i,dop\n10,0.1\n", ["theta_r"]),
    ("theta_i,theta_r,dop\n10,abc,0.1\n", ["line 2", "theta_r", "abc"]),
    ("theta_i,theta_r,dop\n10,20,1.5\n", ["line 2", "dop", "outside"]),
    ("theta_i,theta_r,dop\n95,20,0.1\n", ["line 2", "theta_i", "below 90"]),
    ("theta_i,theta_r,dop,dop_err\n10,20,0.1,-0.01\n", ["line 2", "dop_err", "negative"]),
    ("", ["empty"]),
    ("theta_i,theta_r,dop\n", ["no data rows"]),
    ("theta_i,theta_r,dop\n10,20\n", ["line 2", "fields"]),
    ("\x00\x01\x02binary", ["w.csv"]),
    (GOOD_CSV + ",,\n", ["line 17", "empty fields"]),
    ("theta_i,theta_r,s0,s1,s2\n" + "".join(f"{ti},{tr},1.0,{1.5 if tr == 35 else 0.3},0.1\n"
                                            for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65)),
     ["line 4", "s1", "above s0"]),
])
def test_malformed_measurement_files(capsys, here, text, words):
    (here / "w.csv").write_text(text)
    expect_error(capsys, here, ["run", "w.csv", "--out", "r"], "w.csv", *words)


@pytest.mark.parametrize("observables", ["q", None])
def test_a_stokes_row_above_s0_is_refused_whatever_is_fitted(capsys, here, observables):
    rows = "".join(f"{ti},{tr},1.0,{1.2 if tr == 50 else 0.3},0.1\n" for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65))
    (here / "st.csv").write_text("theta_i,theta_r,s0,s1,s2\n" + rows)
    extra = ["--observables", observables] if observables else []
    expect_error(capsys, here, ["run", "st.csv", "--out", "r", *extra], "st.csv", "line 5", "above s0")


def test_blank_lines_and_fully_polarized_stokes_rows_are_still_read(here):
    """The controls: a blank line is skipped (not a row of empty fields), and a Stokes vector exactly at DOP 1 is possible."""
    from spacepol.io import read_measurements

    (here / "b.csv").write_text(GOOD_CSV.replace("\n10,20,", "\n\n10,20,") + "\n  \n")
    assert len(read_measurements(here / "b.csv")) == 15
    (here / "s.csv").write_text("theta_i,theta_r,s0,s1,s2,s3\n10,20,1.0,0.6,0.0,0.8\n30,20,2.0,0.0,-2.0,0.0\n")
    assert len(read_measurements(here / "s.csv")) == 2


def test_a_folder_or_a_missing_file_as_data(capsys, here):
    (here / "folder").mkdir()
    expect_error(capsys, here, ["run", "folder", "--out", "r"], "folder")
    expect_error(capsys, here, ["run", "missing.csv", "--out", "r"], "missing.csv", "not found")


def test_a_byte_order_mark_is_accepted(capsys, here):
    """Spreadsheets save "CSV UTF-8" with a BOM: the file reads as without it (negative control: the same
    file with a BOM inside the header name would still be refused)."""
    (here / "bom.csv").write_bytes(b"\xef\xbb\xbf" + GOOD_CSV.encode())
    assert cli.main(["forward", "bom.csv", "--out", "f.csv"]) == 0
    assert (here / "f.csv").read_text().count("\n") > 15
    capsys.readouterr()
    (here / "bom2.csv").write_bytes(b"\xef\xbb\xbf\xef\xbb\xbf" + GOOD_CSV.encode())
    expect_error(capsys, here, ["forward", "bom2.csv", "--out", "g.csv"], "unknown column")


def test_outputs_follow_the_umask(here, capsys):
    old = os.umask(0o027)
    try:
        assert cli.main(["synth", "--out", "s.csv"]) == 0
    finally:
        os.umask(old)
    assert oct((here / "s.csv").stat().st_mode & 0o777) == oct(0o640)
    assert cli.main(["synth", "--out", "t.csv"]) == 0
    assert oct((here / "t.csv").stat().st_mode & 0o777) == oct(0o666 & ~old)
