"""polarized_diffuse and the specular lobe against Mitsuba 3's `pplastic` (scalar_spectral_polarized) at the
Mueller level.

Mitsuba expresses Mueller matrices in its own Stokes frames; the comparison uses quantities no rotation of
the reference frames changes (rotations mix only S1 and S2): M11, the linear diattenuation sqrt(m12^2 + m13^2)
and polarizance sqrt(m21^2 + m31^2), |m14|, |m41|, m44, the Frobenius norm and |determinant| of the linear
block. Where the two describe the same physics they agree to Mitsuba's float32 rounding; where they differ
the difference is what docs/physics.md says it is."""

import numpy as np
import pytest

from spacepol.physics import Model, fresnel
from spacepol.physics.geometry import Geometry

N, SIGMA = 1.5, 0.2


def _geometry():
    rng = np.random.default_rng(0)
    ti = np.r_[rng.uniform(5, 70, 30), np.full(8, 45.0)]
    tr = np.r_[rng.uniform(5, 70, 30), np.linspace(5, 70, 8)]
    dphi = np.r_[rng.uniform(-180, 180, 30), np.full(8, 180.0)]
    return Geometry(ti, tr, dphi)


def _mitsuba(g, diffuse, specular):
    mi = pytest.importorskip("mitsuba")
    mi.set_variant("scalar_spectral_polarized")
    bsdf = mi.load_dict({"type": "pplastic", "distribution": "beckmann", "alpha": float(np.sqrt(2) * SIGMA),
                         "int_ior": N, "ext_ior": 1.0, "sample_visible": False, "specular_reflectance": specular,
                         "diffuse_reflectance": {"type": "uniform", "value": diffuse}})

    def direction(theta_deg, phi):
        t = np.radians(theta_deg)
        return mi.Vector3f(np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t))

    out = np.empty((4, 4, g.size))
    for j, (ti, tr, dphi) in enumerate(zip(g.theta_i, g.theta_r, g.dphi)):
        si = mi.SurfaceInteraction3f()
        si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
        si.wavelengths = [550.0, 600.0, 650.0, 700.0]
        si.wi = direction(tr, -np.radians(dphi))  # Mitsuba's wi is the detector; the source goes in wo
        out[:, :, j] = np.array(bsdf.eval(mi.BSDFContext(), si, direction(ti, 0.0)))[:, :, 0] / np.cos(np.radians(ti))
    return out


def _invariants(M):
    m = M / M[0, 0]
    lin = m[1:3, 1:3]
    return {"M11": M[0, 0], "diattenuation": np.hypot(m[0, 1], m[0, 2]), "polarizance": np.hypot(m[1, 0], m[2, 0]),
            "|m14|": np.abs(m[0, 3]), "|m41|": np.abs(m[3, 0]), "m44": m[3, 3],
            "linear block norm": np.sqrt((lin**2).sum(axis=(0, 1))), "|det linear block|": np.abs(lin[0, 0] * lin[1, 1] - lin[0, 1] * lin[1, 0])}


def _compare(ours, theirs):
    a, b = _invariants(ours), _invariants(theirs)
    return {k: (np.max(np.abs(a[k] / b[k] - 1)) if k == "M11" else np.max(np.abs(a[k] - b[k]))) for k in a}


def test_the_interface_is_mitsubas_up_to_its_smith_approximation():
    """pplastic without its diffuse base: a Beckmann rough dielectric with Fresnel's Mueller matrix and Smith
    shadowing = spacepol's specular+smith at k_s = 1. Polarization invariants to 1e-5; M11 to 0.5 % (Mitsuba
    takes Walter et al.'s rational approximation of Beckmann's Smith G1: -0.3 % at theta_r 70 deg)."""
    g = _geometry()
    ours = Model.from_string("specular+smith").evaluate({"n": N, "k": 0.0, "sigma": SIGMA, "ks": 1.0}, g, mueller=True).mueller
    diff = _compare(ours, _mitsuba(g, 0.0, 1.0))
    assert diff.pop("M11") < 5e-3
    assert max(diff.values()) < 1e-5, diff


def test_polarized_diffuse_is_pplastics_diffuse_base():
    """pplastic's diffuse base (specular_reflectance 0): T(theta_r) D T(theta_i) rho / pi, exactly
    polarized_diffuse (no internal reflections, no 1/n^2): every invariant to float32 rounding. subsurface
    (SCATMECH's model) differs by exactly 1 / (n^2 (1 - rho_i rho)) in M11, the same polarization."""
    g = _geometry()
    theirs = _mitsuba(g, 0.5, 0.0)
    base = {"n": N, "k": 0.0, "sigma": SIGMA, "ks": 0.0}
    ours = Model.from_string("specular+polarized_diffuse").evaluate({**base, "rho_pd": 0.5}, g, mueller=True).mueller
    diff = _compare(ours, theirs)
    assert max(diff.values()) < 1e-5, diff
    sub = Model.from_string("specular+subsurface").evaluate({**base, "rho_s": 0.5}, g, mueller=True).mueller
    ratio = sub[0, 0] / theirs[0, 0]
    expected = 1.0 / (N**2 * (1.0 - fresnel.hemispherical_internal_reflectance(N) * 0.5))
    np.testing.assert_allclose(ratio, expected, rtol=1e-5)
    # negative control: a Lambertian term has none of the transmission's polarization
    lam = Model.from_string("specular+lambertian").evaluate({**base, "rho_l": 0.5}, g, mueller=True).mueller
    assert _compare(lam, theirs)["polarizance"] > 1e-2
