"""`diagnose` (issue 4, first version): a hidden effect is named; DESIGN's JSON fields."""

import json
import subprocess
import sys

import numpy as np

from spacepol.io.measurements import write_table


def _hidden_polarized_diffuse(tmp_path):
    """84 points of paper + polarized_diffuse (DOP 0.005, BRDF 3 %) written as a measurement file."""
    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_residuals import TRUTH, _data

    d = _data("paper+polarized_diffuse", TRUTH, 9)
    data = tmp_path / "hidden.csv"
    write_table(data, {"theta_i": d.theta_i, "theta_r": d.theta_r, "dphi": d.dphi, "dop": np.clip(d.dop, 0, 1),
                       "dop_err": d.dop_err, "brdf": d.brdf, "brdf_err": d.brdf_err})
    return data


def test_diagnose_names_a_hidden_polarized_diffuse(tmp_path):
    data = _hidden_polarized_diffuse(tmp_path)
    out = tmp_path / "diag.json"
    run = subprocess.run([sys.executable, "-m", "spacepol.cli", "diagnose", data, "--model", "paper", "--json", out,
                          "--candidates", "polarized_diffuse", "extinction", "dop_bias", "--top", "2",
                          "--out", tmp_path / "figs"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    report = json.loads(out.read_text())
    assert set(report) >= {"model", "fit", "ranking", "verdict"}
    assert report["verdict"] == "polarized_diffuse"
    lead = report["ranking"][0]
    assert set(lead) >= {"effect", "delta_elpd", "delta_elpd_se", "rmse_dop_after", "significant", "explanation"}
    assert lead["effect"] == "polarized_diffuse" and lead["significant"]
    assert lead["delta_elpd"] > 2 * lead["delta_elpd_se"]
    assert lead["rmse_dop_after"] < 0.5 * report["fit"]["rmse_dop"]  # the error falls
    assert (tmp_path / "figs" / "residuals_base.png").exists()
    assert (tmp_path / "figs" / "residuals_polarized_diffuse.png").exists()


def test_diagnose_rejects_unknown_candidates(tmp_path):
    from spacepol.paths import bundled

    run = subprocess.run([sys.executable, "-m", "spacepol.cli", "diagnose", bundled("ptfe", "ptfe_mueller_brdf.csv"),
                          "--wavelength-um", "0.633", "--json", tmp_path / "d.json", "--candidates", "sparkle"],
                         capture_output=True, text=True)
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1
    assert "unknown effect 'sparkle'" in run.stderr and not (tmp_path / "d.json").exists()


def test_ladder_shows_the_error_falling(tmp_path):
    data = _hidden_polarized_diffuse(tmp_path)
    run = subprocess.run([sys.executable, "-m", "spacepol.cli", "ladder", data, "--model", "paper", "--add",
                          "polarized_diffuse", "--json", tmp_path / "ladder.json", "--out", tmp_path / "lad"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    rungs = json.loads((tmp_path / "ladder.json").read_text())["rungs"]
    assert [r["model"] for r in rungs] == ["specular+shadowing+body", "specular+shadowing+body+polarized_diffuse"]
    for r in rungs:
        assert set(r) >= {"model", "rmse_dop", "chi2_red", "elpd_loo"}
    assert rungs[1]["rmse_dop"] < 0.2 * rungs[0]["rmse_dop"]
    assert rungs[0]["chi2_red"] > 10 and abs(rungs[1]["chi2_red"] - 1) < 1.5  # down to the noise floor
    assert rungs[1]["elpd_loo"] > rungs[0]["elpd_loo"]
    assert (tmp_path / "lad" / "ladder.png").stat().st_size > 0 and "| 1 |" in (tmp_path / "lad" / "ladder.md").read_text()
