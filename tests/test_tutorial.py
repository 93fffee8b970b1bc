"""The user-effect tutorial (examples/tutorial_user_effect) runs as written and does what it says:
diagnose names the user's effect among the whole library, and the ladder closes the misfit.

The whole script (diagnose --rounds over the whole library, then the ladder replaying its path) is a slow
test; the default suite registers, hides and climbs the same path with an explicit ladder."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EFFECT = "examples/tutorial_user_effect/sheen.py:Sheen"


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "spacepol.cli", *map(str, args)], cwd=ROOT, capture_output=True, text=True)


def test_tutorial_steps_register_hide_and_close_a_user_effect(tmp_path):
    """Fast version: the effect registers like a built-in, hides in synthetic data from a surface with Smith
    shadowing, and the ladder from the paper's model (swap the shadowing, then add the sheen) closes the misfit
    round by round and recovers the hidden value (same commands and settings as run.sh)."""
    listing = _cli("effects", "--effect", EFFECT)
    assert listing.returncode == 0 and "\nsheen\n" in listing.stdout
    data = tmp_path / "sheen_hidden.csv"
    synth = _cli("synth", "--effect", EFFECT, "--model", "specular+smith+body+sheen", "--set", "n=1.5", "--set", "k=0",
                 "--set", "sigma=0.2", "--set", "ks=0.5", "--set", "rho_d=0.2", "--set", "b_sheen=0.15", "--noise-dop", "0.003",
                 "--noise-brdf", "0.02", "--seed", "7", "--out", data)
    assert synth.returncode == 0, synth.stderr
    ladder = _cli("ladder", data, "--effect", EFFECT, "--model", "paper", "--add", "replace shadowing by smith", "--add", "sheen",
                  "--json", tmp_path / "ladder.json", "--out", tmp_path / "ladder")
    assert ladder.returncode == 0, ladder.stderr
    rungs = json.loads((tmp_path / "ladder.json").read_text())["rungs"]
    assert [r["model"] for r in rungs] == ["specular+shadowing+body", "specular+smith+body", "specular+smith+body+sheen"]
    chi2 = [r["chi2_red"] for r in rungs]  # known noise: chi^2 is the error measure
    assert chi2[0] > chi2[1] > chi2[2] and abs(chi2[2] - 1) < 0.5, chi2
    assert rungs[1]["elpd_loo"] > rungs[0]["elpd_loo"] and rungs[2]["elpd_loo"] > rungs[1]["elpd_loo"]
    b = rungs[2]["parameters"]["b_sheen"]
    assert abs(b["median"] - 0.15) < 3.3 * (b["q84"] - b["q16"]) / 2


@pytest.mark.slow
def test_tutorial_finds_and_closes_a_user_effect(tmp_path):
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}
    run = subprocess.run(["sh", "examples/tutorial_user_effect/run.sh", str(tmp_path)], cwd=ROOT, env=env,
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr[-2000:]
    report = json.loads((tmp_path / "diagnose.json").read_text())
    assert set(report) >= {"model", "fit", "ranking", "verdict", "rounds", "final_model"}
    path = [r["change"] for r in report["rounds"][1:]]
    assert set(path) == {"replace shadowing by smith", "add sheen"}, path  # the swap and the user's effect, nothing else
    screened = {r["effect"] for r in report["ranking"]}
    assert {"polarized_diffuse", "extinction", "dop_bias", "sheen", "smith", "lambertian"} <= screened  # the whole library
    chi2 = [r["fit"]["chi2_red"] for r in report["rounds"]]
    assert all(b < a for a, b in zip(chi2, chi2[1:])) and chi2[-1] < 1.5, chi2  # the error falls at each round
    assert "Explained" in report["conclusion_rounds"]
    for name in ("report.html", "signatures.png", "residuals_base.png", "path.png"):
        assert (tmp_path / "diagnose" / name).stat().st_size > 0
    rungs = json.loads((tmp_path / "ladder.json").read_text())["rungs"]
    assert [r["model"] for r in rungs] == [r["model"] for r in report["rounds"]]
    from spacepol.io import read_measurements

    truth = float(read_measurements(tmp_path / "sheen_hidden.csv").metadata["truth_b_sheen"])
    b = rungs[-1]["parameters"]["b_sheen"]
    assert abs(b["median"] - truth) < 3.3 * (b["q84"] - b["q16"]) / 2
