"""Projections of the hemisphere: Tissot distortion from complex-step Jacobians of the
forward maps (independent of the module's own h, k formulas), inverses, the zenith cap's share."""

import numpy as np
import pytest

from spacepol.skylight.projections import PROJECTIONS, cap_fraction

ZEN = np.linspace(0.5, 89.5, 179)
AZ = np.linspace(0.0, 350.0, 36)


def _jacobian_scales(proj, zen_deg, az_deg, h=1e-30):
    """Scale factors along the meridian (d/dtheta) and the parallel (d/(sin theta dphi)) by complex step:
    exact to rounding for analytic maps."""
    t, p = np.radians(zen_deg), np.radians(az_deg)

    def xy(theta, phi):
        r = proj.radius(theta)
        return r * np.sin(phi), r * np.cos(phi)

    dx_t, dy_t = (np.imag(c) / h for c in xy(t + 1j * h, p + 0j))
    dx_p, dy_p = (np.imag(c) / h for c in xy(t + 0j, p + 1j * h))
    h_mer = np.hypot(dx_t, dy_t)
    k_par = np.hypot(dx_p, dy_p) / np.sin(t)
    orthogonal = (dx_t * dx_p + dy_t * dy_p) / (h_mer * np.hypot(dx_p, dy_p))
    return h_mer, k_par, orthogonal


def test_stereographic_is_conformal_to_1e_9():
    proj = PROJECTIONS["stereographic"]
    zen, az = np.meshgrid(ZEN, AZ)
    h, k, cos_angle = _jacobian_scales(proj, zen, az)
    omega = 2 * np.arcsin(np.abs(h - k) / (h + k))
    assert np.max(omega) < 1e-9 and np.max(np.abs(cos_angle)) < 1e-9
    assert np.max(np.abs(proj.tissot(zen)["angular_distortion_deg"])) < 1e-9
    # the module's own Tissot numbers agree with the complex-step ones
    assert np.allclose(proj.tissot(zen)["h"], h, rtol=1e-12) and np.allclose(proj.tissot(zen)["k"], k, rtol=1e-12)


def test_equal_area_has_areal_scale_one_and_orthographic_does_not():
    zen, az = np.meshgrid(ZEN, AZ)
    h, k, _ = _jacobian_scales(PROJECTIONS["equal-area"], zen, az)
    assert np.max(np.abs(h * k - 1)) < 1e-12
    h, k, _ = _jacobian_scales(PROJECTIONS["orthographic"], zen, az)
    assert np.max(np.abs(h * k - 1)) > 0.9  # negative control: crushed to ~0 at the horizon
    assert np.allclose(PROJECTIONS["orthographic"].tissot(zen)["areal_scale"], h * k, rtol=1e-9)


@pytest.mark.parametrize("name", list(PROJECTIONS))
def test_forward_inverse_round_trips(name):
    proj = PROJECTIONS[name]
    top = 80.0 if name == "orthographic" else 90.0  # see the next test for the orthographic horizon
    zen, az = np.meshgrid(np.linspace(0.001, top, 181), np.linspace(0.0, 359.0, 360))
    z2, a2 = proj.inverse(*proj.forward(zen, az))
    assert np.max(np.abs(z2 - zen)) < 1e-12 * 90
    assert np.max(np.abs(((a2 - az + 180) % 360) - 180)) < 1e-12 * 360
    x, y = proj.forward(zen, az)
    x2, y2 = proj.forward(*proj.inverse(x, y))
    assert np.max(np.hypot(x2 - x, y2 - y)) < 1e-12


def test_orthographic_round_trip_loses_precision_only_at_the_horizon():
    """r = sin(theta) is flat at 90 deg, so theta = arcsin(r) cannot be recovered there to 1e-12:
    the paper's 'cannot be reverse projected', quantified."""
    proj = PROJECTIONS["orthographic"]
    zen = np.linspace(0.0, 80.0, 801)
    z2, _ = proj.inverse(*proj.forward(zen, 30.0))
    assert np.max(np.abs(z2 - zen)) < 1e-12 * 90
    z2, _ = proj.inverse(*proj.forward(np.array([89.9999]), 30.0))
    assert abs(z2[0] - 89.9999) > 1e-11  # ~1e-9 deg: sqrt of rounding, 1000x worse than elsewhere


def test_zenith_cap_share_of_the_map():
    """ERRATA: the zenith cap (<= 30 deg) takes 7.2 % of the stereographic map, 13.4 % of the sky's solid
    angle (= the equal-area map) and 25 % of the orthographic one."""
    assert cap_fraction(PROJECTIONS["stereographic"], 30) == pytest.approx(0.0718, abs=5e-4)
    assert cap_fraction(PROJECTIONS["equal-area"], 30) == pytest.approx(1 - np.cos(np.radians(30)), abs=1e-12)
    assert cap_fraction(PROJECTIONS["orthographic"], 30) == pytest.approx(0.25, abs=1e-12)
