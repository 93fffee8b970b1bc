"""emcee's HDF5 backend, written every ``every`` steps instead of every step.

h5py opens the file, checks it and writes five attributes for each step, which costs more than an emcee step
of a small likelihood itself (``benchmarks/inversion_speed.py``). Here steps wait in memory and go to the file in one write of ``every`` rows,
with the random state of the last of them; the chain is also written before it is read (autocorrelation,
reports) and by ``flush()``. A kill loses at most the steps since the last write: the file always holds a
consistent chain and the random state that continues it, so the same command resumes it and gives the
chain an uninterrupted run would have given (``tests/test_sampler.py``).
"""

from __future__ import annotations

import emcee
import numpy as np


class BufferedHDFBackend(emcee.backends.HDFBackend):
    """emcee's HDF5 backend that writes every ``every`` steps instead of each one (an HDF5 write per step cost more
    than a step); ``flush`` writes what is pending, and every read flushes first, so a resumed chain is the
    same."""

    def __init__(self, filename, name="mcmc", every: int = 100, **kwargs):
        super().__init__(filename, name=name, **kwargs)
        self.every = every
        self._pending: list = []

    def save_step(self, state, accepted):
        blobs = None if state.blobs is None else np.array(state.blobs)
        self._pending.append((np.array(state.coords), np.array(state.log_prob), blobs, np.array(accepted),
                              state.random_state))
        if len(self._pending) >= self.every:
            self.flush()

    def flush(self) -> None:
        """Write the steps waiting in memory."""
        if not self._pending:
            return
        pending, self._pending = self._pending, []
        with self.open("a") as f:
            g = f[self.name]
            start = int(g.attrs["iteration"])
            stop = start + len(pending)
            g["chain"][start:stop] = np.stack([p[0] for p in pending])
            g["log_prob"][start:stop] = np.stack([p[1] for p in pending])
            if pending[0][2] is not None:
                g["blobs"][start:stop] = np.stack([p[2] for p in pending])
            g["accepted"][:] += np.sum([p[3] for p in pending], axis=0)
            for i, value in enumerate(pending[-1][4]):
                g.attrs[f"random_state_{i}"] = value
            g.attrs["iteration"] = stop

    # everything that reads the file sees the waiting steps too
    @property
    def iteration(self):
        """Steps stored so far, the pending ones included."""
        return super().iteration + len(self._pending)

    @property
    def accepted(self):
        """Accepted proposals per walker (after writing what is pending)."""
        self.flush()
        return super().accepted

    @property
    def random_state(self):
        """The random state after the latest step, pending or stored."""
        return self._pending[-1][4] if self._pending else super().random_state

    def get_value(self, name, flat=False, thin=1, discard=0):
        """A stored array (chain, log_prob, ...) after writing what is pending; emcee's arguments."""
        self.flush()
        return super().get_value(name, flat=flat, thin=thin, discard=discard)

    def grow(self, ngrow, blobs):
        self.flush()
        super().grow(ngrow, blobs)
