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
        log Metropolis factors. For each walker one member of each of the three other subsets, in random order (z, z1,
        z2); all walkers at once (a loop over walkers cost more than the likelihood of a small problem)."""
        count, ndim = s.shape
        picked = np.stack([c[j][random.randint(len(c[j]), size=count)] for j in range(3)], axis=1)  # (count, 3, D)
        order = np.argsort(random.random_sample((count, 3)), axis=1)  # a uniform random permutation per walker
        z, z1, z2 = np.moveaxis(picked[np.arange(count)[:, None], order], 1, 0)
        delta = s - z
        norm = np.linalg.norm(delta, axis=1)
        u = delta / norm[:, None]
        q = s + u * (self.gammas * (np.einsum("ij,ij->i", u, z1) - np.einsum("ij,ij->i", u, z2)))[:, None]
        metropolis = np.log(np.linalg.norm(q - z, axis=1)) - np.log(norm)
        return q, (ndim - 1.0) * metropolis
