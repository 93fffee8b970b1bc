"""Reciprocity: the relation M(r -> i, -dphi) = Q M(i -> r, dphi)^T Q, Q = diag(1, 1, -1, 1),
in spacepol's frames is checked on NIST SCATMECH's reciprocal facet model (an independent implementation),
then used to measure models and measured pairs."""

import numpy as np
import pytest

from spacepol.criticism import reciprocity
from spacepol.io.measurements import Dataset
from spacepol.physics import Model
from spacepol.physics.geometry import Geometry


def _random_geometry(n=40, seed=0):
    rng = np.random.default_rng(seed)
    return Geometry(rng.uniform(5, 70, n), rng.uniform(5, 70, n), rng.uniform(-180, 180, n))


def test_scatmech_facet_model_obeys_the_relation_in_spacepols_frames():
    """SCATMECH's Facet_BRDF_Model (absorbing substrate, so the circular elements are non-zero) at swapped
    geometries (dphi -> -dphi): Q M^T Q with Q = diag(1, 1, -1, 1) to rounding; the other sign convention,
    diag(1, 1, 1, -1), fails."""
    from pySCATMECH.brdf import BRDF_Model

    model = BRDF_Model("Facet_BRDF_Model", {"lambda": 0.633, "substrate": "(1.2,6.0)", "type": 0,
                                            "sdf": "Gaussian_Slope_Distribution_Function", "sdf.s": 0.3})
    g = _random_geometry(12)

    def at(ti, tr, dphi):
        return np.array(model.MuellerBRDF(*np.radians([ti, tr, 180.0 - dphi])))

    worst, wrong = 0.0, 0.0
    for ti, tr, dphi in zip(g.theta_i, g.theta_r, g.dphi):
        forward, backward = at(ti, tr, dphi), at(tr, ti, -dphi)
        worst = max(worst, np.max(np.abs(reciprocity.reciprocal_image(forward) - backward)) / forward[0, 0])
        other = np.diag([1.0, 1, 1, -1])
        wrong = max(wrong, np.max(np.abs(other @ forward.T @ other - backward)) / forward[0, 0])
    assert worst < 1e-9 and wrong > 0.05


@pytest.mark.parametrize("spec", ["specular", "specular+smith", "specular+smith+lambertian", "specular+subsurface",
                                  "specular+smith+polarized_diffuse"])
def test_physical_models_are_reciprocal(spec):
    v = reciprocity.model_violation(Model.from_string(spec), {"k": 2.0, "rho_pd": 0.3}
                                    if "polarized" in spec else {"k": 2.0}, _random_geometry())
    assert v["brdf_relative_p95"] < 1e-12 and v["element_p95"] < 1e-12, v


def test_the_papers_model_is_not_reciprocal():
    """Negative control: the paper's cos(theta_r) body term and its shadowing function change the BRDF when
    source and detector swap."""
    v = reciprocity.model_violation(Model.from_string("paper"), {"k": 2.0}, _random_geometry())
    assert v["brdf_relative_p95"] > 0.1


def test_measured_pairs_are_found_and_compared():
    """Rows whose swapped geometry was measured (and theta_i = theta_r rows, which pair with themselves);
    a reciprocal set shows no violation, one with a transposed element sign broken does."""
    ti = np.array([30.0, 45.0, 30.0, 20.0])
    tr = np.array([45.0, 30.0, 30.0, 60.0])
    dphi = np.array([150.0, -150.0, 180.0, 180.0])
    g = Geometry(ti, tr, dphi)
    model = Model.from_string("specular+smith")
    data = Dataset(ti, tr, dphi)
    data.mueller = model.evaluate({"k": 2.0}, g, mueller=True).mueller
    pairs = reciprocity.data_pairs(data)
    assert sorted(map(tuple, pairs)) == [(0, 1), (2, 2)]
    clean = reciprocity.data_violation(data)
    assert clean["n_pairs"] == 2 and clean["n_self_pairs"] == 1 and clean["element_p95"] < 1e-12
    broken = Dataset(ti, tr, dphi)
    broken.mueller = data.mueller.copy()
    broken.mueller[3, 1, 1] *= -1  # m42 of the swapped row with the wrong sign
    assert reciprocity.data_violation(broken)["element_p95"] > 1e-3


def _symmetric_set(sigma, seed=0):
    """A reciprocal, isotropic model (absorbing facets + volume: every element non-zero out of the plane) at mirror
    pairs and at theta_i = theta_r rows, with Gaussian noise ``sigma`` on each normalised element."""
    rng = np.random.default_rng(seed)
    ti = np.concatenate([rng.uniform(10, 60, 150), np.full(150, 40.0)])
    tr = np.concatenate([rng.uniform(10, 60, 150), np.full(150, 40.0)])
    # distinct azimuths (two random ones within the pairing's 0.01 deg would pair with each other's mirror)
    dphi = np.concatenate([rng.choice(np.arange(20.0, 160.0, 0.25), 150, replace=False),
                           rng.choice(np.arange(20.0, 160.0, 0.25), 150, replace=False)])
    ti, tr, dphi = np.concatenate([ti, ti]), np.concatenate([tr, tr]), np.concatenate([dphi, -dphi])
    model = Model.from_string("specular+smith+volume")
    m = model.evaluate({"n": 1.4, "k": 0.3, "ks": 0.5, "sigma": 0.4, "w_vol": 0.8, "pc_vol": 0.5}, Geometry(ti, tr, dphi),
                       mueller=True).mueller
    m = m / m[0, 0]
    m[1:] += sigma * rng.standard_normal(m[1:].shape)
    m[0, 1:] += sigma * rng.standard_normal(m[0, 1:].shape)
    return Dataset(ti, tr, dphi, mueller=m, brdf=np.ones_like(ti))


def test_symmetry_checks_measure_noise_and_catch_a_broken_relation():
    """A reciprocal, isotropic set with noise 0.01: mirror pairs give the noise back (the mean over elements of
    noise_from_mirror within 10 %: 600 pairs x 15 elements, Monte-Carlo error ~1.5 %), and at theta_i = theta_r the
    part that breaks reciprocity + mirror symmetry is noise / sqrt(2). Control: the same set with m13's sign flipped
    (an input basis whose S2 axis points the other way for one element) breaks m13/m31 far beyond it."""
    exact = reciprocity.symmetry_checks(_symmetric_set(0.0))  # the library's reciprocal effects keep both to rounding
    assert max(e["rms_mirrored"] for e in exact["mirror"]["elements"].values()) < 1e-12
    assert max(p["rms_breaking"] for p in exact["equal_angles"]["pairs"].values()) < 1e-12
    assert min(p["rms_opposite_sign"] for k, p in exact["equal_angles"]["pairs"].items() if k != "m14/m41") > 1e-3
    sigma = 0.01
    data = _symmetric_set(sigma)
    checks = reciprocity.symmetry_checks(data)
    assert checks["mirror"]["n_pairs"] == 300
    noise = np.mean([e["noise_from_mirror"] for e in checks["mirror"]["elements"].values()])
    assert abs(noise / sigma - 1) < 0.1
    equal = checks["equal_angles"]
    assert equal["n_rows"] == 300
    for pair in equal["pairs"].values():
        assert abs(pair["rms_breaking"] / (sigma / np.sqrt(2)) - 1) < 0.2
    broken = _symmetric_set(sigma)
    broken.mueller[0, 2] *= -1
    pair = reciprocity.symmetry_checks(broken)["equal_angles"]["pairs"]["m13/m31"]
    assert pair["rms_breaking"] > 3 * sigma and pair["rms_opposite_sign"] < sigma
    # in words: the broken relation is named, and a clean set has no such finding
    words = reciprocity.symmetry_findings(reciprocity.symmetry_checks(broken), {"pol": 0.01})
    assert any("The data break m13/m31" in w for w in words) and "(reciprocal pairs: 0.0100)" in words[0]
    assert not any("The data break" in w for w in reciprocity.symmetry_findings(checks))


def test_mirror_asymmetry_is_noise_on_an_isotropic_set_and_flags_the_pairs_made_anisotropic():
    """An isotropic set with noise 0.01 in every element: the mirror pairs' chi^2 per degree of freedom is 1 within
    its Monte-Carlo error (300 pairs x 15: SD ~0.02) and no pair passes the Bonferroni limit (p < 0.001 over all
    pairs). Control: 10 pairs whose -dphi member gets m13 and m31 shifted by 0.05 (5 sigma: what a slight in-plane
    anisotropy does to the elements odd in dphi) are flagged, and only they (chi^2 ~ 15 + 2 x 50 against the
    limit's ~50)."""
    sigma = 0.01
    noise = {"pol": sigma, "lin": sigma, "circ": sigma}
    data = _symmetric_set(sigma)
    clean = reciprocity.mirror_asymmetry(data, noise)
    assert len(clean.pairs) == 300 and abs(clean.excess - 1) < 0.1, clean.excess
    assert clean.flagged.sum() == 0 and "0 pairs (0 rows)" in clean.text
    shifted = clean.pairs[:10, 1]
    m11 = data.mueller[0, 0, shifted]
    data.mueller[0, 2, shifted] += 0.1 * m11
    data.mueller[2, 0, shifted] += 0.1 * m11
    anisotropic = reciprocity.mirror_asymmetry(data, noise)
    assert set(np.flatnonzero(anisotropic.flagged)) == set(range(10)), np.flatnonzero(anisotropic.flagged)
    assert len(anisotropic.rows) == 20 and anisotropic.excess > clean.excess
    with pytest.raises(ValueError, match="no noise for the circ group"):
        reciprocity.mirror_asymmetry(data, {"pol": sigma, "lin": sigma})


def test_mirror_scatter_follows_a_noise_that_grows_with_the_exit_angle():
    """An isotropic set whose noise is 0.005 below 40 deg of exit and 0.015 above: the mirror pairs' scatter per exit
    bin gives each bin's noise back within 20 % (each bin holds >= 300 differences: the MAD's relative SE ~ 1.17 /
    sqrt(n) <= 6.8 %, so 20 % is 3 SE). Control: the same noise everywhere gives equal bins, and pairs made anisotropic raise the
    scatter of their bin only."""
    rng = np.random.default_rng(3)
    data = _symmetric_set(0.0)
    m, tr = data.mueller, np.abs(data.theta_r)
    sigma = np.where(tr < 40, 0.005, 0.015)
    noisy = m.copy()
    noisy[1:] += sigma * rng.standard_normal(m[1:].shape)
    noisy[0, 1:] += sigma * rng.standard_normal(m[0, 1:].shape)
    scatter = reciprocity.mirror_scatter(Dataset(data.theta_i, data.theta_r, data.dphi, mueller=noisy,
                                                 brdf=np.ones_like(tr)), edges_deg=(0, 40, 90))
    for group in ("pol", "lin", "circ"):
        assert np.all(scatter.count[group] >= 300), scatter.count[group]
        np.testing.assert_allclose(scatter.sd[group], [0.005, 0.015], rtol=0.2, err_msg=group)
    flat = reciprocity.mirror_scatter(_symmetric_set(0.01), edges_deg=(0, 40, 90))
    for group in ("pol", "lin", "circ"):
        np.testing.assert_allclose(flat.sd[group], [0.01, 0.01], rtol=0.2, err_msg=group)
    shifted = _symmetric_set(0.01)
    pairs = reciprocity.mirror_pairs(shifted)
    high = pairs[np.abs(shifted.theta_r[pairs[:, 1]]) >= 40, 1]
    from spacepol.observables.mueller import GROUPS, index

    for element in GROUPS["lin"]:  # what an anisotropy odd in dphi does to a pair: each lin element shifted by 5 sigma
        shifted.mueller[index(element) + (high,)] += 0.05 * np.sign(rng.standard_normal(high.size))
    raised = reciprocity.mirror_scatter(shifted, edges_deg=(0, 40, 90))
    assert raised.sd["lin"][1] > 1.5 * flat.sd["lin"][1] and abs(raised.sd["lin"][0] / flat.sd["lin"][0] - 1) < 0.05
    assert scatter.labels() == ["0-40 deg", "40-90 deg"]
    with pytest.raises(ValueError, match="needs the Mueller matrix"):
        reciprocity.mirror_scatter(Dataset(data.theta_i, data.theta_r, data.dphi, dop=np.zeros_like(tr)))
