"""Mirror folding: every effect's ``mirror_symmetric`` flag tells the truth, and a folded evaluation and likelihood
equal the unfolded ones on every row (``physics.mirror``)."""

import numpy as np
import pytest

from spacepol.physics import Geometry, Model
from spacepol.physics.compiled import Program
from spacepol.physics.effect import Effect
from spacepol.physics.effects import registry
from spacepol.physics.mirror import MIRROR_SIGNS, MirrorFold
from spacepol.physics.spectral import SpectralModel

D = np.diag(MIRROR_SIGNS)


def _random_params(model, rng):
    return {p.name: float(rng.uniform(*p.prior.bounds)) for p in model.parameters}


def _mirror_error(spec, rng, draws=3):
    """The largest |M(-dphi) - D M(dphi) D| over random parameter draws and geometries (either sign of theta), over
    the largest |M00|."""
    model = Model.from_string(spec)
    worst = 0.0
    for _ in range(draws):
        ti, tr, dphi = rng.uniform(-80, 80, 24), rng.uniform(-80, 80, 24), rng.uniform(0, 360, 24)
        params = _random_params(model, rng)
        m = model.evaluate(params, Geometry(ti, tr, dphi, np.full(24, 0.6)), mueller=True).mueller
        mirrored = model.evaluate(params, Geometry(ti, tr, -dphi, np.full(24, 0.6)), mueller=True).mueller
        imaged = np.einsum("ab,bcj,cd->adj", D, m, D)
        worst = max(worst, float(np.max(np.abs(mirrored - imaged)) / np.max(np.abs(m[0, 0]))))
    return worst


def test_mirror_flags_match_behaviour(rng):
    """Each built-in declared mirror-symmetric keeps M(-dphi) = D M(dphi) D to rounding; each declared otherwise
    breaks it at random parameters (the negative control: an anisotropic surface turned off the plane)."""
    undeclared = []
    for name in registry.names():
        spec = "specular" if name == "specular" else f"specular+{name}"
        error = _mirror_error(spec, rng)
        if registry.get(name).mirror_symmetric:
            assert error < 1e-12, (name, error)
        else:
            undeclared.append(name)
            assert error > 1e-4, (name, error)
    assert undeclared == ["anisotropy"]


def _paired_geometry(rng, n=40):
    """Out-of-plane geometries at dphi and -dphi (wrapped to (180, 360)), in-plane ones, and unpaired ones, shuffled."""
    ti, tr, dphi = rng.uniform(0, 80, n), rng.uniform(0, 80, n), rng.uniform(5, 175, n)
    ti = np.concatenate([ti, ti, [30.0, 45.0], rng.uniform(0, 80, 6)])
    tr = np.concatenate([tr, tr, [30.0, 60.0], rng.uniform(0, 80, 6)])
    dphi = np.concatenate([dphi, 360.0 - dphi, [180.0, 0.0], rng.uniform(0, 360, 6)])
    order = rng.permutation(ti.size)
    return ti[order], tr[order], dphi[order]


@pytest.mark.parametrize("mueller", [True, False])
def test_folded_program_equals_the_unfolded_one(rng, mueller):
    """A four-wavelength model on mirror pairs: the fold evaluates each pair once (94 rows -> 48 geometries per
    wavelength) and gives every row's Mueller matrix (or Stokes vector) and DOP as the full evaluation does."""
    ti, tr, dphi = _paired_geometry(rng)
    wavelengths = np.repeat([0.35, 0.53, 0.63, 1.06], ti.size)
    geometry = Geometry(np.tile(ti, 4), np.tile(tr, 4), np.tile(dphi, 4), wavelengths)
    model = SpectralModel(Model.from_string("specular+smith+subsurface+phase_matrix"), [0.35, 0.53, 0.63, 1.06])
    params = _random_params(model, rng)
    values = {name: np.full((3, 1), v) * np.array([[1.0], [0.97], [1.02]]) if name.startswith("n") else v
              for name, v in params.items()}
    folded, full = Program(model, geometry, mueller, fold=True), Program(model, geometry, mueller)
    assert [f.geometry.size for f in folded.folds] == [48] * 4 and full.folds == [None] * 4
    (a_total, a_dop), (b_total, b_dop) = folded(values, folded.inputs), full(values, full.inputs)
    scale = np.max(np.abs(np.asarray(b_total)))
    assert np.max(np.abs(np.asarray(a_total) - np.asarray(b_total))) < 1e-10 * scale  # rounding: a row and its mirror image differ in the last bits of their angles
    assert np.max(np.abs(np.asarray(a_dop) - np.asarray(b_dop))) < 1e-10


def test_no_fold_without_pairs_or_with_an_asymmetric_effect(rng):
    """In-plane rows have no mirror partners: nothing to fold. An anisotropic surface, or a plug-in that does not
    declare itself mirror-symmetric, is evaluated at every row."""
    in_plane = Geometry(np.repeat([20.0, 50.0], 10), np.tile(np.linspace(0, 80, 10), 2), np.full(20, 180.0))
    assert MirrorFold.of(in_plane) is None
    ti, tr, dphi = _paired_geometry(rng)
    paired = Geometry(ti, tr, dphi)
    assert MirrorFold.of(paired).geometry.size == 48
    assert Program(Model.from_string("specular+smith+anisotropy"), paired, True, fold=True).folds == [None]

    class Sheen(Effect):
        """A plug-in lobe that says nothing of its symmetry."""
        name = "sheen_undeclared"

        def lobe(self, ctx):
            return ctx.depolarized(0.1 * ctx.geometry.cos_tr)

    model = Model([registry.get("specular")(), Sheen()])
    assert Program(model, paired, True, fold=True).folds == [None]


def test_the_folded_likelihood_is_the_unfolded_one(rng, monkeypatch):
    """Noisy Mueller data (inferred noise levels, a noise profile) at mirror pairs, repeated rows and unpaired rows over
    two wavelengths: the likelihood folded into slots gives every row's pointwise value, the total and the profiled
    levels of the likelihood that evaluates every row; the model is evaluated at 48 of 89 geometries per wavelength."""
    from spacepol.infer.likelihood import Likelihood
    from spacepol.io.measurements import Dataset
    from spacepol.physics import mirror

    ti, tr, dphi = _paired_geometry(rng)
    ti, tr, dphi = np.append(ti, ti[0]), np.append(tr, tr[0]), np.append(dphi, dphi[0])  # a repeated measurement
    n = ti.size
    geometry = Geometry(np.tile(ti, 2), np.tile(tr, 2), np.tile(dphi, 2), np.repeat([0.53, 0.63], n))
    # the slots' bookkeeping does not depend on the effects (each effect's mirror symmetry and the phase matrix's
    # folded program are checked above): a model whose out-of-plane rows fill all 16 elements, compiled quickly
    model = SpectralModel(Model.from_string("specular+smith+subsurface"), [0.53, 0.63])
    truth = _random_params(model, rng)
    data = Dataset(geometry.theta_i, geometry.theta_r, geometry.dphi, wavelength_um=geometry.wavelength_um)
    data.mueller = model.evaluate(truth, geometry, mueller=True).mueller * (1 + 0.02 * rng.standard_normal((4, 4, 2 * n)))
    data.mueller_noise_profile = rng.uniform(0.5, 2.0, (3, 2 * n))
    data.source = "mirror pairs"
    sets = {**{k: np.full(3, v) for k, v in truth.items()}, "sigma": np.array([0.1, 0.2, 0.3])}
    outputs = {}
    for fold in (True, False):
        # the program is built at the first call: a fold that must save more than every row never happens
        monkeypatch.setattr(mirror, "MIN_SAVED", 0.1 if fold else 1.1)
        likelihood = Likelihood(data, model)
        noise = {p.name: np.array([0.01, 0.02, 0.05]) for p in likelihood.nuisance}
        levels = tuple((p.name, 1e-4, 1.0) for p in likelihood.nuisance)
        outputs[fold] = (likelihood.pointwise({**sets, **noise}), likelihood.total({**sets, **noise}),
                         *likelihood.profiled(sets, levels), [None if f is None else f.geometry.size
                                                               for f in likelihood._program.folds])
    (a, a_total, a_max, a_levels, a_folds), (b, b_total, b_max, b_levels, b_folds) = outputs[True], outputs[False]
    assert a_folds == [48, 48] and b_folds == [None, None] and len(b_levels) == 3
    # rounding: a row and its mirror image differ in the last bits of their angles
    assert np.max(np.abs(a - b)) < 1e-10 * np.max(np.abs(b)) and np.allclose(a_total, b_total, rtol=1e-11)
    assert np.allclose(a_max, b_max, rtol=1e-11) and all(np.allclose(a_levels[k], b_levels[k], rtol=1e-11) for k in b_levels)
    assert np.ptp(b_total) > 1.0  # the sets differ


def test_the_folded_likelihood_of_dop_aop_and_brdf_is_the_unfolded_one(rng, monkeypatch):
    """Stokes observables at mirror pairs: the AoP changes sign in the mirror (S2 does), the DOP and BRDF do not; the
    folded likelihood gives the unfolded one's pointwise values (AoP's noise inferred, growing as 1 / DOP)."""
    from spacepol.infer.likelihood import Likelihood
    from spacepol.io.measurements import Dataset
    from spacepol.physics import mirror

    ti, tr, dphi = _paired_geometry(rng)
    geometry = Geometry(ti, tr, dphi, np.full(ti.size, 0.63))
    model = Model.from_string("specular+smith+polarized_diffuse")
    truth = _random_params(model, rng)
    predicted = model.evaluate(truth, geometry)
    data = Dataset(ti, tr, dphi, wavelength_um=geometry.wavelength_um)
    data.dop, data.dop_err = predicted.dop + 0.01 * rng.standard_normal(ti.size), np.full(ti.size, 0.01)
    data.brdf, data.brdf_err = predicted.brdf * (1 + 0.02 * rng.standard_normal(ti.size)), 0.02 * predicted.brdf
    data.aop = predicted.aop_deg + rng.standard_normal(ti.size)
    data.source = "mirror pairs, Stokes"
    sets = {**{k: np.full(3, v) for k, v in truth.items()}, "sigma_aop_deg": np.array([0.5, 1.0, 2.0])}
    outputs = {}
    for fold in (True, False):
        monkeypatch.setattr(mirror, "MIN_SAVED", 0.1 if fold else 1.1)
        likelihood = Likelihood(data, model, observables=["dop", "aop", "brdf"])
        outputs[fold] = (likelihood.pointwise(sets), [None if f is None else f.geometry.size
                                                       for f in likelihood._program.folds])
    (a, a_folds), (b, b_folds) = outputs[True], outputs[False]
    assert a_folds == [48] and b_folds == [None]
    assert np.max(np.abs(a - b)) < 1e-10 * np.max(np.abs(b)) and np.ptp(b.sum(axis=1)) > 1.0
