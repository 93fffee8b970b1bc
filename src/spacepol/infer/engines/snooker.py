"""The differential-evolution snooker move (ter Braak & Vrugt, Stat. Comput. 18, 435 (2008)), as emcee means it.

emcee 3.1.6 (the newest release) projects the difference of two walkers on ``delta / sqrt(|delta|)`` instead of
the unit vector ``delta / |delta|`` and weighs the Metropolis ratio with (d - 1) / 2 instead of d - 1: its chain
does not keep the posterior. Measured on a 10-dimensional Gaussian (``tests/test_snooker.py``): the snooker alone
gives E[-2 log p] = 6.3 instead of 10 (variances 0.63 of the truth), mixed 20 % with DE moves 9.5 (0.95); on PTFE
(``paper+lambertian``, 278 geometries) emcee's posterior SDs were 0.87-0.90 of the exact ones. Fixed upstream in
dfm/emcee pull request 531 (merged December 2024, not yet released); this is that fix.
"""

from __future__ import annotations

import emcee
import numpy as np


class DESnookerMove(emcee.moves.DESnookerMove):
    """emcee's snooker move with the unit vector and the (d - 1) Jacobian exponent of ter Braak & Vrugt (2008)."""

    def get_proposal(self, s, c, random):
        """emcee's move interface: proposals for the walkers ``s`` from the complementary ensemble ``c``, with their
        log Metropolis factors."""
        count, ndim = s.shape
        sizes = list(map(len, c))
        q = np.empty_like(s)
        metropolis = np.empty(count, dtype=np.float64)
        for i in range(count):
            w = np.array([c[j][random.randint(sizes[j])] for j in range(3)])
            random.shuffle(w)
            z, z1, z2 = w
            delta = s[i] - z
            norm = np.linalg.norm(delta)
            u = delta / norm
            q[i] = s[i] + u * self.gammas * (np.dot(u, z1) - np.dot(u, z2))
            metropolis[i] = np.log(np.linalg.norm(q[i] - z)) - np.log(norm)
        return q, (ndim - 1.0) * metropolis
