"""The nested samplers' watchdog: a sampling loop that stops calling its likelihood stops with one clear error."""

import time

import pytest

from spacepol.errors import SamplerStalled
from spacepol.infer.engines.stall_guard import CallClock, stall_guard


def _spin(clock: CallClock, seconds: float, tick_every: float | None) -> None:
    """A stand-in for nautilus' loops: Python code for ``seconds``, calling the likelihood every ``tick_every``."""
    end = last = time.monotonic()
    end += seconds
    while time.monotonic() < end:
        if tick_every is not None and time.monotonic() - last >= tick_every:
            clock.tick()
            last = time.monotonic()


def test_a_loop_that_stops_calling_its_likelihood_is_stopped_with_a_clear_error():
    clock = CallClock()
    started = time.monotonic()
    with pytest.raises(SamplerStalled) as caught:
        with stall_guard(clock, "material kapton", seconds=0.5, poll_seconds=0.05):
            _spin(clock, 0.2, tick_every=0.02)  # calls at first ...
            _spin(clock, 30.0, tick_every=None)  # ... then draws without end
    waited = time.monotonic() - started
    message = str(caught.value)
    assert "material kapton" in message and "no likelihood call" in message and "--seed" in message, message
    assert clock.calls >= 5, clock.calls
    assert waited < 5.0, f"stopped after {waited:.1f} s, the limit 0.5 s"


def test_a_loop_that_keeps_calling_runs_to_its_end_and_nothing_arrives_after_it():
    # the control: three times the limit in all, calls all along
    clock = CallClock()
    with stall_guard(clock, "material kapton", seconds=0.5, poll_seconds=0.05):
        _spin(clock, 1.5, tick_every=0.05)
    _spin(clock, 0.3, tick_every=None)  # the watchdog has stopped: no stray exception lands here
    assert clock.calls >= 20


def test_the_command_line_says_a_stall_in_one_line_with_status_1(monkeypatch, capsys):
    from spacepol import cli, commands

    def stalled(args):
        raise SamplerStalled("material kapton: nested sampling stalled: no likelihood call for 120 s after 800 calls")

    monkeypatch.setattr(commands, "effects", stalled)
    assert cli.main(["effects"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("invert-mcmc: material kapton: nested sampling stalled"), err
