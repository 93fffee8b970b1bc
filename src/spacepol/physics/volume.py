"""Light scattered once inside the material, under a smooth interface: the effects ``volume`` (Code-Whitney
phase matrix over a Henyey-Greenstein phase function) and ``volume_rayleigh`` (the Rayleigh phase matrix).

The physics is NIST SCATMECH's ``First_Diffuse_BRDF_Model`` (Germer, Proc. SPIE 10655, 1065504 (2018)):
light refracts in through the interface (Fresnel transmission Mueller matrix T(theta_i) of N = n + ik, times
the power factor n cos(theta_i') / cos(theta_i)), scatters once with a polarized phase matrix P(Theta) that is
defined in the scattering plane's basis (parallel, perpendicular), and refracts out (T(theta_r)):

    M = w / (n^2 (mu_i' + mu_r')) T(theta_r) R_out P(Theta) R_in T(theta_i),

mu' the cosines of the internal (refracted) directions, Theta the internal scattering angle, R the rotations
between each beam's (s, p) basis and the scattering plane's, and w the single-scattering albedo (scattering
over attenuation, the host's absorption included). The factor 1/(mu_i' + mu_r') is the probability that light
scattered at depth leaves unattenuated, integrated over depth. Everything is reciprocal.

Both effects fill the slot ``volume``, so diagnose can swap one for the other; they add to any diffuse body
term (``subsurface`` is the multiple scattering under the same interface).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from ..infer.priors import Uniform
from . import fresnel
from .effect import Context, Effect
from .parameter import Parameter

_TINY = 1e-12


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _components(vectors):
    return tuple(vectors[..., j] for j in range(3))


def _internal_direction(k_out, n, into: bool):
    """The direction of propagation inside the material of a beam whose outside direction (pointing away from
    the surface) is ``k_out``: Snell's law, the horizontal part divided by n. Returns (vector, mu') with mu'
    the internal cosine; where no light gets through (n < sin(theta): total reflection) mu' is ~0."""
    kx, ky, _ = k_out
    mu = jnp.sqrt(jnp.maximum(1.0 - (kx * kx + ky * ky) / (n * n), _TINY))
    sign = -1.0 if into else 1.0
    return (sign * kx / n, sign * ky / n, sign * mu), mu


def _matrix(rows):
    """(4, 4, *shape) from nested rows of arrays or numbers, broadcast to one shape."""
    flat = jnp.broadcast_arrays(*[jnp.asarray(v, dtype=float) for row in rows for v in row])
    return jnp.stack(flat).reshape((4, 4) + flat[0].shape)


def _apply(matrix, x):
    """matrix @ x over the leading axes: x is a Mueller matrix (4, 4, ...) or a Stokes vector (4, ...)."""
    if x.ndim == matrix.ndim:
        return jnp.einsum("ij...,jk...->ik...", matrix, x)
    return jnp.einsum("ij...,j...->i...", matrix, x)


def _real_jones_mueller(j11, j12, j21, j22):
    """Mueller matrix of a real Jones matrix [[j11, j12], [j21, j22]] (a change of basis between two beams'
    bases, a rotation or a reflection). Independent of the sign convention of S3: M44 is the determinant."""
    h = 0.5
    return _matrix((
        (h * (j11**2 + j12**2 + j21**2 + j22**2), h * (j11**2 - j12**2 + j21**2 - j22**2), j11 * j12 + j21 * j22, 0.0),
        (h * (j11**2 + j12**2 - j21**2 - j22**2), h * (j11**2 - j12**2 - j21**2 + j22**2), j11 * j12 - j21 * j22, 0.0),
        (j11 * j21 + j12 * j22, j11 * j21 - j12 * j22, j11 * j22 + j12 * j21, 0.0),
        (0.0, 0.0, 0.0, j11 * j22 - j12 * j21),
    ))


def _transmission(n, k, cos_t, mu_internal):
    """Mueller matrix of Fresnel transmission from vacuum into N = n + ik at external angle theta (cosine
    ``cos_t``), in the (s, p) bases outside and inside, as a power ratio (the field's Mueller matrix times
    n mu' / cos(theta)): its M11 is the transmittance 1 - R for k = 0. By reciprocity the same matrix carries
    light out at that angle."""
    N = n + 1j * k
    sin2 = 1.0 - cos_t * cos_t
    root = jnp.sqrt(N * N - sin2)  # N cos(theta_t), principal branch
    t_s = 2.0 * cos_t / (cos_t + root)
    t_p = 2.0 * N * cos_t / (N * N * cos_t + root)
    a, b, c, d = fresnel.matrix_entries(t_s, t_p)
    power = n * mu_internal / cos_t
    return _matrix(((power * a, power * b, 0.0, 0.0), (power * b, power * a, 0.0, 0.0),
                    (0.0, 0.0, power * c, power * d), (0.0, 0.0, -power * d, power * c)))


def henyey_greenstein(g, cos_theta):
    """Henyey-Greenstein phase function (per steradian, integrates to 1 over the sphere)."""
    return (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * cos_theta) ** 1.5)


def code_whitney(phase, cos_theta, linear, circular, asymmetry=0.0):
    """Code & Whitney's polarized phase matrix (ApJ 441, 400 (1995)) in the scattering plane's (parallel,
    perpendicular) basis, over any scalar phase function ``phase``: M12 = M21 = linear (cos^2 - 1)/(1 + cos^2),
    M33 = M44 = 2 cos / (1 + cos^2), M43 = -M34 = circular (1 - cos_f^2) / (1 + cos_f^2) with the angle of the
    circular term skewed, Theta_f = Theta (1 + 3.13 s exp(-7 Theta / pi)); all times ``phase``. With
    linear = 1, circular = 0 and the phase function 3 (1 + cos^2) / (16 pi) it is the Rayleigh matrix."""
    c = jnp.clip(cos_theta, -1.0 + _TINY, 1.0 - _TINY)
    theta = jnp.arccos(c)
    cf = jnp.cos(theta * (1.0 + 3.13 * asymmetry * jnp.exp(-7.0 * theta / np.pi)))
    a = 1.0 + c * c
    m12 = linear * (c * c - 1.0) / a
    m33 = 2.0 * c / a
    m43 = circular * (1.0 - cf * cf) / (1.0 + cf * cf)
    return _matrix(((phase, phase * m12, 0.0, 0.0), (phase * m12, phase, 0.0, 0.0),
                    (0.0, 0.0, phase * m33, -phase * m43), (0.0, 0.0, phase * m43, phase * m33)))


def rayleigh_phase(cos_theta):
    """Rayleigh's phase function 3 (1 + cos^2) / (16 pi) per steradian (integrates to 1 over the sphere)."""
    return 3.0 * (1.0 + cos_theta * cos_theta) / (16.0 * np.pi)


def single_scattering(ctx: Context, albedo, phase_matrix):
    """The lobe of light scattered once under the interface: ``phase_matrix(cos Theta)`` -> (4, 4, ...) in the
    scattering plane's (parallel, perpendicular) basis; (4, 4, ...) with ``ctx.mueller``, else the Stokes
    vector for unpolarized light (the matrix's first column)."""
    geo = ctx.geometry
    n, k = ctx["n"], ctx["k"]
    k_i, k_r = _components(geo.k_i), _components(geo.k_r)
    d_in, mu_in = _internal_direction(k_i, n, into=True)
    d_out, mu_out = _internal_direction(k_r, n, into=False)
    s_in, s_out = _components(geo.s_in), _components(geo.s_out)
    p_in, p_out = _cross(d_in, s_in), _cross(d_out, s_out)  # (s, p, d) right-handed
    perp = _cross(d_in, d_out)
    norm2 = _dot(perp, perp)
    degenerate = norm2 < 1e-18  # exact backscatter: any perpendicular serves both beams
    inverse = 1.0 / jnp.sqrt(jnp.maximum(norm2, 1e-18))
    perp = tuple(jnp.where(degenerate, s, p * inverse) for p, s in zip(perp, s_in))
    par_in, par_out = _cross(d_in, perp), _cross(d_out, perp)
    into_plane = _real_jones_mueller(_dot(par_in, s_in), _dot(par_in, p_in), _dot(perp, s_in), _dot(perp, p_in))
    out_of_plane = _real_jones_mueller(_dot(s_out, par_out), _dot(s_out, perp), _dot(p_out, par_out), _dot(p_out, perp))
    scale = albedo / (n * n * (mu_in + mu_out))
    enter = _transmission(n, k, geo.cos_ti, mu_in)
    x = enter if ctx.mueller else enter[:, 0]
    for step in (into_plane, phase_matrix(_dot(d_in, d_out)), out_of_plane, _transmission(n, k, geo.cos_tr, mu_out)):
        x = _apply(step, x)
    return x * scale


class Volume(Effect):
    name = "volume"
    parameters = (
        Parameter("w_vol", "", Uniform(0.0, 1.0), 0.5, "single-scattering albedo of the volume scatterers (scattering over "
                  "attenuation, the host's absorption included)", physical=(0.0, 1.0)),
        Parameter("g_vol", "", Uniform(-0.9, 0.9), 0.0, "Henyey-Greenstein asymmetry of the phase function (> 0 forward)",
                  physical=(-0.999, 0.999)),
        Parameter("pl_vol", "", Uniform(-1.0, 1.0), 1.0, "largest degree of linear polarization of once-scattered light "
                  "(at 90 deg; 1 for Rayleigh scatterers, > 0 perpendicular to the scattering plane)", physical=(-1.0, 1.0)),
        Parameter("pc_vol", "", Uniform(-1.0, 1.0), 0.0, "the P34 (retardance) term's largest value: circular polarization "
                  "made from linear by one scattering", physical=(-1.0, 1.0)),
        Parameter("s_vol", "", Uniform(-1.0, 1.0), 0.0, "skew of the P34 term towards small angles (Code-Whitney s)",
                  fixed=True),
    )
    requires = ("specular",)
    description = (
        "Light scattered once inside the material (NIST SCATMECH's First_Diffuse_BRDF_Model with the "
        "Code-Whitney phase matrix): it refracts in through the interface (Fresnel transmission of the facets' "
        "n, k), scatters once with a Henyey-Greenstein phase function (asymmetry g_vol) carrying linear "
        "polarization (P12, largest at 90 deg: pl_vol) and retardance (P34: pc_vol), and refracts out; "
        "f = w_vol T(theta_r) P(Theta) T(theta_i) / (n^2 (mu_i' + mu_r')). Unlike multiply scattered light it "
        "stays polarized out of the plane of incidence and fills the linear Mueller block with structure that "
        "follows the internal scattering angle. Reciprocal. Add `subsurface` for the light scattered many times."
    )
    slot = "volume"
    removable = True
    intensity = "w_vol"
    neutral = {"w_vol": 0.0}

    def lobe(self, ctx):
        def phase_matrix(cos_theta):
            phase = henyey_greenstein(ctx["g_vol"], cos_theta)
            return code_whitney(phase, cos_theta, ctx["pl_vol"], ctx["pc_vol"], ctx["s_vol"])

        return single_scattering(ctx, ctx["w_vol"], phase_matrix)


class VolumeRayleigh(Effect):
    name = "volume_rayleigh"
    parameters = (
        Parameter("w_ray", "", Uniform(0.0, 1.0), 0.5, "single-scattering albedo of the small (Rayleigh) scatterers",
                  physical=(0.0, 1.0)),
    )
    requires = ("specular",)
    description = (
        "Light scattered once inside the material by scatterers much smaller than the wavelength: `volume` with "
        "the Rayleigh phase matrix (phase function 3 (1 + cos^2 Theta) / (16 pi), fully polarized at 90 deg, no "
        "retardance); f = w_ray T(theta_r) P(Theta) T(theta_i) / (n^2 (mu_i' + mu_r')). Reciprocal."
    )
    slot = "volume"
    removable = True
    intensity = "w_ray"
    neutral = {"w_ray": 0.0}

    def lobe(self, ctx):
        def phase_matrix(cos_theta):
            return code_whitney(rayleigh_phase(cos_theta), cos_theta, 1.0, 0.0)

        return single_scattering(ctx, ctx["w_ray"], phase_matrix)
