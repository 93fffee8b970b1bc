"""Scattering geometry of the microfacet model (paper eqs 2-5), computed with vectors.

Convention (DESIGN.md, fixed): the source is at (theta_i, phi_i = 0), the detector at
(theta_r, phi_r = -dphi); both direction vectors point away from the surface, so
dphi = 180 deg is the specular (forward) plane.  Stokes vectors of each beam are expressed in
the basis (s, p, d), right-handed, with d the propagation direction and s perpendicular to the
macroscopic plane of incidence (or scattering): S1 > 0 is s-polarized light.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import jax.numpy as jnp
import numpy as np

from .arrays import array_module

_TINY = 1e-12


def _signed_angle(xp, a, b, axis):
    """Angle that rotates unit vector ``a`` into ``b`` about ``axis`` (right-hand rule)."""
    cos = xp.sum(a * b, axis=-1)
    sin = xp.sum(xp.cross(a, b) * axis, axis=-1)
    return xp.arctan2(sin, cos)


@dataclass
class Geometry:
    """Angles (degrees) of a set of measurements, and every parameter-free term derived from them.

    ``theta_i``, ``theta_r``, ``dphi`` broadcast together; typically shape (N,), or (P, N)
    when an effect (``angle_offset``) makes the geometry depend on parameters.
    """

    theta_i: np.ndarray
    theta_r: np.ndarray
    dphi: np.ndarray
    wavelength_um: np.ndarray | None = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        angles = (self.theta_i, self.theta_r, self.dphi, self.wavelength_um)
        xp = array_module(*angles)
        self.xp = xp
        ti, tr, dp = xp.broadcast_arrays(*(xp.asarray(a, dtype=float) for a in angles[:3]))
        self.theta_i, self.theta_r, self.dphi = ti, tr, dp
        if self.wavelength_um is not None:
            self.wavelength_um = xp.broadcast_to(xp.asarray(self.wavelength_um, dtype=float), ti.shape[-1:])
        self._compute(xp)

    @property
    def shape(self):
        """The shape of the angle arrays."""
        return self.theta_i.shape

    @property
    def size(self) -> int:
        """The number of geometries."""
        return self.theta_i.shape[-1]

    def __reduce__(self):
        # sent to another process as its angles: the cached terms hold JAX arrays and a module reference
        wavelength = None if self.wavelength_um is None else np.asarray(self.wavelength_um)
        return Geometry, (np.asarray(self.theta_i), np.asarray(self.theta_r), np.asarray(self.dphi), wavelength)

    def cached(self, key, compute):
        """Memoise a parameter-free term (e.g. the paper's shadowing at fixed constants)."""
        if key not in self._cache:
            self._cache[key] = compute()
        return self._cache[key]

    _TERMS = ("theta_i", "theta_r", "dphi", "wavelength_um", "k_i", "k_r", "visible", "cos_ti", "cos_tr", "h",
              "cos_beta", "sin2_beta", "sin_beta", "sin_tan_beta", "cos_alpha", "sin_alpha", "tan2_alpha", "phi_h",
              "eta_i", "eta_r", "cos_2eta_r", "sin_2eta_r", "cos_2eta_i", "sin_2eta_i", "tan_ti", "tan_tr",
              "specular_jacobian", "sec4_alpha", "stokes_basis", "mueller_basis", "s_in", "s_out")

    def device_terms(self) -> dict:
        """Every term as a JAX array (made once per geometry): what the compiled model receives. Computing
        them outside matters: XLA on a CPU fuses a geometry-only term such as cos(2 eta) into every
        (parameter set, geometry) element that uses it and recomputes it there (7x on the Mueller lobe)."""
        return self.cached("device_terms", lambda: {name: None if getattr(self, name) is None else jnp.asarray(getattr(self, name))
                                                    for name in self._TERMS})

    @classmethod
    def from_terms(cls, terms: dict, all_visible: bool) -> "Geometry":
        """A geometry made of ``device_terms`` (inside compiled code), without computing anything."""
        geo = cls.__new__(cls)
        geo._cache, geo.xp, geo.all_visible = {}, jnp, all_visible
        for name, value in terms.items():
            setattr(geo, name, value)
        return geo

    def with_offset(self, delta_deg) -> "Geometry":
        """The same measurements seen through a goniometer whose zero is off by ``delta_deg``."""
        delta = delta_deg  # scalar, or (P, 1) for P parameter sets
        return Geometry(self.theta_i + delta, self.theta_r + delta, self.dphi, self.wavelength_um)

    def _compute(self, xp):
        ti = xp.radians(self.theta_i)
        tr = xp.radians(self.theta_r)
        phi_r = -xp.radians(self.dphi)
        zeros = xp.zeros_like(ti)

        # Direction vectors pointing away from the surface (a negative theta lies across the normal).
        k_i = xp.stack([xp.sin(ti), zeros, xp.cos(ti)], axis=-1)
        k_r = xp.stack([xp.sin(tr) * xp.cos(phi_r), xp.sin(tr) * xp.sin(phi_r), xp.cos(tr)], axis=-1)
        self.k_i, self.k_r = k_i, k_r
        # A source or detector pushed below the horizon (e.g. by angle_offset) sees nothing.
        self.visible = (k_i[..., 2] > 0) & (k_r[..., 2] > 0)
        # inside compiled code visibility is data: the mask is then always applied
        self.all_visible = bool(np.all(self.visible)) if xp is np else False
        self.cos_ti = xp.maximum(k_i[..., 2], _TINY)
        self.cos_tr = xp.maximum(k_r[..., 2], _TINY)

        # Half vector = facet normal for specular reflection.  eq 2: cos(2 beta) = k_i . k_r
        h_sum = k_i + k_r
        norm = xp.linalg.norm(h_sum, axis=-1)
        h = h_sum / xp.maximum(norm, _TINY)[..., None]
        self.h = h
        self.cos_beta = xp.clip(norm / 2.0, 0.0, 1.0)
        self.sin2_beta = xp.clip(1.0 - self.cos_beta**2, 0.0, 1.0)
        self.sin_beta = xp.sqrt(self.sin2_beta)
        self.sin_tan_beta = self.sin2_beta / xp.maximum(self.cos_beta, _TINY)
        # eq 3: cos(alpha) = (cos ti + cos tr) / (2 cos beta) = h_z
        self.cos_alpha = xp.clip(h[..., 2], _TINY, 1.0)
        h_xy = xp.hypot(h[..., 0], h[..., 1])
        self.sin_alpha = h_xy
        self.tan2_alpha = (h_xy / self.cos_alpha) ** 2
        # Azimuth of the facet normal; at alpha = 0 take the plane of incidence (phi = 0),
        # the limit along the specular plane.
        self.phi_h = xp.where(h_xy > _TINY, xp.arctan2(h[..., 1], h[..., 0]), 0.0)

        # Stokes bases.  Macroscopic s vectors come from the azimuth alone, so they have a
        # limit at normal incidence: s = z x (azimuth unit vector).
        s_in = xp.stack([zeros, xp.ones_like(ti), zeros], axis=-1)  # phi_i = 0
        s_out = xp.stack([-xp.sin(phi_r), xp.cos(phi_r), zeros], axis=-1)
        # A source or detector with negative theta sits at azimuth + 180 deg.
        s_in = s_in * xp.where(ti < 0, -1.0, 1.0)[..., None]
        s_out = s_out * xp.where(tr < 0, -1.0, 1.0)[..., None]
        self.s_in, self.s_out = s_in, s_out
        # Facet s vector: normal to the plane containing k_i, h (and k_r).
        s_f = xp.cross(h, k_i)
        s_f_norm = xp.linalg.norm(s_f, axis=-1, keepdims=True)
        s_f = xp.where(s_f_norm > 1e-9, s_f / xp.maximum(s_f_norm, _TINY), s_in)
        d_in, d_out = -k_i, k_r
        # eta_i rotates the incident (macro) basis into the facet basis about the incident
        # propagation direction; eta_r rotates the facet exit basis into the macro exit basis.
        self.eta_i = _signed_angle(xp, s_in, s_f, d_in)
        self.eta_r = _signed_angle(xp, s_f, s_out, d_out)
        self.cos_2eta_r = xp.cos(2 * self.eta_r)
        self.sin_2eta_r = xp.sin(2 * self.eta_r)
        self.cos_2eta_i = xp.cos(2 * self.eta_i)
        self.sin_2eta_i = xp.sin(2 * self.eta_i)
        self.stokes_basis = stokes_basis(xp, self.cos_2eta_r, self.sin_2eta_r)
        self.mueller_basis = mueller_basis(xp, self.cos_2eta_i, self.sin_2eta_i, self.cos_2eta_r, self.sin_2eta_r)
        self.tan_ti = xp.sqrt(1.0 - self.cos_ti**2) / self.cos_ti
        self.tan_tr = xp.sqrt(1.0 - self.cos_tr**2) / self.cos_tr

        # Common factor of the specular lobe: 1 / (4 cos^4(alpha) cos(ti) cos(tr)); the facet
        # distribution supplies the rest (eq 20 = D(alpha) * G * F / (4 cos ti cos tr)).
        self.specular_jacobian = 1.0 / (4.0 * self.cos_ti * self.cos_tr)
        self.sec4_alpha = self.cos_alpha**-4


def stokes_basis(xp, cos_2out, sin_2out):
    """(2, 4, ...): the Stokes vectors, in the macroscopic exit basis, of light that leaves a facet as
    (1, 0, 0, 0) and as (0, 1, 0, 0) in the facet's basis: the coefficients of (S0, S1) of eq 21's reflected
    light for unpolarized incidence."""
    zero, one = xp.zeros_like(cos_2out), xp.ones_like(cos_2out)
    return xp.stack([xp.stack([one, zero, zero, zero]), xp.stack([zero, cos_2out, -sin_2out, zero])])


def mueller_basis(xp, cos_2in, sin_2in, cos_2out, sin_2out):
    """(4, 4, 4, ...): L(eta_out) E L(eta_in) for E the four parts of a Fresnel Mueller matrix
    M_F = a E_a + b E_b + c E_c + d E_d = [[a, b, 0, 0], [b, a, 0, 0], [0, 0, c, d], [0, 0, -d, c]], with
    L(eta) = [[1, 0, 0, 0], [0, c, s, 0], [0, -s, c, 0], [0, 0, 0, 1]] (c, s = cos 2 eta, sin 2 eta): so
    eq 21's matrix is sum_e entry_e x basis[e], with geometry-only coefficients computed once per data set."""
    ci, si, co, so = xp.broadcast_arrays(cos_2in, sin_2in, cos_2out, sin_2out)
    zero, one = xp.zeros_like(ci), xp.ones_like(ci)
    rows = (
        ((one, zero, zero, zero), (zero, co * ci, co * si, zero), (zero, -so * ci, -so * si, zero), (zero, zero, zero, zero)),
        ((zero, ci, si, zero), (co, zero, zero, zero), (-so, zero, zero, zero), (zero, zero, zero, zero)),
        ((zero, zero, zero, zero), (zero, -so * si, so * ci, zero), (zero, -co * si, co * ci, zero), (zero, zero, zero, one)),
        ((zero, zero, zero, zero), (zero, zero, zero, so), (zero, zero, zero, co), (zero, si, -ci, zero)),
    )
    return xp.stack([xp.stack([xp.stack(row) for row in part]) for part in rows])


def default_grid() -> Geometry:
    """84 in-plane geometries on the specular side: theta_i in {20, 35, 50, 65}, theta_r 0-80 step 4."""
    theta_i = np.repeat([20.0, 35.0, 50.0, 65.0], 21)
    theta_r = np.tile(np.arange(0.0, 81.0, 4.0), 4)
    return Geometry(theta_i, theta_r, np.full(theta_i.shape, 180.0))
