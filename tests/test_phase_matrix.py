"""`phase_matrix` (first-order volume scattering with a free-form, realizable phase matrix under an interface of its
own index) against NIST SCATMECH's First_Diffuse_BRDF_Model with Constrained_Phase_Function and leg depolarization,
an independent implementation (Germer), over 240 draws from the effect's prior at geometries covering NIST's PTFE
set, in and out of the plane; realizability of every prior draw (hypothesis), reciprocity; and the negative
controls that show each comparison can fail."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from coherency import coherency_eigenvalues

from spacepol.criticism.reciprocity import reciprocal_image, swapped
from spacepol.errors import ParameterError
from spacepol.physics import Geometry, Model, constrained_phase
from spacepol.physics.effects.phase_matrix import SHAPE_NAMES, PhaseMatrix, circular_depolarization

pytest.importorskip("pySCATMECH")

WAVELENGTH = 0.633
MODEL = Model.from_string("specular+phase_matrix")


def _draw(rng):
    """A parameter set of ``specular+phase_matrix`` from the effect's prior (the facet lobe switched off)."""
    values = {p.name: rng.uniform(*p.prior.bounds) for p in MODEL.parameters}
    values.update(ks=0.0, w_pm=rng.uniform(0.05, 0.999))
    return values


def _scatmech(values, perturb=None):
    """SCATMECH's model of the same parameters; ``perturb`` = (name, delta) moves one of its phase-function values."""
    from pySCATMECH.brdf import BRDF_Model

    shape = {f"phase_function.{k}": float(v) for k, v in PhaseMatrix.nodes(values).scatmech().items()}
    if perturb:
        shape[f"phase_function.{perturb[0]}"] += perturb[1]
    albedo = values["w_pm"]
    return BRDF_Model("First_Diffuse_BRDF_Model", {
        "lambda": WAVELENGTH, "substrate": f"({values['n_pm']},0)", "type": 0,
        "phase_function": "Constrained_Phase_Function",
        "phase_function.phase_function": "Henyey_Greenstein_Phase_Function",
        "phase_function.phase_function.g": values["g_pm"],
        # albedo = scattering / (scattering + absorption) with the scattering coefficient 1 / um
        "phase_function.log_scattering": 0, "phase_function.log_absorption": float(np.log((1 - albedo) / albedo)),
        "depoll": values["dl_pm"], "depolc": float(circular_depolarization(values["dl_pm"], values["fc_pm"])), **shape})


def _geometries(rng, size):
    """(theta_i, theta_r, phi_s) in degrees, SCATMECH's phi_s = 0 the specular direction: PTFE's incidence 0-75 deg,
    exit 0-85 deg, a third in the plane (forward and back), the rest at any azimuth."""
    ti, tr = rng.uniform(0.0, 75.0, size), rng.uniform(0.0, 85.0, size)
    ps = rng.uniform(-180.0, 180.0, size)
    ps[: size // 3] = rng.choice([0.0, 180.0], size // 3)
    return ti, tr, ps


def _theirs(peer, ti, tr, ps):
    return np.stack([np.array(peer.MuellerBRDF(*np.radians([a, b, c]))) for a, b, c in zip(ti, tr, ps)], axis=-1)


def _worst(ours, theirs):
    """The largest difference of any element over M11, and M11's largest relative difference."""
    return np.max(np.abs(ours - theirs) / theirs[0, 0]), np.max(np.abs(ours[0, 0] / theirs[0, 0] - 1))


def test_phase_matrix_matches_scatmech_over_prior_draws():
    """240 prior draws, 4 geometries each: every element within 1e-6 of M11, M11 within 1e-6 relative. Negative
    control: SCATMECH with one phase-matrix value moved by 0.01 (m23_60, the m34 node at 60 deg) differs by 100 times
    the tolerance."""
    rng = np.random.default_rng(47)
    worst = worst_m11 = 0.0
    for _ in range(240):
        values = _draw(rng)
        ti, tr, ps = _geometries(rng, 4)
        ours = MODEL.evaluate(values, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
        theirs = _theirs(_scatmech(values), ti, tr, ps)
        assert np.all(theirs[0, 0] > 0)
        element, m11 = _worst(ours, theirs)
        worst, worst_m11 = max(worst, element), max(worst_m11, m11)
    assert worst <= 1e-6 and worst_m11 <= 1e-6, f"largest difference {worst:.2e} of M11, M11 {worst_m11:.2e}"
    values = _draw(np.random.default_rng(3))
    ti, tr, ps = _geometries(np.random.default_rng(4), 30)
    ours = MODEL.evaluate(values, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    moved = _worst(ours, _theirs(_scatmech(values, perturb=("m23_60", 0.01)), ti, tr, ps))[0]
    assert moved > 1e-4, f"a moved phase-matrix value changed the matrices by only {moved:.2e} of M11"


def test_leg_depolarization_and_own_index_match_scatmech():
    """The two parts SCATMECH adds around the phase function: the depolarization along the legs and the interface's
    own index (the facets' n set far from it must not matter). Negative control: SCATMECH with depolc moved."""
    rng = np.random.default_rng(8)
    values = {**_draw(rng), "dl_pm": 0.7, "fc_pm": 0.9, "n_pm": 1.22, "n": 2.5, "k": 1.0}
    ti, tr, ps = _geometries(rng, 60)
    ours = MODEL.evaluate(values, Geometry(ti, tr, 180.0 - ps), mueller=True).mueller
    theirs = _theirs(_scatmech(values), ti, tr, ps)
    assert max(_worst(ours, theirs)) <= 1e-6
    off = _scatmech({**values, "fc_pm": 0.3})
    assert _worst(ours, _theirs(off, ti, tr, ps))[0] > 1e-3


def test_the_coherency_eigenvalues_are_the_ones_the_parameterisation_bounds():
    """The closed form the parameterisation relies on (``constrained_phase``'s docstring) against numerical
    eigenvalues of the coherency matrix, on random matrices of the isotropic form."""
    rng = np.random.default_rng(1)
    a2, a3, a4, b1, b2 = rng.uniform(-1, 1, (5, 500))
    mueller = np.zeros((500, 4, 4))
    mueller[:, 0, 0] = 1
    mueller[:, 0, 1] = mueller[:, 1, 0] = b1
    mueller[:, 1, 1], mueller[:, 2, 2], mueller[:, 3, 3] = a2, a3, a4
    mueller[:, 2, 3], mueller[:, 3, 2] = b2, -b2
    ball = np.sqrt((a3 + a4) ** 2 + 4 * b1**2 + 4 * b2**2)
    closed = np.sort(np.stack([1 - a2 - a3 + a4, 1 - a2 + a3 - a4, 1 + a2 - ball, 1 + a2 + ball], -1) / 4, axis=-1)
    np.testing.assert_allclose(coherency_eigenvalues(mueller), closed, atol=1e-12)


def _reduced(nodes, theta):
    a2, a3, a4, b1, b2 = (np.asarray(v, float) for v in nodes.at(theta))
    out = np.zeros(theta.shape + (4, 4))
    out[..., 0, 0] = 1
    out[..., 0, 1] = out[..., 1, 0] = b1
    out[..., 1, 1], out[..., 2, 2], out[..., 3, 3] = a2, a3, a4
    out[..., 2, 3], out[..., 3, 2] = b2, -b2
    return out


THETA = np.linspace(0.0, np.pi, 721)
coordinates = st.lists(st.floats(-1.0, 1.0, allow_nan=False), min_size=14, max_size=14)


@settings(max_examples=120, deadline=None)
@given(u=coordinates)
def test_every_prior_draw_is_realizable_at_every_scattering_angle(u):
    """Any point of the 14 shape coordinates' box (its faces and corners included) gives a reduced phase matrix whose
    coherency eigenvalues are >= 0 at 721 angles from 0 to 180 deg, with the symmetries of an isotropic medium at
    0 and 180 deg."""
    nodes = constrained_phase.realizable_nodes(u)
    matrices = _reduced(nodes, THETA)
    smallest = coherency_eigenvalues(matrices).min()
    assert smallest >= -1e-12, f"coherency eigenvalue {smallest:.3e} < 0"
    assert float(constrained_phase.spline_gauge(nodes)) <= 1 + 1e-12
    for end, sign in ((0, 1.0), (-1, -1.0)):  # M12 = M34 = 0 and M33 = +-M22 forward and back
        m = matrices[end]
        assert abs(m[0, 1]) < 1e-12 and abs(m[2, 3]) < 1e-12 and abs(m[2, 2] - sign * m[1, 1]) < 1e-12


def test_without_the_pull_the_spline_leaves_the_realizable_set():
    """Negative control of the test above: the nodes alone inside the realizable set (no pull) give splines that are
    unphysical between the nodes for a good share of prior draws, and the check sees it."""
    rng = np.random.default_rng(2)
    bad = sum(coherency_eigenvalues(_reduced(constrained_phase.node_values(list(rng.uniform(-1, 1, 14))), THETA)).min()
              < -1e-6 for _ in range(200))
    assert bad > 50, f"only {bad} of 200 unpulled draws unrealizable"


@settings(max_examples=60, deadline=None)
@given(data=st.data())
def test_the_effect_is_realizable_and_reciprocal_over_its_prior(data):
    """The whole lobe (transmission, phase matrix, leg depolarization) at random geometries and prior draws: coherency
    eigenvalues >= -1e-12 M11 and M(r -> i, -dphi) = Q M(i -> r, dphi)^T Q to 1e-9 of M11."""
    values = {p.name: data.draw(st.floats(*p.prior.bounds, allow_nan=False)) for p in MODEL.parameters}
    values["ks"] = 0.0
    seed = data.draw(st.integers(0, 2**31))
    ti, tr, ps = _geometries(np.random.default_rng(seed), 12)
    geometry = Geometry(ti, tr, 180.0 - ps)
    forward = MODEL.evaluate(values, geometry, mueller=True).mueller
    scale = np.max(forward[0, 0]) + 1e-300
    assert coherency_eigenvalues(np.moveaxis(forward, -1, 0)).min() >= -1e-12 * scale
    backward = MODEL.evaluate(values, swapped(geometry), mueller=True).mueller
    np.testing.assert_allclose(backward, reciprocal_image(forward), rtol=0, atol=1e-9 * scale)


def test_circular_depolarization_beyond_its_bound_would_be_unphysical():
    """Why depolc is a share of min(1, 2 depoll): a leg that keeps linear polarization and loses circular
    (diag(1, 1, 1, 0.5)) has a negative coherency eigenvalue; at the bound it is 0."""
    assert coherency_eigenvalues(np.diag([1.0, 1.0, 1.0, 0.5])).min() < -0.1
    assert abs(coherency_eigenvalues(np.diag([1.0, 0.8, 0.8, 1.0 - 2 * 0.2])).min()) < 1e-12


def test_a_shape_coordinate_outside_its_range_is_one_line_naming_it():
    values = {**_draw(np.random.default_rng(0)), "pm_m12_60": 1.4}
    with pytest.raises(ParameterError, match=r"pm_m12_60 = 1\.4 is impossible \(allowed \[-1, 1\]\)"):
        MODEL.evaluate(values, Geometry(np.array([30.0]), np.array([40.0]), np.array([180.0])), mueller=True)


def test_shape_names_are_the_effects_parameters():
    names = [p.name for p in PhaseMatrix.parameters]
    assert set(SHAPE_NAMES) <= set(names) and len(SHAPE_NAMES) == 14


def test_diagnose_weighs_it_as_an_addition_and_in_place_of_volume_or_subsurface():
    """The candidate library holds it three ways on PTFE-like models; negative control: a model without either term
    offers only the addition."""
    from spacepol.criticism.changes import changes
    from spacepol.io import read_measurements
    from spacepol.paths import bundled

    data = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    labels = {c.label for c in changes(Model.from_string("specular+smith+subsurface+volume"), data)}
    assert {"add phase_matrix", "replace volume by phase_matrix", "replace subsurface by phase_matrix"} <= labels
    plain = {c.label for c in changes(Model.from_string("paper"), data) if "phase_matrix" in c.label}
    assert plain == {"add phase_matrix"}
