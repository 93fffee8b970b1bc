"""`polarization_memory` (Lambertian light keeping part of its polarization in the beams' own s/p frames): the matrix
built from its Cloude decomposition (four Jones matrices turned into Mueller matrices independently of the effect),
realizability over the whole prior (hypothesis, with a control that the check can fail), reciprocity beside the
other body terms, and who may use it (measured Mueller elements only)."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from coherency import PAULI, coherency_eigenvalues, jones_to_mueller

from spacepol.criticism.changes import changes
from spacepol.criticism.reciprocity import reciprocal_image, swapped
from spacepol.io import Dataset, read_measurements
from spacepol.paths import bundled
from spacepol.physics import Geometry, Model
from spacepol.physics.effects.polarization_memory import PolarizationMemory

MEMORY = Model.from_string("specular+polarization_memory")


def _geometry(rng, size=64):
    return Geometry(rng.uniform(0, 85, size), rng.uniform(0, 85, size), rng.uniform(-180, 180, size), np.full(size, 0.633))


def _lobe(rho, f, c, geometry):
    """The effect's Mueller matrix (4, 4, N), the facets switched off."""
    return np.asarray(MEMORY.evaluate({"ks": 0.0, "rho_mem": rho, "f_mem": f, "c_mem": c}, geometry, mueller=True,
                                      check=False).mueller)


@pytest.mark.parametrize("f, c", [(0.0, 0.0), (0.6, 0.2), (-0.9, -0.5), (1.0, -1.0), (-1.0, 1.0)])
def test_the_matrix_is_the_mixture_of_four_jones_matrices(f, c):
    """(rho / pi) sum_k lambda_k M(J_k) with J_k the Pauli matrices (identity, a half-wave plate at 0 deg, at 45 deg, a
    circular retarder) and lambda_k the documented coherency eigenvalues: the effect's matrix at every geometry, in and
    out of the plane (the s/p frames do not turn)."""
    rho = 0.37
    weights = [(1 + c) / 4, (1 - c) * (1 + f) / 4, (1 - c) * (1 - f) / 4, (1 + c) / 4]  # I, sigma_3, sigma_1, sigma_2
    expected = rho / np.pi * sum(w * jones_to_mueller(j) for w, j in zip(weights, PAULI))
    got = _lobe(rho, f, c, _geometry(np.random.default_rng(1)))
    np.testing.assert_allclose(np.moveaxis(got, -1, 0), np.broadcast_to(expected, (got.shape[-1], 4, 4)), atol=1e-15)
    assert min(weights) >= 0


@settings(max_examples=200, deadline=None)
@given(f=st.floats(-1.0, 1.0), c=st.floats(-1.0, 1.0), rho=st.floats(0.0, 1.0))
def test_every_prior_draw_is_realizable(f, c, rho):
    lobe = _lobe(rho, f, c, _geometry(np.random.default_rng(2), 4))
    assert coherency_eigenvalues(np.moveaxis(lobe, -1, 0)).min() >= -1e-15


def test_the_realizability_check_can_fail():
    """Negative control: linear memory beyond the bound (1 - c)/2 has a negative coherency eigenvalue."""
    assert coherency_eigenvalues(np.diag([1.0, 0.6, -0.6, 0.0])).min() < -0.04


def test_it_is_reciprocal_beside_the_other_body_terms():
    model = Model.from_string("specular+smith+subsurface+polarization_memory")
    params = {"n": 1.35, "k": 0.0, "sigma": 0.3, "ks": 0.2, "rho_s": 0.6, "rho_mem": 0.4, "f_mem": 0.7, "c_mem": 0.3}
    geometry = _geometry(np.random.default_rng(3), 200)
    forward = model.evaluate(params, geometry, mueller=True).mueller
    backward = model.evaluate(params, swapped(geometry), mueller=True).mueller
    np.testing.assert_allclose(reciprocal_image(forward), backward, rtol=1e-9, atol=1e-12)
    # control: the same comparison sees an element that breaks the symmetry (M12 != M21 is not reciprocal)
    broken = np.array(forward)
    broken[0, 1] += 0.01 * broken[0, 0]
    assert not np.allclose(reciprocal_image(broken), backward, rtol=1e-9, atol=1e-12)


def test_unpolarized_light_sees_a_lambertian_lobe():
    """Its first column is (rho / pi, 0, 0, 0): DOP and BRDF data cannot tell it from `lambertian`."""
    geometry = _geometry(np.random.default_rng(4))
    mine = MEMORY.evaluate({"ks": 0.0, "rho_mem": 0.3, "f_mem": 0.8, "c_mem": -0.4}, geometry, check=False)
    np.testing.assert_allclose(mine.brdf, 0.3 / np.pi, rtol=1e-14)
    assert np.all(mine.dop < 1e-12)


def test_only_mueller_data_can_use_it():
    ptfe = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    assert PolarizationMemory().applicable(ptfe) is None
    labels = {c.label for c in changes(Model.from_string("specular+smith+subsurface+phase_matrix"), ptfe)}
    assert "add polarization_memory" in labels
    dop = Dataset(ptfe.theta_i, ptfe.theta_r, ptfe.dphi, wavelength_um=ptfe.wavelength_um)
    dop.dop, dop.dop_err = np.full(len(ptfe), 0.1), np.full(len(ptfe), 0.01)
    assert "Mueller" in PolarizationMemory().applicable(dop)
    assert not any("polarization_memory" in c.label for c in changes(Model.from_string("paper"), dop))


def _render(rho_mem, seed):
    """A PTFE-like full-Mueller set from spacepol's own model with ``rho_mem`` of polarization-keeping light (the
    facets of index 1.35 and a subsurface body otherwise), noise 0.012 per element, 2 % on the BRDF."""
    from scatmech_sets import measured, ptfe_like_geometry

    g = ptfe_like_geometry(70)
    g = Geometry(g.theta_i, g.theta_r, g.dphi, np.full(g.size, 0.633))
    truth = {"n": 1.35, "k": 0.0, "sigma": 0.3, "ks": 0.15, "rho_s": 0.8, "rho_mem": rho_mem, "f_mem": 0.5, "c_mem": 0.2}
    mueller = np.asarray(Model.from_string("specular+smith+subsurface+polarization_memory").evaluate(truth, g, mueller=True).mueller)
    return measured(g, mueller, 0.012, 0.02, np.random.default_rng(seed), "polarization memory render")


@pytest.mark.parametrize("rho_mem", [0.15, 0.0])
def test_diagnose_adds_it_where_the_data_hold_it_and_only_there(rho_mem):
    """A hidden polarization-keeping share (0.15 of a 0.8 body, keeping 0.4 of linear polarization) is named by a
    decisive ELPD-LOO gain; with none hidden (control) it is not."""
    from spacepol.criticism.diagnose import diagnose

    report = diagnose(_render(rho_mem, seed=3), Model.from_string("specular+smith+subsurface"), np.random.default_rng(0),
                      seed=0, candidates=["polarization_memory", "lambertian", "depolarization"], top=1, progress=False)
    lead = report["ranking"][0]
    if rho_mem:
        assert report["verdict"] == "polarization_memory", report["verdict"]
        # measured: +1,596 +- 102 (15.7 SE)
        assert lead["delta_elpd"] > 5 * lead["delta_elpd_se"], f"{lead['delta_elpd']:.0f} +- {lead['delta_elpd_se']:.0f}"
    else:
        assert report["verdict"] != "polarization_memory", (report["verdict"], lead)  # measured: "none"
