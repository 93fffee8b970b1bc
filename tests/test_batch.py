"""``invert-mcmc batch``: several synthetic sets and one broken file on a Dask LocalCluster of 2 workers.
The good sets recover their truths, the broken one is ``failed`` with its reason, the table follows
DESIGN.md's contract, and a re-run skips what is finished."""

import csv
import subprocess
import sys
import time

import numpy as np
import pytest

from spacepol.batch import read_manifest, run_batch
from spacepol.errors import InputFileError
from spacepol.io import write_table
from spacepol.physics import Model
from spacepol.physics.geometry import default_grid

TRUTHS = {
    "glossy_metal": {"n": 1.2, "k": 3.0, "sigma": 0.15, "ks": 0.6, "rho_d": 0.05},
    # a dark (absorbing) paint: with k = 0, at its bound, the chain needed 11,500 steps to R-hat 1.01; here 2,000
    "paint": {"n": 1.6, "k": 0.5, "sigma": 0.3, "ks": 0.4, "rho_d": 0.3},
}
NOISE_DOP, NOISE_BRDF = 0.004, 0.02


def write_synthetic(path, truth, seed):
    """DOP + BRDF of the paper's model on the 84-point grid, Gaussian noise (absolute DOP, relative BRDF)."""
    rng = np.random.default_rng(seed)
    grid = default_grid()
    pred = Model.from_string("paper").evaluate(truth, grid)
    write_table(path, {"theta_i": grid.theta_i, "theta_r": grid.theta_r, "dphi": grid.dphi,
                       "dop": np.clip(pred.dop + NOISE_DOP * rng.standard_normal(grid.size), 0, 1),
                       "dop_err": np.full(grid.size, NOISE_DOP),
                       "brdf": pred.brdf * (1 + NOISE_BRDF * rng.standard_normal(grid.size)),
                       "brdf_err": NOISE_BRDF * pred.brdf})


@pytest.fixture
def manifest(tmp_path):
    rows = ["id,data,seed"]
    for i, (name, truth) in enumerate(TRUTHS.items()):
        write_synthetic(tmp_path / f"{name}.csv", truth, seed=10 + i)
        rows.append(f"{name},{name}.csv,{i}")
    (tmp_path / "broken.csv").write_text("theta_i,theta_r,dop\n20,30,0.4\n20,oops,0.5\n")
    rows.append("broken,broken.csv,0")
    (tmp_path / "sets.csv").write_text("\n".join(rows) + "\n")
    return tmp_path / "sets.csv"


def read_results(path):
    with open(path, newline="") as fh:
        return {row["id"]: row for row in csv.DictReader(fh)}


# the default run keeps the Dask pathway (cluster, a failed job with its reason, the table, the re-run) on the broken
# set alone; the recovery of a set's truths is checked through the local pool in the default run
@pytest.mark.parametrize("sets", [pytest.param([], id="the broken set"),
                                  pytest.param(list(TRUTHS), id="every set", marks=pytest.mark.slow)])
def test_dask_local_cluster_batch_recovers_truths_reports_the_broken_set_and_skips_on_rerun(manifest, tmp_path, sets):
    lines = manifest.read_text().splitlines()
    manifest.write_text("\n".join([lines[0]] + [line for line in lines[1:] if line.split(",")[0] in sets + ["broken"]]) + "\n")
    out = tmp_path / "out"
    start = time.perf_counter()
    rows = run_batch(manifest, out, executor="dask", workers=2, progress=False)
    first = time.perf_counter() - start
    assert [r["id"] for r in rows] == sets + ["broken"]  # manifest order
    table = read_results(out / "results.csv")
    assert list(next(iter(table.values())))[:3] == ["id", "status", "seconds"]
    assert table["broken"]["status"] == "failed"
    assert "broken.csv" in table["broken"]["error"] and "line 3" in table["broken"]["error"]
    for name in sets:
        assert (out / name / "summary.json").is_file() and (out / name / "posterior.nc").is_file()
    if sets:
        assert_recovered(table, sets)

    start = time.perf_counter()
    again = run_batch(manifest, out, executor="dask", workers=2, progress=False)
    rerun = time.perf_counter() - start
    status = {r["id"]: r["status"] for r in again}
    assert status == {**{name: "skipped" for name in sets}, "broken": "failed"}
    kept = read_results(out / "results.csv")
    assert all(kept[name]["n_median"] == table[name]["n_median"] for name in sets)
    print(f"first batch {first:.1f} s, re-run {rerun:.1f} s")


def assert_recovered(table: dict, sets: list[str]) -> None:
    """Each set converged and holds its truths within 4 SD; the control: the paint's intervals miss the metal's
    truths."""
    for name in sets:
        truth, row = TRUTHS[name], table[name]
        assert row["status"] == "ok", row["error"]
        assert float(row["rhat_max"]) < 1.01 and float(row["ess_min"]) > 400
        for param, value in truth.items():
            median, q05, q95 = (float(row[f"{param}_{q}"]) for q in ("median", "q05", "q95"))
            sd = (q95 - q05) / 3.29  # the 90 % interval of a normal is 3.29 sd wide
            assert abs(median - value) < 4 * sd + 1e-3, (name, param, value, median, q05, q95)
    paint, metal = table["paint"], TRUTHS["glossy_metal"]
    assert not all(float(paint[f"{p}_q05"]) <= v <= float(paint[f"{p}_q95"]) for p, v in metal.items())


def test_a_changed_setting_runs_the_set_again(manifest, tmp_path):
    """A finished set is skipped only with the same settings: a new seed in the manifest runs it again."""
    text = manifest.read_text().replace("paint,paint.csv,1", "paint,paint.csv,5")
    jobs = {j.id: j for j in read_manifest(manifest)}
    from spacepol.batch.job import SETTINGS_FILE, finished
    import json

    folder = tmp_path / "out" / "paint"
    folder.mkdir(parents=True)
    (folder / "summary.json").write_text(json.dumps({"parameters": {}, "diagnostics": {}}))
    (folder / SETTINGS_FILE).write_text(json.dumps(jobs["paint"].settings()))
    assert finished(jobs["paint"], str(tmp_path / "out")) is not None
    manifest.write_text(text)
    changed = {j.id: j for j in read_manifest(manifest)}["paint"]
    assert finished(changed, str(tmp_path / "out")) is None


@pytest.mark.parametrize("text, words", [
    ("id,path\nx,a.csv\n", ["unknown column 'path'"]),
    ("data\na.csv\n", ["no 'id' column"]),
    ("id,data\nx,a.csv\nx,b.csv\n", ["line 3", "id 'x' also on line 2"]),
    ("id,data,seed\nx,a.csv,-1\n", ["line 2", "seed"]),
    ("id,data\n../x,a.csv\n", ["line 2", "id '../x'"]),
    ("id,data\n", ["no data sets"]),
    ("id,data\nx,a.csv,extra\n", ["line 2", "3 fields"]),
])
def test_bad_manifests_are_one_line_exit_2_and_leave_nothing(tmp_path, text, words):
    (tmp_path / "m.csv").write_text(text)
    with pytest.raises(InputFileError):
        read_manifest(tmp_path / "m.csv")
    run = subprocess.run([sys.executable, "-m", "spacepol.cli", "batch", str(tmp_path / "m.csv"), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True)
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert run.returncode == 2 and len(lines) == 1 and "Traceback" not in run.stderr, run.stderr
    assert all(word in lines[0] for word in words), lines[0]
    assert not (tmp_path / "o").exists()


def test_local_pool_from_the_command_line(manifest, tmp_path):
    """The default executor (a spawned process pool), through the CLI: exit 1 when a set failed, table written, the
    good set's truths recovered."""
    keep = manifest.read_text().splitlines()
    manifest.write_text("\n".join([keep[0], keep[2], keep[3]]) + "\n")  # paint and broken
    run = subprocess.run([sys.executable, "-m", "spacepol.cli", "batch", str(manifest), "--out", str(tmp_path / "o"),
                          "--workers", "2"], capture_output=True, text=True)
    assert run.returncode == 1, run.stderr
    assert "1 ok, 0 skipped (finished before), 1 failed" in run.stdout and "failed broken" in run.stdout
    assert "[2/2]" in run.stderr
    table = read_results(tmp_path / "o" / "results.csv")
    assert table["paint"]["status"] == "ok" and table["broken"]["status"] == "failed"
    assert_recovered(table, ["paint"])
