"""Reciprocity (Helmholtz): swapping source and detector leaves a BRDF unchanged and transposes its
Mueller matrix. Swapped, the source sits at the detector's azimuth, so dphi changes sign; in spacepol's
frames (DESIGN.md, "Geometry convention")

    M(theta_r -> theta_i, -dphi) = Q M(theta_i -> theta_r, dphi)^T Q,   Q = diag(1, 1, -1, 1),

which SCATMECH's reciprocal facet model satisfies to rounding (tested), as do spacepol's reciprocal effects.
(On an isotropic surface, mirror symmetry M(-dphi) = diag(1, 1, -1, -1) M(dphi) diag(1, 1, -1, -1) turns
this into D M^T D at the same dphi, D = diag(1, 1, 1, -1); the form here needs no isotropy.)
A model term that breaks it (the paper's cos(theta_r) body term, its shadowing function) cannot be the
physics of a passive surface; measured data that break it beyond their noise point to an instrument
or alignment error. Germer's PTFE set is reciprocal by construction of his measurement (Appl. Opt. 56,
9333, 2017); here it is checked on the rows whose swapped geometry was also measured.
"""

from __future__ import annotations

import numpy as np

from ..infer.measured_noise import RECIPROCITY_SIGNS, reciprocal_pairs
from ..physics.geometry import Geometry

Q = np.diag(RECIPROCITY_SIGNS)


def reciprocal_image(mueller) -> np.ndarray:
    """Q M^T Q for (4, 4, ...) Mueller arrays: what the swapped geometry must measure."""
    return np.einsum("ij,jk...,kl->il...", Q, np.swapaxes(mueller, 0, 1), Q)


def swapped(geometry: Geometry) -> Geometry:
    """Source and detector exchanged: theta_i <-> theta_r, dphi -> -dphi."""
    return Geometry(geometry.theta_r, geometry.theta_i, -geometry.dphi, geometry.wavelength_um)


def model_violation(model, params: dict, geometry: Geometry, max_angle_deg: float = 89.0) -> dict:
    """How far ``model`` at ``params`` is from reciprocal at the geometries (those whose swapped incidence
    angle is below ``max_angle_deg``): the relative BRDF change |f(r->i) / f(i->r) - 1| and the largest
    normalised element difference max_ij |m(r->i) - (D m(i->r)^T D)|, as median and 95th percentile."""
    keep = geometry.theta_r < max_angle_deg
    geo = Geometry(geometry.theta_i[keep], geometry.theta_r[keep], geometry.dphi[keep],
                   None if geometry.wavelength_um is None else geometry.wavelength_um[keep])
    forward = model.evaluate(params, geo, mueller=True, check=False).mueller
    backward = model.evaluate(params, swapped(geo), mueller=True, check=False).mueller
    return _compare(forward, backward)


def _compare(forward, backward) -> dict:
    f0, b0 = forward[0, 0], backward[0, 0]
    ok = (f0 > 0) & (b0 > 0)
    brdf = np.abs(b0[ok] / f0[ok] - 1.0)
    image = reciprocal_image(forward[..., ok] / f0[ok])
    diff = backward[..., ok] / b0[ok] - image
    elements = np.max(np.abs(diff), axis=(0, 1))
    return {"element_rms": float(np.sqrt(np.sum(diff**2) / (15 * max(int(ok.sum()), 1)))),  # compare with sqrt(2) x noise
            "brdf_relative_median": float(np.median(brdf)), "brdf_relative_p95": float(np.percentile(brdf, 95)),
            "element_median": float(np.median(elements)), "element_p95": float(np.percentile(elements, 95)),
            "n_geometries": int(ok.sum())}


data_pairs = reciprocal_pairs  # the measured geometries that are each other's swap (infer.measured_noise)


def data_violation(data, pairs: np.ndarray | None = None) -> dict:
    """Reciprocity of the measurement itself on its swapped pairs (``data_pairs``): the BRDF's relative
    difference and the normalised elements' largest difference per pair, median and 95th percentile.
    Needs the Mueller matrix."""
    pairs = data_pairs(data) if pairs is None else pairs
    if len(pairs) == 0 or data.mueller is None:
        return {"n_pairs": int(len(pairs))}
    forward, backward = data.mueller[..., pairs[:, 0]], data.mueller[..., pairs[:, 1]]  # sr^-1 (M_11 = BRDF)
    out = _compare(forward, backward)
    out.update({"n_pairs": int(len(pairs)), "n_self_pairs": int(np.sum(pairs[:, 0] == pairs[:, 1]))})
    return out
