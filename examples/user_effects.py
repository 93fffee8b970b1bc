"""Writing your own effect: two ways, a class and a decorated function.

Use them from the command line with ``--effect examples/user_effects.py:OppositionSurge``
(then the name ``opposition_surge`` works in ``--model``), or register them for good through the
``spacepol.effects`` entry-point group of your own package::

    [project.entry-points."spacepol.effects"]
    opposition_surge = "my_package.effects:OppositionSurge"

Hooks are JAX code (they are compiled and evaluated for many parameter sets at once): compute with
``jax.numpy`` and return new arrays (``lobe.at[1:].multiply(f)``, not ``lobe[1:] *= f``).
"""

import jax.numpy as jnp
import numpy as np

from spacepol.priors import Uniform
from spacepol.physics.effects import Effect, Parameter, effect


class OppositionSurge(Effect):
    """Shadow hiding / coherent backscatter: a narrow, unpolarized brightening at zero phase angle."""

    name = "opposition_surge"
    parameters = (
        Parameter("b0", "sr^-1", Uniform(0.0, 1.0), 0.1, "peak BRDF added at zero phase angle", physical=(0.0, np.inf)),
        Parameter("h_deg", "deg", Uniform(0.5, 20.0), 5.0, "angular width of the surge", physical=(1e-3, 180.0)),
    )
    description = (
        "Opposition effect of particulate or porous surfaces: when source and detector coincide, "
        "each grain hides its own shadow, so the BRDF rises in a narrow peak around zero phase angle. "
        "Modelled as b0 exp(-phase / h) of unpolarized light; symmetric in source and detector."
    )

    def lobe(self, ctx):
        geo = ctx.geometry
        cos_phase = jnp.clip(jnp.sum(geo.k_i * geo.k_r, axis=-1), -1.0, 1.0)
        phase_deg = jnp.degrees(jnp.arccos(cos_phase))
        return ctx.depolarized(ctx["b0"] * jnp.exp(-phase_deg / ctx["h_deg"]))


@effect(
    "dop_scale_error",
    stage="modify_dop",
    parameters=[Parameter("gain", "", Uniform(0.8, 1.2), 1.0, "calibration gain of the DOP", physical=(0.0, np.inf))],
    description="A polarimeter whose DOP calibration is off by a constant gain (the DOP is clipped to 1).",
)
def DopScaleError(ctx, dop, gain):
    return jnp.minimum(gain * dop, 1.0)
