"""The nested samplers' watchdog: a sampling loop that stops calling its likelihood stops with one clear error."""

import time

import pytest

from spacepol.errors import SamplerStalled
from spacepol.infer.engines import stall_guard as guard
from spacepol.infer.engines.stall_guard import CallClock, stall_guard


class _Bound:
    n_sample = 0
    n_reject = 0


class _Sampler:
    """What the watchdog reads of a nautilus Sampler: its shells' bounds, each counting the points drawn and rejected."""

    def __init__(self):
        self.bounds = [_Bound()]


def _spin(clock: CallClock, seconds: float, tick_every: float | None, sampler=None, acceptance: float = 0.3) -> None:
    """A stand-in for nautilus' loops: Python code for ``seconds``, calling the likelihood every ``tick_every``,
    drawing 1,000 points at a time into ``sampler``'s newest shell and keeping ``acceptance`` of them."""
    end = last = time.monotonic()
    end += seconds
    while time.monotonic() < end:
        if sampler is not None:
            sampler.bounds[-1].n_sample += 1000
            sampler.bounds[-1].n_reject += 1000 - int(acceptance * 1000)
            time.sleep(0.001)
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


def test_a_shell_that_keeps_almost_none_of_its_draws_is_stopped_though_the_likelihood_is_still_called(monkeypatch):
    monkeypatch.setattr(guard, "MIN_DRAWS", 100_000)
    clock, sampler = CallClock(), _Sampler()
    with pytest.raises(SamplerStalled) as caught:
        with stall_guard(clock, "material kapton", sampler, seconds=30.0, poll_seconds=0.05):
            _spin(clock, 30.0, tick_every=0.05, sampler=sampler, acceptance=0.0)  # calls go on, the shell starves
    assert "newest shell kept 0 of" in str(caught.value), str(caught.value)
    # the control: a shell keeping 1 % of its draws (a healthy one keeps 1-50 %) runs to its end
    clock, sampler = CallClock(), _Sampler()
    with stall_guard(clock, "material kapton", sampler, seconds=30.0, poll_seconds=0.05):
        _spin(clock, 1.0, tick_every=0.05, sampler=sampler, acceptance=0.01)
    assert sampler.bounds[-1].n_sample > guard.MIN_DRAWS  # past the threshold, so the criterion was in force


def test_the_command_line_says_a_stall_in_one_line_with_status_1(monkeypatch, capsys):
    from spacepol import cli, commands

    def stalled(args):
        raise SamplerStalled("material kapton: nested sampling stalled: no likelihood call for 120 s after 800 calls")

    monkeypatch.setattr(commands, "effects", stalled)
    assert cli.main(["effects"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("invert-mcmc: material kapton: nested sampling stalled"), err


def test_ctrl_c_swallowed_inside_the_sampler_is_raised_again_at_the_next_likelihood_call():
    import os
    import signal

    def swallowed_interrupt():
        # as scikit-learn's MLP training inside nautilus does: Ctrl-C caught, a warning, training goes on
        try:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(1.0)
        except KeyboardInterrupt:
            return True
        return False

    original = signal.signal(signal.SIGINT, signal.default_int_handler)  # as in an interactive shell
    try:
        clock = CallClock()
        with pytest.raises(KeyboardInterrupt):
            with stall_guard(clock, "material kapton", seconds=30.0, poll_seconds=0.05):
                assert swallowed_interrupt()
                clock.tick()
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back as it was
        # the control: without the guard, the swallowed interrupt is lost and the next call goes on
        clock = CallClock()
        assert swallowed_interrupt()
        clock.tick()
        assert clock.calls == 1
        # Ctrl-C ignored (a run under nohup) stays ignored inside the guard
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        with stall_guard(clock, "material kapton", seconds=30.0, poll_seconds=0.05):
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            assert not swallowed_interrupt()
            clock.tick()
    finally:
        signal.signal(signal.SIGINT, original)
