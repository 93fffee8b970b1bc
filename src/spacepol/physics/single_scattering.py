"""Light scattered once inside the material, under a smooth interface: the effects ``volume`` (Code-Whitney
phase matrix over a Henyey-Greenstein phase function) and ``volume_rayleigh`` (the Rayleigh phase matrix), after
NIST SCATMECH's ``First_Diffuse_BRDF_Model`` (Germer, Proc. SPIE 10655, 1065504 (2018)): Fresnel transmission in,
one scattering with a polarized phase matrix in the scattering plane's basis, transmission out.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from . import fresnel
from .effect import Context, Effect

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
    h2 = (kx * kx + ky * ky) / (n * n)  # sin^2 of the internal angle; > 1 where no light gets through
    # there the direction is kept a unit vector at grazing (the transmission, ~mu', is ~0 anyway)
    shrink = jnp.where(h2 > 1.0 - _TINY, jnp.sqrt((1.0 - _TINY) / jnp.maximum(h2, _TINY)), 1.0)
    mu = jnp.sqrt(jnp.maximum(1.0 - h2 * shrink * shrink, _TINY))
    direction = -1.0 if into else 1.0  # down into the material, or up towards the surface
    horizontal = direction * shrink / n
    return (horizontal * kx, horizontal * ky, direction * mu), mu


# Stokes S_k = E^dagger sigma_k E in each beam's (s, p) basis (S1 > 0 for s; S3 = 2 Im(E_s* E_p), the sign of
# ``fresnel.matrix_entries``), so the Mueller matrix of a Jones matrix J is M_kl = tr(sigma_k J sigma_l J^dagger) / 2
_SIGMA = np.array([[[1, 0], [0, 1]], [[1, 0], [0, -1]], [[0, 1], [1, 0]], [[0, -1j], [1j, 0]]])
_JONES_TO_MUELLER = 0.5 * np.einsum("kab,lcd->klbcad", _SIGMA, _SIGMA)  # M_kl = Re sum C J[b, c] conj(J[a, d])


def jones_mueller(jones):
    """The Mueller matrix (4 x 4 nested lists of arrays) of a Jones matrix given as 2 x 2 nested lists of (real,
    imaginary) pairs: every product J[b, c] conj(J[a, d]) is formed once, in real arithmetic (complex arithmetic
    compiles ~3x slower on a CPU), and each element sums the few that its constant coefficients select."""
    products = {}

    def product(b, c, a, d):
        if (b, c, a, d) not in products:
            (xr, xi), (yr, yi) = jones[b][c], jones[a][d]
            products[b, c, a, d] = (xr * yr + xi * yi, xi * yr - xr * yi)
        return products[b, c, a, d]

    rows = []
    for k in range(4):
        row = []
        for l in range(4):
            total = 0.0
            for index in zip(*np.nonzero(np.abs(_JONES_TO_MUELLER[k, l]) > 1e-12)):
                coefficient = _JONES_TO_MUELLER[k, l][index]
                re, im = product(*index)
                if abs(coefficient.real) > 1e-12:
                    total = total + coefficient.real * re
                if abs(coefficient.imag) > 1e-12:
                    total = total - coefficient.imag * im
            row.append(total)
        rows.append(row)
    return rows


def _times(a, b, columns: int):
    """a @ b for 4 x 4 nested lists (b: ``columns`` leading columns), skipping structural zeros (plain 0.0)."""
    out = []
    for i in range(4):
        row = []
        for j in range(columns):
            terms = [a[i][k] * b[k][j] for k in range(4) if not _is_zero(a[i][k]) and not _is_zero(b[k][j])]
            row.append(sum(terms[1:], terms[0]) if terms else 0.0)
        out.append(row)
    return out


def _is_zero(x) -> bool:
    return isinstance(x, float) and x == 0.0


def _transmission_amplitudes(n, k, cos_t):
    """Fresnel amplitude transmission (t_s, t_p) from vacuum into N = n + ik at external angle theta, each as
    (real, imaginary), in real arithmetic: t_s = 2 c / (c + N cos(theta_t)), t_p = 2 N c / (N^2 c + N cos(theta_t)),
    with N cos(theta_t) = A + iB the principal root (``fresnel._a_b``)."""
    sin2 = 1.0 - cos_t * cos_t
    a, b = fresnel._a_b(n, k, sin2)
    ds_re, ds_im = cos_t + a, b
    inv_s = 2.0 * cos_t / (ds_re * ds_re + ds_im * ds_im)
    t_s = (ds_re * inv_s, -ds_im * inv_s)
    eps_re, eps_im = n * n - k * k, 2.0 * n * k
    dp_re, dp_im = eps_re * cos_t + a, eps_im * cos_t + b
    inv_p = 2.0 * cos_t / (dp_re * dp_re + dp_im * dp_im)
    # (n + ik) / (dp_re + i dp_im)
    t_p = ((n * dp_re + k * dp_im) * inv_p, (k * dp_re - n * dp_im) * inv_p)
    return t_s, t_p


def _scaled(pair, factor):
    return (pair[0] * factor, pair[1] * factor)


def henyey_greenstein(g, cos_theta):
    """Henyey-Greenstein phase function (per steradian, integrates to 1 over the sphere)."""
    return (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * cos_theta) ** 1.5)


def code_whitney(phase, cos_theta, linear, circular, asymmetry=0.0):
    """Code & Whitney's polarized phase matrix (ApJ 441, 400 (1995)) in the scattering plane's (parallel,
    perpendicular) basis, over any scalar phase function ``phase``: M12 = M21 = linear (cos^2 - 1)/(1 + cos^2),
    M33 = M44 = 2 cos / (1 + cos^2), M43 = -M34 = circular (1 - cos_f^2) / (1 + cos_f^2) with the angle of the
    circular term skewed, Theta_f = Theta (1 + 3.13 s exp(-7 Theta / pi)); all times ``phase``. With
    linear = 1, circular = 0 and the phase function 3 (1 + cos^2) / (16 pi) it is the Rayleigh matrix. Returns
    4 x 4 nested lists (0.0 where structurally zero)."""
    c = jnp.clip(cos_theta, -1.0 + _TINY, 1.0 - _TINY)
    theta = jnp.arccos(c)
    cf = jnp.cos(theta * (1.0 + 3.13 * asymmetry * jnp.exp(-7.0 * theta / np.pi)))
    a = 1.0 + c * c
    m12 = linear * (c * c - 1.0) / a
    m33 = 2.0 * c / a
    m43 = circular * (1.0 - cf * cf) / (1.0 + cf * cf)
    p12, p33, p43 = phase * m12, phase * m33, phase * m43
    return [[phase, p12, 0.0, 0.0], [p12, phase, 0.0, 0.0], [0.0, 0.0, p33, -p43], [0.0, 0.0, p43, p33]]


def rayleigh_phase(cos_theta):
    """Rayleigh's phase function 3 (1 + cos^2) / (16 pi) per steradian (integrates to 1 over the sphere)."""
    return 3.0 * (1.0 + cos_theta * cos_theta) / (16.0 * np.pi)


def single_scattering(ctx: Context, albedo, phase_matrix, depolarization=(0.0, 0.0), index=None):
    """The lobe of light scattered once under the interface: ``phase_matrix(cos Theta)`` -> 4 x 4 nested lists in the
    scattering plane's (parallel, perpendicular) basis; (4, 4, ...) with ``ctx.mueller``, else the Stokes vector
    for unpolarized light (the matrix's first column).

    The way in (transmission, then the change of basis into the scattering plane) and the way out are each one
    Jones matrix, J_in = R_in diag(t_s, t_p) and J_out = diag(t_s, t_p) R_out, so M = A_out P A_in with A the
    Mueller matrices of the two; the power factors n mu' / cos(theta) of the transmissions go into the scale.

    ``depolarization`` = (linear, circular): SCATMECH's depoll, depolc, the share of the light's linear and
    circular polarization lost on its path in and out (further scattering along the way), split between the two
    paths by their lengths: diag(1, 1 - d mu_r'/(mu_i' + mu_r'), ...) on the way in, mu_i' on the way out.

    ``index``: the interface's (n, k); None for the facets' n and k."""
    geo = ctx.geometry
    n, k = (ctx["n"], ctx["k"]) if index is None else index
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
    # changes of basis (real Jones matrices): (s_in, p_in) -> (par_in, perp) and (par_out, perp) -> (s_out, p_out)
    into = ((_dot(par_in, s_in), _dot(par_in, p_in)), (_dot(perp, s_in), _dot(perp, p_in)))
    out_of = ((_dot(s_out, par_out), _dot(s_out, perp)), (_dot(p_out, par_out), _dot(p_out, perp)))
    t_in = _transmission_amplitudes(n, k, geo.cos_ti)
    t_out = _transmission_amplitudes(n, k, geo.cos_tr)
    j_in = [[_scaled(t_in[c], into[r][c]) for c in range(2)] for r in range(2)]
    j_out = [[_scaled(t_out[r], out_of[r][c]) for c in range(2)] for r in range(2)]
    power = (n * mu_in / geo.cos_ti) * (n * mu_out / geo.cos_tr)
    scale = albedo * power / (n * n * (mu_in + mu_out))
    a_in = jones_mueller(j_in)
    columns = 4 if ctx.mueller else 1
    inner = _times(phase_matrix(_dot(d_in, d_out)), [row[:columns] for row in a_in], columns)
    total = _times(jones_mueller(j_out), inner, columns)
    linear, circular = depolarization
    if not (_is_zero(linear) and _is_zero(circular)):
        share_in, share_out = mu_out / (mu_in + mu_out), mu_in / (mu_in + mu_out)
        keep_in = (1.0, 1.0 - linear * share_in, 1.0 - linear * share_in, 1.0 - circular * share_in)
        keep_out = (1.0, 1.0 - linear * share_out, 1.0 - linear * share_out, 1.0 - circular * share_out)
        total = [[v if _is_zero(v) else v * keep_out[i] * keep_in[j] for j, v in enumerate(row)] for i, row in enumerate(total)]
    stacked = fresnel.combined([v * scale for row in total for v in row], _ELEMENT_BASIS[columns], 2)
    return stacked if ctx.mueller else stacked[:, 0]


# The elements are put in place as sum_e value_e x (one-hot e), not stacked: XLA fuses the producers of a stack into
# its loop and, on a CPU, computes them again for every element (the Stokes vector's four elements cost 4.6x the
# whole Mueller matrix, whose sixteen fusions it keeps apart); a value broadcast over the elements is computed once.
_ELEMENT_BASIS = {columns: np.eye(4 * columns).reshape(4 * columns, 4, columns) for columns in (1, 4)}


class SingleScattering(Effect):
    """What `volume` and `volume_rayleigh` share: the slot ``volume`` (they replace each other), the lobe
    ``single_scattering`` with the albedo ``intensity``; a member says its ``phase_matrix`` and, optionally, the
    polarization lost on the paths in and out (``depolarization``)."""

    requires = ("specular",)
    slot = "volume"
    removable = True

    def phase_matrix(self, ctx, cos_theta):
        """The phase matrix (4, 4, ...) at the internal scattering angle's cosine."""
        raise NotImplementedError

    def depolarization(self, ctx):
        """(linear, circular) shares of polarization lost on the paths in and out; default none."""
        return (0.0, 0.0)

    def index(self, ctx):
        """The interface's (n, k); default None, the facets' n and k."""
        return None

    def lobe(self, ctx):
        """The once-scattered lobe under the interface: Fresnel transmission in, the phase matrix, transmission out,
        over (mu_i' + mu_r')."""
        return single_scattering(ctx, ctx[self.intensity], lambda cos_theta: self.phase_matrix(ctx, cos_theta),
                                 self.depolarization(ctx), self.index(ctx))
