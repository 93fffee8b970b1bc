"""A watchdog for nested sampling's exploration: a run that stops calling its likelihood is stopped with a clear error.

nautilus draws new points from each shell by rejection: points from the shell's ellipsoids, kept where its neural
network says they lie inside. Where the network accepts almost nothing of the ellipsoids (a multimodal attitude
posterior of a light curve is one case; upstream: johannesulf/nautilus issues 26 and 28) that loop runs for hours
and calls no likelihood, so neither a call budget nor nautilus' own ``timeout`` (checked between batches) stops it.
A healthy run calls its likelihood several times a second, so ``STALL_SECONDS`` without a call is a stall. The
watchdog thread then raises ``SamplerStalled`` in the sampling thread (``PyThreadState_SetAsyncExc``: delivered at
the next Python instruction of the rejection loop, which is Python code).
"""

from __future__ import annotations

import ctypes
import threading
import time
from contextlib import contextmanager

from ...errors import SamplerStalled

# seconds without a likelihood call that make a stall: ~100x the longest gap of a healthy run
STALL_SECONDS = 120.0


class CallClock:
    """When the likelihood was last called: ``tick()`` from inside it."""

    def __init__(self):
        self.last = time.monotonic()
        self.calls = 0

    def tick(self) -> None:
        """Record a likelihood call now."""
        self.last = time.monotonic()
        self.calls += 1


def _raise_in(thread_id: int, exception: type[BaseException]) -> None:
    ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(thread_id), ctypes.py_object(exception))


@contextmanager
def stall_guard(clock: CallClock, what: str, seconds: float = STALL_SECONDS, poll_seconds: float = 0.5):
    """Run the block under a watchdog: where ``clock`` records no likelihood call for ``seconds``, the block stops
    with ``SamplerStalled`` naming ``what`` and how many calls it had made."""
    target = threading.get_ident()
    lock, state = threading.Lock(), {"active": True, "fired": False}

    def watch():
        while True:
            time.sleep(poll_seconds)
            with lock:
                if not state["active"]:
                    return
                if time.monotonic() - clock.last > seconds:
                    state["fired"] = True
                    _raise_in(target, SamplerStalled)
                    return

    clock.last = time.monotonic()
    watchdog = threading.Thread(target=watch, name="spacepol-stall-guard", daemon=True)
    watchdog.start()
    try:
        try:
            yield clock
        finally:
            with lock:
                state["active"] = False
    except SamplerStalled:
        if not state["fired"]:
            raise
        raise SamplerStalled(
            f"{what}: nested sampling stalled: no likelihood call for {seconds:.0f} s after {clock.calls} calls "
            "(nautilus drawing new points from bounds its neural network rejects nearly all of); try another --seed "
            "or more --live points") from None
    finally:
        watchdog.join()
