"""Full-Mueller measurement sets rendered by an independent implementation (NIST SCATMECH via pySCATMECH):
Beckmann facets (Facet_BRDF_Model, Gaussian slopes s = sqrt(2) sigma, no shadowing: spacepol's `specular`)
plus one hidden effect or none:

* "depolarization": a share d of the facet light depolarized, (1 - d) M + d M11 diag(1, 0, 0, 0);
* "extinction": an analyser of efficiency e in front of the detector, diag(1, e, e, e) M;
* "subsurface": SCATMECH's Diffuse_Subsurface_BRDF_Model added (albedo rho under the smooth interface).

Each set holds the BRDF (M11, relative noise) and the 15 normalised elements m_ij (absolute noise)."""

from __future__ import annotations

import numpy as np

from spacepol.io.measurements import Dataset
from spacepol.physics.geometry import Geometry

MATERIAL = {"n": 1.5, "k": 0.0, "sigma": 0.2}  # a smooth-ish dielectric (paint, plastic)
HIDDEN = {"none": {}, "depolarization": {"d": 0.3}, "extinction": {"e": 0.8}, "subsurface": {"rho": 0.6}}


def geometry() -> Geometry:
    """In-plane sweeps at theta_i 20, 45, 65 deg and out-of-plane rings at theta_i 45 deg (dphi 150, 120)."""
    ti = np.repeat([20.0, 45.0, 65.0], 13)
    tr = np.tile(np.linspace(0.0, 78.0, 13), 3)
    ti2 = np.full(16, 45.0)
    tr2 = np.tile(np.linspace(10.0, 70.0, 8), 2)
    dp2 = np.repeat([150.0, 120.0], 8)
    return Geometry(np.concatenate([ti, ti2]), np.concatenate([tr, tr2]), np.concatenate([np.full(39, 180.0), dp2]))


def mueller_set(kind: str, noise_m: float = 0.005, noise_brdf: float = 0.02, seed: int = 0) -> Dataset:
    from pySCATMECH.brdf import BRDF_Model

    m = MATERIAL
    facets = BRDF_Model("Facet_BRDF_Model", {"lambda": 0.633, "substrate": f"({m['n']},{m['k']})", "type": 0,
                                            "sdf": "Gaussian_Slope_Distribution_Function", "sdf.s": np.sqrt(2) * m["sigma"]})
    under = BRDF_Model("Diffuse_Subsurface_BRDF_Model", {"lambda": 0.633, "substrate": f"({m['n']},0)", "type": 0,
                                                        "reflectance": "Table_Reflectance",
                                                        "reflectance.table": HIDDEN["subsurface"]["rho"]})
    g = geometry()
    mueller = np.empty((4, 4, g.size))
    for j, (ti, tr, dphi) in enumerate(zip(g.theta_i, g.theta_r, g.dphi)):
        args = np.radians([ti, tr, 180.0 - dphi])  # SCATMECH's phi_s = 0 is the specular direction
        M = np.array(facets.MuellerBRDF(*args))
        if kind == "depolarization":
            d = HIDDEN[kind]["d"]
            M = (1 - d) * M + d * M[0, 0] * np.diag([1.0, 0, 0, 0])
        elif kind == "extinction":
            M = np.diag([1.0] + [HIDDEN[kind]["e"]] * 3) @ M
        elif kind == "subsurface":
            M = M + np.array(under.MuellerBRDF(*args))
        mueller[:, :, j] = M
    data = measured(g, mueller, noise_m, noise_brdf, np.random.default_rng(seed), f"SCATMECH render ({kind})")
    # the same measurement reduced to DOP (from the first column) and BRDF
    noisy = data.mueller / data.mueller[0, 0]
    data.dop = np.clip(np.sqrt(np.sum(noisy[1:, 0] ** 2, axis=0)), 0, 1)
    data.dop_err = np.full(g.size, noise_m)
    return data


def measured(g: Geometry, mueller, noise_m: float, noise_brdf: float, rng: np.random.Generator, source: str) -> Dataset:
    """A measurement of the Mueller matrices ``mueller`` (4, 4, N) at ``g``: the 15 normalised elements with
    absolute noise ``noise_m`` (clipped to [-1, 1]), the BRDF with relative noise ``noise_brdf``, both errors in
    the file."""
    noisy = mueller / mueller[0, 0] + noise_m * rng.standard_normal(mueller.shape)
    noisy[0, 0] = 1.0
    brdf = mueller[0, 0] * (1 + noise_brdf * rng.standard_normal(g.size))
    data = Dataset(g.theta_i, g.theta_r, g.dphi, wavelength_um=np.full(g.size, 0.633))
    data.mueller = np.clip(noisy, -1, 1) * brdf
    data.mueller_err = np.full((4, 4, g.size), noise_m)
    data.brdf, data.brdf_err = brdf, noise_brdf * mueller[0, 0]
    data.source = source
    return data


# PTFE-like: a rough dielectric of index 1.35, a weak facet lobe, strong multiple scattering under the surface and,
# in the "volume" sets, light scattered once inside (First_Diffuse_BRDF_Model, Code-Whitney over Henyey-Greenstein)
PTFE_LIKE = {"n": 1.35, "k": 0.0, "sigma": 0.3, "ks": 0.15, "rho_s": 0.9,
             "w_vol": 0.8, "g_vol": 0.2, "pl_vol": 0.5, "pc_vol": 0.3, "s_vol": 0.0}
_LOG_ABSORPTION = -1.38629  # SCATMECH's albedo 1 / (1 + exp(la)) = 0.8 (w_vol), to SCATMECH's 6 digits


def ptfe_like_geometry(size: int = 280) -> Geometry:
    """About ``size`` of the geometries NIST measured PTFE at (theta_i 0-75 deg, theta_r to 80 deg, 192 azimuths;
    data/ptfe), every k-th row, plus the rows of its reciprocal pairs (so the set measures its own noise)."""
    from spacepol.infer.measured_noise import reciprocal_pairs
    from spacepol.io.measurements import read_measurements
    from spacepol.paths import bundled

    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    pairs = reciprocal_pairs(data)
    rows = np.union1d(np.arange(0, len(data), max(1, len(data) // size)), pairs.ravel())
    return Geometry(data.theta_i[rows], data.theta_r[rows], data.dphi[rows])


def _surface_and_body(m: dict, substrate: str):
    """SCATMECH's Beckmann facets and its subsurface multiple scattering (albedo rho_s) of ``m`` under ``substrate``."""
    from pySCATMECH.brdf import BRDF_Model

    facets = BRDF_Model("Facet_BRDF_Model", {"lambda": 0.633, "substrate": substrate, "type": 0,
                                            "sdf": "Gaussian_Slope_Distribution_Function", "sdf.s": np.sqrt(2) * m["sigma"]})
    under = BRDF_Model("Diffuse_Subsurface_BRDF_Model", {"lambda": 0.633, "substrate": substrate, "type": 0,
                                                        "reflectance": "Table_Reflectance", "reflectance.table": m["rho_s"]})
    return facets, under


def _ptfe_like_render(m: dict, facets, under, once, noise_m, noise_brdf, seed, source) -> Dataset:
    """ks x facets + subsurface (+ ``once``, where not None) at ``ptfe_like_geometry``, measured with that noise."""
    g = ptfe_like_geometry()
    mueller = np.empty((4, 4, g.size))
    for j, (ti, tr, dphi) in enumerate(zip(g.theta_i, g.theta_r, g.dphi)):
        args = np.radians([ti, tr, 180.0 - dphi])
        M = m["ks"] * np.array(facets.MuellerBRDF(*args)) + np.array(under.MuellerBRDF(*args))
        if once is not None:
            M = M + np.array(once.MuellerBRDF(*args))
        mueller[:, :, j] = M
    return measured(g, mueller, noise_m, noise_brdf, np.random.default_rng(seed), source)


def ptfe_like_set(volume: bool = True, noise_m: float = 0.012, noise_brdf: float = 0.02, seed: int = 0,
                  truth: dict = PTFE_LIKE) -> Dataset:
    """Facets (weight ks) + SCATMECH's subsurface multiple scattering + (``volume``) first-order volume
    scattering, at ``ptfe_like_geometry``; the 15 normalised elements with absolute noise ``noise_m`` and the
    BRDF with relative noise ``noise_brdf``, both given in the file as errors."""
    from pySCATMECH.brdf import BRDF_Model

    m = truth
    substrate = f"({m['n']},{m['k']})"
    facets, under = _surface_and_body(m, substrate)
    once = BRDF_Model("First_Diffuse_BRDF_Model", {
        "lambda": 0.633, "substrate": substrate, "type": 0, "phase_function": "CodeWhitney_Phase_Function",
        "phase_function.phase_function": "Henyey_Greenstein_Phase_Function", "phase_function.phase_function.g": m["g_vol"],
        "phase_function.plmax": m["pl_vol"], "phase_function.pcmax": m["pc_vol"], "phase_function.s": m["s_vol"],
        "phase_function.log_absorption": _LOG_ABSORPTION, "phase_function.log_scattering": 0})
    return _ptfe_like_render(m, facets, under, once if volume else None, noise_m, noise_brdf, seed,
                             f"SCATMECH PTFE-like render ({'with' if volume else 'without'} volume scattering)")


# PTFE-like with light scattered once by pores: air spheres (radius 0.15 um, size parameter 2.0) in the polymer,
# their Mie phase matrix (SCATMECH's SphericalScatterer_Phase_Function; outside the Code-Whitney family and the
# spline of phase_matrix), refraction through the polymer's interface, and linear depolarization along the legs
PTFE_PORES = {"n": 1.35, "sigma": 0.3, "ks": 0.15, "rho_s": 0.5, "radius_um": 0.15, "depoll": 0.2}


def ptfe_pores_set(volume: bool = True, noise_m: float = 0.012, noise_brdf: float = 0.02, seed: int = 0,
                   truth: dict = PTFE_PORES) -> Dataset:
    """Facets (weight ks) + SCATMECH's subsurface multiple scattering + (``volume``) first-order scattering by air
    pores in the polymer (Mie, ``First_Diffuse_BRDF_Model`` with ``SphericalScatterer_Phase_Function``), at
    ``ptfe_like_geometry``; noise as ``ptfe_like_set``."""
    from pySCATMECH.brdf import BRDF_Model

    m = truth
    substrate = f"({m['n']},0)"
    facets, under = _surface_and_body(m, substrate)
    once = BRDF_Model("First_Diffuse_BRDF_Model", {
        "lambda": 0.633, "substrate": substrate, "type": 0, "depoll": m["depoll"], "depolc": 0.0,
        "phase_function": "SphericalScatterer_Phase_Function", "phase_function.scatterer": "MieScatterer",
        "phase_function.scatterer.lambda": 0.633, "phase_function.scatterer.medium": substrate,
        "phase_function.scatterer.radius": m["radius_um"], "phase_function.scatterer.sphere": "(1,0)",
        "phase_function.volume_density": 0.01})
    return _ptfe_like_render(m, facets, under, once if volume else None, noise_m, noise_brdf, seed,
                             f"SCATMECH PTFE-like render with pores ({'with' if volume else 'without'} volume scattering)")
