"""A watchdog for nested sampling's exploration: a run that stops making progress is stopped with a clear error.

nautilus draws new points from each shell by rejection: points from the shell's ellipsoids, kept where its neural
network says they lie inside. Where the network accepts almost nothing of the ellipsoids (a multimodal attitude
posterior of a light curve; upstream: johannesulf/nautilus issues 26 and 28) that loop runs for hours, calling the
likelihood rarely or never, so neither a call budget nor nautilus' own ``timeout`` (checked between batches) stops
it. Two signs, each far from a healthy run: no likelihood call for ``STALL_SECONDS``, or the newest shell's bound
keeping fewer than ``MIN_ACCEPTANCE`` of ``MIN_DRAWS`` or more points drawn (a healthy shell keeps 1-50 %): then
``SamplerStalled`` is raised in the sampling thread (``PyThreadState_SetAsyncExc``). The guard also keeps Ctrl-C,
which scikit-learn's network training would swallow (details: docs/internals.md).
"""

from __future__ import annotations

import ctypes
import signal
import threading
import time
from contextlib import contextmanager

from ...errors import SamplerStalled

# seconds without a likelihood call that make a stall: ~100x the longest gap of a healthy run
STALL_SECONDS = 120.0
# a shell's bound that has drawn MIN_DRAWS points and kept under MIN_ACCEPTANCE of them: a stall in counts, not time
MIN_DRAWS = 20_000_000
MIN_ACCEPTANCE = 1e-4


class CallClock:
    """When the likelihood was last called: ``tick()`` from inside it."""

    def __init__(self):
        self.last = time.monotonic()
        self.calls = 0
        self.interrupted = False

    def tick(self) -> None:
        """Record a likelihood call now; raise ``KeyboardInterrupt`` where Ctrl-C came since (``stall_guard``)."""
        if self.interrupted:
            raise KeyboardInterrupt
        self.last = time.monotonic()
        self.calls += 1


@contextmanager
def _interrupts_kept(clock: CallClock):
    """Within the block, Ctrl-C raises KeyboardInterrupt as usual and also marks ``clock``, whose next ``tick``
    raises it again: code that catches and drops the first (scikit-learn's MLP training, inside nautilus) cannot
    swallow it. Where Ctrl-C does not raise KeyboardInterrupt already (ignored, as under nohup, or handled by the
    caller) or outside the main thread, where signals cannot be handled, the block runs as it is."""
    if threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        yield
        return

    def interrupted(signum, frame):
        clock.interrupted = True
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
        clock.interrupted = False


def _raise_in(thread_id: int, exception: type[BaseException]) -> None:
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id), ctypes.py_object(exception))


def starved(sampler) -> str:
    """Why ``sampler``'s (a nautilus Sampler's) newest shell counts as stalled, in words; "" where it does not."""
    bounds = getattr(sampler, "bounds", None)
    if not bounds:
        return ""
    drawn, rejected = getattr(bounds[-1], "n_sample", 0), getattr(bounds[-1], "n_reject", 0)
    if drawn < MIN_DRAWS or drawn - rejected >= MIN_ACCEPTANCE * drawn:
        return ""
    return f"its newest shell kept {drawn - rejected} of {drawn:.3g} points drawn"


@contextmanager
def stall_guard(clock: CallClock, what: str, sampler=None, seconds: float = STALL_SECONDS, poll_seconds: float = 0.5):
    """Run the block under a watchdog: where ``clock`` records no likelihood call for ``seconds``, or ``sampler``'s
    newest shell keeps almost none of the points it draws (``starved``), the block stops with ``SamplerStalled``
    naming ``what`` and the sign."""
    target = threading.get_ident()
    lock, state = threading.Lock(), {"active": True, "sign": ""}

    def watch():
        while True:
            time.sleep(poll_seconds)
            with lock:
                if not state["active"]:
                    return
                idle = time.monotonic() - clock.last
                sign = f"no likelihood call for {idle:.0f} s" if idle > seconds else starved(sampler)
                if sign:
                    state["sign"] = sign
                    _raise_in(target, SamplerStalled)
                    return

    clock.last = time.monotonic()
    watchdog = threading.Thread(target=watch, name="spacepol-stall-guard", daemon=True)
    watchdog.start()
    try:
        try:
            with _interrupts_kept(clock):
                yield clock
        finally:
            with lock:
                state["active"] = False
    except SamplerStalled:
        if not state["sign"]:
            raise
        raise SamplerStalled(
            f"{what}: nested sampling stalled after {clock.calls} likelihood calls: {state['sign']} (nautilus drawing "
            "new points from bounds its neural network rejects nearly all of); try another --seed or more --live "
            "points") from None
    finally:
        watchdog.join()
