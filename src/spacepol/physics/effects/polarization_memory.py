"""The ``polarization_memory`` effect: diffuse light that keeps part of its polarization in the beams' own s/p frames,

    M = (rho_mem / pi) diag(1, l, -l, c),   l = f_mem (1 - c_mem) / 2,   c = c_mem,

each beam's Stokes frame its own plane of incidence (s horizontal, along the surface). In the plane of incidence it
is a depolarizing mirror (s stays s, +45 deg becomes -45 deg); out of the plane it keeps the s/p frames instead of
turning with the scattering plane, as a multiply scattering medium layered parallel to its surface (pressed and
sintered powders) would keep the horizontal (s) field apart from the one with a vertical part (p). A phenomenological
term: the data decide whether they need it (``diagnose``).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ...priors import Uniform
from ..effect import Context, Effect
from ..parameter import Parameter


def retention(f_mem, c_mem):
    """(l, c) of diag(1, l, -l, c) from the effect's coordinates: the coherency eigenvalues of that matrix are
    (1 + c)/4 (twice) and (1 - c)(1 +- f)/4, all >= 0 for f, c in [-1, 1], so every coordinate pair is realizable."""
    return f_mem * (1.0 - c_mem) / 2.0, c_mem


class PolarizationMemory(Effect):
    """The ``polarization_memory`` effect: Lambertian light keeping part of its linear and circular polarization."""
    name = "polarization_memory"
    mirror_symmetric = True  # isotropic: M(-dphi) = D M(dphi) D
    parameters = (
        Parameter("rho_mem", "", Uniform(0.0, 1.0), 0.1, "albedo of the diffuse light that keeps part of its polarization",
                  physical=(0.0, 1.0)),
        Parameter("f_mem", "", Uniform(-1.0, 1.0), 0.0, "linear polarization kept, as a share of its realizable bound "
                  "(1 - c_mem) / 2 (> 0: s stays s, mirror-like)", physical=(-1.0, 1.0)),
        Parameter("c_mem", "", Uniform(-1.0, 1.0), 0.0, "circular polarization kept (> 0: the helicity kept in the "
                  "exit frame)", physical=(-1.0, 1.0)),
    )
    description = (
        "Diffuse (Lambertian) light that keeps part of its polarization in the beams' own s/p frames: f = (rho_mem / pi) "
        "diag(1, l, -l, c_mem) with l = f_mem (1 - c_mem) / 2, a depolarizing mirror in the plane of incidence whose frame "
        "stays with the planes of incidence out of it (a medium layered parallel to its surface). It changes only the "
        "Mueller matrix's diagonal: for unpolarized light it is Lambertian. Realizable over its whole prior (coherency "
        "eigenvalues (1 + c)/4 and (1 - c)(1 +- f_mem)/4) and reciprocal (a diagonal matrix is its own reciprocal image)."
    )
    removable = True
    intensity = "rho_mem"
    neutral = {"rho_mem": 0.0}

    def applicable(self, data) -> str | None:
        if "mueller" not in data.observables:
            return "acts on polarized incident light only: needs measured Mueller elements"
        return None

    def lobe(self, ctx: Context):
        scale = (ctx["rho_mem"] / np.pi) * jnp.ones_like(ctx.geometry.cos_tr)
        if not ctx.mueller:
            return ctx.depolarized(scale)
        linear, circular = retention(ctx["f_mem"], ctx["c_mem"])
        zero = jnp.zeros_like(scale)
        diagonal = (scale, linear * scale, -linear * scale, circular * scale)
        return jnp.stack([jnp.stack([diagonal[i] if j == i else zero for j in range(4)]) for i in range(4)])
