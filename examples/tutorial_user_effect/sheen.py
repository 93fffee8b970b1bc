"""A new effect in a few lines: the grazing sheen of a fibrous surface (e.g. a thermal blanket's
woven outer layer). Fibres lying along the surface scatter light that arrives and leaves near
grazing; many scattering events leave it unpolarized. So it brightens grazing geometries and
lowers their DOP, which no built-in effect does in that way.

The hook is JAX code (plain arithmetic here; use ``jax.numpy`` for functions).
"""

from spacepol.priors import Uniform
from spacepol.physics.effects import Parameter, effect


@effect(
    "sheen",
    stage="lobe",  # an additive lobe of scattered light
    parameters=[Parameter("b_sheen", "sr^-1", Uniform(0.0, 1.0), 0.1, "sheen BRDF at grazing in and out", physical=(0.0, 10.0))],
    description="Grazing sheen of fibres: unpolarized light b sin^2(theta_i) sin^2(theta_r), strongest at grazing.",
)
def Sheen(ctx, b_sheen):
    sin2_i = 1.0 - ctx.geometry.cos_ti**2
    sin2_r = 1.0 - ctx.geometry.cos_tr**2
    return ctx.depolarized(b_sheen * sin2_i * sin2_r)
