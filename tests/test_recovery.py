"""Runs that recover: kill -9 during sampling and during the report, then the same command completes;
a finished run re-run exits 0; a truncated chain.h5 gives one line and --restart works; two runs on
one folder give one clear error.  Real processes and real signals (the in-process resume test that
proves bit-identity is in test_sampler.py)."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

ENV = {**os.environ, "PYTHONUNBUFFERED": "1"}


def cli(*args, **kw):
    return subprocess.run([sys.executable, "-m", "spacepol.cli", *map(str, args)], capture_output=True, text=True, env=ENV, **kw)


def start(*args):
    return subprocess.Popen([sys.executable, "-m", "spacepol.cli", *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=ENV)


def stopped_at(text, *args) -> list[str]:
    """Start ``invert-mcmc ARGS``, read its output until a line holds ``text``, kill it; returns the lines read."""
    proc = start(*args)
    try:
        return wait_for(proc, text)
    finally:
        proc.kill()
        proc.wait()


def wait_for(proc, text, timeout=240):
    """Read the process's output until a line contains ``text``; returns the lines read."""
    lines, deadline = [], time.time() + timeout
    while time.time() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        lines.append(line)
        if text in line:
            return lines
    proc.kill()
    raise AssertionError(f"never saw {text!r}: {''.join(lines)}")


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("recovery")
    path = tmp / "syn.csv"
    r = cli("synth", "--model", "specular+smith", "--set", "n=1.5", "--set", "k=0.5", "--set", "sigma=0.2", "--set", "ks=0.8",
            "--noise-dop", "0.01", "--noise-brdf", "0.05", "--seed", "3", "--out", path)
    assert r.returncode == 0, r.stderr
    return path


RUN = ("--model", "specular+smith", "--steps", "900", "--seed", "2")


@pytest.fixture(scope="module")
def finished(data, tmp_path_factory):
    """A finished 300-step run, made once; tests damage copies of it."""
    out = tmp_path_factory.mktemp("finished") / "run"
    first = cli("run", data, *RUN, "--steps", "300", "--quiet", "--out", out)
    assert first.returncode == 0, first.stderr
    return out


def copy_of(run, tmp_path):
    import shutil

    return shutil.copytree(run, tmp_path / "run")


def test_kill_during_sampling_and_during_the_report_then_the_same_command_completes(data, tmp_path):
    out = tmp_path / "run"
    proc = start("run", data, *RUN, "--out", out)
    wait_for(proc, "step    500/")
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert (out / "chain.h5").exists() and not (out / "summary.json").exists()

    proc = start("run", data, *RUN, "--out", out)
    lines = wait_for(proc, "writing the report")
    assert any("resuming the chain" in line and "step 500" in line for line in lines), lines
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()

    again = cli("run", data, *RUN, "--out", out)
    assert again.returncode == 0, again.stderr
    assert "is complete (900 steps" in again.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["sampler"]["steps"] == 900
    assert not list(out.glob(".*.tmp")), "a half-written file was left behind"
    # a finished run run again reports again: tests/test_run_cli.py::test_rerun_of_a_finished_run_reports_again...


def test_a_damaged_chain_gives_one_line_and_restart_starts_afresh(data, finished, tmp_path):
    out = copy_of(finished, tmp_path)
    chain = out / "chain.h5"
    size = chain.stat().st_size
    with open(chain, "r+b") as fh:  # a kill during a write / a full disk: the file is cut short
        fh.truncate(size // 3)
    damaged = cli("run", data, *RUN, "--steps", "300", "--quiet", "--out", out)
    assert damaged.returncode == 2
    lines = damaged.stderr.strip().splitlines()
    assert len(lines) == 1 and "damaged chain file" in lines[0] and "--restart" in lines[0], damaged.stderr
    assert "Traceback" not in damaged.stderr

    restarted = cli("run", data, *RUN, "--steps", "300", "--quiet", "--restart", "--out", out)
    assert restarted.returncode == 0, restarted.stderr
    assert (out / "chain.h5.old").stat().st_size == size // 3  # the old file kept aside
    assert json.loads((out / "summary.json").read_text())["sampler"]["steps"] == 300

    chain.write_bytes(b"")  # an empty file
    empty = cli("run", data, *RUN, "--steps", "300", "--quiet", "--out", out)
    assert empty.returncode == 2 and "empty file" in empty.stderr


def test_a_chain_whose_random_state_a_kill_broke_continues(data, finished, tmp_path):
    """emcee rewrites its random state (a string attribute in HDF5's global heap) at every step; a kill there
    leaves it unreadable ("Expected global heap object size does not match") with every step intact. The
    same command continues from the stored steps with a state drawn from the run's generator; the steps
    already stored are kept exactly."""
    import h5py
    import numpy as np

    out = copy_of(finished, tmp_path)
    chain = out / "chain.h5"
    with h5py.File(chain, "a") as f:  # what a reader sees after the kill: no readable random state
        for key in [k for k in f["mcmc"].attrs if k.startswith("random_state")]:
            del f["mcmc"].attrs[key]
        before = f["mcmc"]["chain"][:300].copy()
    more = cli("run", data, *RUN, "--steps", "600", "--out", out)
    assert more.returncode == 0, more.stderr
    assert "resuming the chain" in more.stderr and "Traceback" not in more.stderr
    with h5py.File(chain, "r") as f:
        assert f["mcmc"].attrs["iteration"] == 600
        np.testing.assert_array_equal(f["mcmc"]["chain"][:300], before)


def test_two_runs_on_one_folder_give_one_clear_error(data, tmp_path):
    out = tmp_path / "run"
    slow = ("--model", "paper", "--observables", "dop", "--seed", "2")  # the k_s/rho_d ridge: thousands of steps
    proc = start("run", data, *slow, "--steps", "20000", "--out", out)
    try:
        wait_for(proc, "step    500/")
        # paused, not ended: it holds the folder while the second run tries it, and its chain stays unfinished (on a
        # fast machine it had converged and been written before the second run got going)
        proc.send_signal(signal.SIGSTOP)
        second = cli("run", data, *slow, "--steps", "20000", "--out", out)
        assert proc.poll() is None, "the first run ended too soon for this test"
        assert second.returncode == 2
        lines = second.stderr.strip().splitlines()
        assert len(lines) == 1 and "in use by another" in lines[0], second.stderr
    finally:
        proc.kill()
        proc.wait()
    # the killed run held the lock only while it lived: the same command takes the folder and continues the chain
    # (stopped once it says so: running it to convergence would prove nothing more)
    lines = stopped_at("resuming the chain", "run", data, *slow, "--steps", "20000", "--out", out)
    assert not any("in use by another" in line for line in lines), lines


def test_a_failed_run_leaves_nothing_that_blocks_the_corrected_command(data, tmp_path):
    out = tmp_path / "run"
    bad = cli("run", data, *RUN, "--walkers", "3", "--out", out)
    assert bad.returncode == 2 and not out.exists()
    # the corrected command takes the folder and samples (stopped there: the finished runs of the other tests show
    # that a run completes)
    lines = stopped_at("sampling ", "run", data, *RUN, "--steps", "300", "--out", out)
    assert not any("error" in line for line in lines), lines
