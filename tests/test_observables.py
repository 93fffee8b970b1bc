"""Observables as objects: each one's log density against a direct computation from the
model's output, written here without the observable's code."""

import math

import numpy as np
import pytest

from spacepol.infer.likelihood import Likelihood
from spacepol.io.measurements import Dataset
from spacepol.physics import Model
from spacepol.physics.geometry import Geometry

TRUTH = {"n": 1.5, "k": 0.1, "sigma": 0.2, "ks": 0.7, "rho_pd": 0.2}
OTHER = {"n": 1.6, "k": 0.05, "sigma": 0.25, "ks": 0.6, "rho_pd": 0.15}  # where the density is evaluated
MODEL = "specular+smith+polarized_diffuse"


def _geometry():
    ti = np.repeat([20.0, 45.0, 60.0], 8)
    tr = np.tile(np.linspace(5.0, 75.0, 8), 3)
    dphi = np.tile([180.0, 150.0, 120.0, 90.0], 6)
    return Geometry(ti, tr, dphi)


def _data(rng):
    g = _geometry()
    pred = Model.from_string(MODEL).evaluate(TRUTH, g, mueller=True)
    d = Dataset(g.theta_i, g.theta_r, g.dphi)
    d.dop = np.clip(pred.dop + 0.01 * rng.standard_normal(g.size), 0, 1)
    d.dop_err = np.full(g.size, 0.01)
    d.brdf = pred.brdf * (1 + 0.05 * rng.standard_normal(g.size))
    d.stokes = pred.stokes + 0.002 * rng.standard_normal(pred.stokes.shape)
    d.aop = 0.5 * np.degrees(np.arctan2(pred.stokes[2], pred.stokes[1])) + 2.0 * rng.standard_normal(g.size)
    d.aop_err = np.full(g.size, 2.0)
    d.mueller = pred.mueller * (1 + 0.01 * rng.standard_normal(pred.mueller.shape))
    d.mueller[0, 0] = pred.mueller[0, 0]
    return d, g


def _gauss(resid, scale):
    return -0.5 * (resid / scale) ** 2 - np.log(scale) - 0.5 * math.log(2 * math.pi)


def _direct(name, data, g, params):
    """The log density per geometry written from the definitions in DESIGN.md and the observables' docs."""
    model = {k: params[k] for k in TRUTH}
    p = Model.from_string(MODEL).evaluate(model, g, mueller=True)
    if name == "dop":
        return _gauss(data.dop - p.dop, data.dop_err)
    if name == "brdf":  # no brdf_err: log BRDF, relative noise sigma_brdf_rel
        return _gauss(np.log(data.brdf) - np.log(p.stokes[0]), params["sigma_brdf_rel"])
    if name == "aop":
        d = data.aop - 0.5 * np.degrees(np.arctan2(p.stokes[2], p.stokes[1]))
        d = (d + 90.0) % 180.0 - 90.0
        return _gauss(d, data.aop_err)
    if name == "stokes":
        q, u = data.stokes[1] / data.stokes[0], data.stokes[2] / data.stokes[0]
        mq, mu = p.stokes[1] / p.stokes[0], p.stokes[2] / p.stokes[0]
        return np.concatenate([_gauss(q - mq, params["sigma_qu"]), _gauss(u - mu, params["sigma_qu"])])
    if name == "mueller":
        groups = {"pol": {(0, 1), (0, 2), (0, 3), (1, 0), (2, 0), (3, 0)}, "lin": {(1, 1), (1, 2), (2, 1), (2, 2)}}
        blocks = []
        for i in range(4):
            for j in range(4):
                if i == j == 0:
                    continue
                group = next((gname for gname, members in groups.items() if (i, j) in members), "circ")
                m_data = data.mueller[i, j] / data.mueller[0, 0]
                m_model = p.mueller[i, j] / p.mueller[0, 0]
                blocks.append(_gauss(m_data - m_model, params[f"sigma_m_{group}"]))
        return np.concatenate(blocks)
    raise AssertionError(name)


NUISANCE = {"sigma_brdf_rel": 0.07, "sigma_qu": 0.004, "sigma_m_pol": 0.011, "sigma_m_lin": 0.013, "sigma_m_circ": 0.02}


@pytest.mark.parametrize("name", ["dop", "brdf", "aop", "stokes", "mueller"])
def test_log_density_equals_a_direct_computation(name):
    data, g = _data(np.random.default_rng(3))
    lik = Likelihood(data, Model.from_string(MODEL), observables=[name])
    params = {**{k: np.array([v]) for k, v in OTHER.items()}, **{k: np.array([v]) for k, v in NUISANCE.items()}}
    got = lik.pointwise(params)[0]
    want = _direct(name, data, g, {**OTHER, **NUISANCE})
    assert got.shape == want.shape == (len(lik.observables) * g.size,)
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10)
    # negative control: the density at other parameters differs
    shifted = {**params, "n": np.array([1.9])}
    assert not np.allclose(lik.pointwise(shifted)[0], want)


def test_inferred_aop_noise_grows_as_one_over_the_measured_dop():
    """Without aop_err, the AoP's noise is sigma_aop_deg / max(DOP, 0.05) per row (a polarimeter's q, u noise
    seen through AoP = atan2(u, q) / 2); negative control: the constant-noise density differs."""
    data, g = _data(np.random.default_rng(3))
    data.aop_err = None
    lik = Likelihood(data, Model.from_string(MODEL), observables=["aop"])
    params = {**{k: np.array([v]) for k, v in OTHER.items()}, "sigma_aop_deg": np.array([0.8])}
    p = Model.from_string(MODEL).evaluate(OTHER, g)
    resid = (data.aop - 0.5 * np.degrees(np.arctan2(p.stokes[2], p.stokes[1])) + 90.0) % 180.0 - 90.0
    scale = 0.8 / np.maximum(data.dop, 0.05)
    np.testing.assert_allclose(lik.pointwise(params)[0], _gauss(resid, scale), rtol=1e-10, atol=1e-10)
    assert data.dop.min() < 0.5 and not np.allclose(lik.pointwise(params)[0], _gauss(resid, np.full(g.size, 0.8)))


def test_observables_declare_their_channels_and_noise():
    data, _ = _data(np.random.default_rng(3))
    lik = Likelihood(data, Model.from_string(MODEL), observables=["mueller", "brdf"])
    assert lik.observables[:15] == [f"m{i}{j}" for i in range(1, 5) for j in range(1, 5)][1:] and lik.observables[15] == "brdf"
    assert {p.name for p in lik.nuisance} == {"sigma_m_pol", "sigma_m_lin", "sigma_m_circ", "sigma_brdf_rel"}
    assert Likelihood(data, Model.from_string(MODEL), observables=["q", "u"]).observables == ["q", "u"]  # aliases
    with pytest.raises(Exception, match="named twice"):
        Likelihood(data, Model.from_string(MODEL), observables=["dop", "dop"])


def _mueller_csv(path, data, header_extra=None, row_edit=None, errors="m_err"):
    from spacepol.io.measurements import write_table
    from spacepol.observables.mueller import ELEMENTS as MUELLER_COLUMNS

    cols = {"theta_i": data.theta_i, "theta_r": data.theta_r, "dphi": data.dphi, "brdf": data.mueller[0, 0]}
    for m in MUELLER_COLUMNS:
        cols[m] = data.mueller[int(m[1]) - 1, int(m[2]) - 1] / data.mueller[0, 0]
    if errors == "m_err":
        cols["m_err"] = np.full(len(data), 0.01)
    elif errors == "each":
        cols.update({f"{m}_err": np.full(len(data), 0.01 + 0.001 * k) for k, m in enumerate(MUELLER_COLUMNS)})
    for edit in (header_extra or []):
        edit(cols)
    write_table(path, cols)
    if row_edit:
        lines = path.read_text().splitlines()
        lines[1] = row_edit(lines[0].split(","), lines[1].split(","))
        path.write_text("\n".join(lines) + "\n")
    return path


def test_mueller_columns_are_read_with_their_errors(tmp_path):
    from spacepol.io import read_measurements

    data, _ = _data(np.random.default_rng(4))
    back = read_measurements(_mueller_csv(tmp_path / "m.csv", data))
    np.testing.assert_allclose(back.mueller, data.mueller, rtol=1e-12)
    assert np.all(back.mueller_err[0, 1] == 0.01) and np.isnan(back.mueller_err[0, 0]).all()
    each = read_measurements(_mueller_csv(tmp_path / "e.csv", data, errors="each"))
    assert each.mueller_err[3, 3][0] == pytest.approx(0.01 + 0.001 * 14)  # m44_err, the 15th column
    lik = Likelihood(each, Model.from_string(MODEL), observables=["mueller"])
    assert lik.nuisance == [] and lik.scale("m44")[0] == pytest.approx(0.024)
    inferred = read_measurements(_mueller_csv(tmp_path / "n.csv", data, errors=None))
    assert inferred.mueller_err is None
    assert {p.name for p in Likelihood(inferred, Model.from_string(MODEL), observables=["mueller"]).nuisance} == \
        {"sigma_m_pol", "sigma_m_lin", "sigma_m_circ"}


def _set_cell(column, text):
    def edit(header, row):
        row[header.index(column)] = text
        return ",".join(row)
    return edit


@pytest.mark.parametrize("case, words", [
    ("outside", ["m34", "outside [-1, 1]", "line 2"]),
    ("missing", ["all 15 elements", "missing m43"]),
    ("err_alone", ["m_err", "without the Mueller elements"]),
    ("partial_errors", ["per-element Mueller errors", "missing m13_err"]),
    ("dop_above_one", ["m21, m31, m41", "DOP", "> 1"]),
])
def test_bad_mueller_input_is_one_clear_error(tmp_path, case, words):
    from spacepol.errors import InputFileError
    from spacepol.io import read_measurements

    data, _ = _data(np.random.default_rng(4))
    if case == "outside":
        path = _mueller_csv(tmp_path / "b.csv", data, row_edit=_set_cell("m34", "1.2"))
    elif case == "missing":
        path = _mueller_csv(tmp_path / "b.csv", data, header_extra=[lambda c: c.pop("m43")])
    elif case == "err_alone":
        from spacepol.io.measurements import write_table

        path = tmp_path / "b.csv"
        write_table(path, {"theta_i": data.theta_i, "theta_r": data.theta_r, "dop": data.dop, "m_err": np.full(len(data), 0.01)})
    elif case == "partial_errors":
        path = _mueller_csv(tmp_path / "b.csv", data, errors=None, header_extra=[lambda c: c.update(m12_err=np.full(len(data), 0.01))])
    else:
        def edit(header, row):
            for m in ("m21", "m31"):
                row[header.index(m)] = "0.8"
            return ",".join(row)
        path = _mueller_csv(tmp_path / "b.csv", data, row_edit=edit)
    with pytest.raises(InputFileError) as err:
        read_measurements(path)
    message = str(err.value)
    assert "\n" not in message and all(w in message for w in words), message


def test_mueller_residuals_are_drawn_as_the_matrix():
    """The 4 x 4 residual figure: one panel per element (BRDF at 1,1), titled with its RMS; red where the
    RMS exceeds 1.5 (a wrong index: the control)."""
    from spacepol.infer.posterior import Posterior
    from spacepol.report.inversion_figures import mueller_residual_figure

    data, _ = _data(np.random.default_rng(4))
    data.mueller_err = np.full((4, 4, len(data)), 0.01)
    data.brdf_err = 0.05 * data.brdf
    post = Posterior.build(data, Model.from_string(MODEL), observables=["mueller", "brdf"])

    class Draws:  # a posterior that is one point
        def __init__(self, values):
            self.values = np.array([[values[n] for n in post.names]] * 4)

        def flat_samples(self):
            return self.values

    good = mueller_residual_figure(post, Draws(TRUTH))
    titles = [ax.get_title() for ax in good.axes if ax.get_title()]
    assert len(titles) == 16 and titles[0].startswith("brdf") and titles[-1].startswith("m44")
    assert all(ax.title.get_color() == "k" for ax in good.axes if ax.get_title())
    bad = mueller_residual_figure(post, Draws({**TRUTH, "n": 1.9}))
    assert any(ax.title.get_color() == "C3" for ax in bad.axes if ax.get_title())


def test_mueller_channels_fitted_as_one_block_equal_the_direct_computation():
    """The 15 Mueller channels go through the compiled likelihood as one array (``Observable.predict_stacked``):
    for three parameter sets, with inferred noise (three group levels) and with the file's per-element errors, the
    pointwise values equal the direct computation, ``total`` their sum and ``profiled`` the levels' closed-form
    maxima (the RMS of each group's residuals). Negative control: the groups' levels swapped give other values."""
    data, g = _data(np.random.default_rng(5))
    model = Model.from_string(MODEL)
    sets = [OTHER, {**OTHER, "n": 1.45, "sigma": 0.3}, {**OTHER, "k": 0.2, "rho_pd": 0.3}]
    params = {k: np.array([s[k] for s in sets]) for k in TRUTH}
    noise = {"sigma_m_pol": 0.011, "sigma_m_lin": 0.013, "sigma_m_circ": 0.02}
    lik = Likelihood(data, model, observables=["mueller"])
    got = lik.pointwise({**params, **{k: np.full(3, v) for k, v in noise.items()}})
    want = np.array([_direct("mueller", data, g, {**s, **noise}) for s in sets])
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(lik.total({**params, **{k: np.full(3, v) for k, v in noise.items()}}), want.sum(axis=1),
                               rtol=1e-12)
    swapped = {"sigma_m_pol": 0.02, "sigma_m_lin": 0.013, "sigma_m_circ": 0.011}
    assert not np.allclose(lik.pointwise({**params, **{k: np.full(3, v) for k, v in swapped.items()}}), want)
    # the levels profiled: each the RMS of its group's residuals (clipped to its bounds)
    levels = tuple((k, 1e-4, 0.5) for k in noise)
    value, found = lik.profiled(params, levels)
    groups = {"sigma_m_pol": [(0, 1), (0, 2), (0, 3), (1, 0), (2, 0), (3, 0)],
              "sigma_m_lin": [(1, 1), (1, 2), (2, 1), (2, 2)]}
    groups["sigma_m_circ"] = [(i, k) for i in range(4) for k in range(4) if (i, k) != (0, 0)
                              and not any((i, k) in m for m in groups.values())]
    for j, s in enumerate(sets):
        p = model.evaluate(s, g, mueller=True)
        resid = data.mueller / data.mueller[0, 0] - p.mueller / p.mueller[0, 0]
        rms = {name: np.sqrt(np.mean([resid[e] ** 2 for e in members])) for name, members in groups.items()}
        for name in noise:
            assert found[name][j] == pytest.approx(rms[name], rel=1e-10)
        assert value[j] == pytest.approx(_direct("mueller", data, g, {**s, **rms}).sum(), rel=1e-10)
    # the file's errors, one per element and row
    data.mueller_err = np.linspace(0.005, 0.03, 16).reshape(4, 4, 1) * np.linspace(1.0, 2.0, g.size)
    lik = Likelihood(data, model, observables=["mueller"])
    assert lik.nuisance == []
    want = []
    for s in sets:
        p = model.evaluate(s, g, mueller=True)
        want.append(np.concatenate([_gauss(data.mueller[i, k] / data.mueller[0, 0] - p.mueller[i, k] / p.mueller[0, 0],
                                           data.mueller_err[i, k]) for i in range(4) for k in range(4) if i or k]))
    np.testing.assert_allclose(lik.pointwise(params), np.array(want), rtol=1e-10, atol=1e-10)


def test_which_observables_read_the_measured_dop_and_which_effects_change_it_alone():
    """diagnose leaves out changes the fitted observables cannot see (``changes.blind_changes``): found by probing each
    observable's prediction (only the DOP reads the measured DOP; q, u, DoLP and DoCP are computed from the Stokes
    vector) and each effect's hooks (only dop_bias acts on the measured DOP alone)."""
    from spacepol.criticism.changes import blind_changes, changes, measured_dop_only, reads_measured_dop
    from spacepol.observables import registry as observables
    from spacepol.physics.registry import registry as effects

    readers = {name for name in observables.names() if reads_measured_dop(observables.get(name))}
    assert readers == {"dop"}, readers
    assert {name for name in effects.names() if measured_dop_only(effects.get(name))} == {"dop_bias"}
    data, _ = _data(np.random.default_rng(0))
    model = Model.from_string("specular+smith")
    candidates = changes(model, data, ["dop_bias", "lambertian"])
    mueller = Likelihood(data, model, observables=["mueller", "brdf"]).objects
    assert [c.label for c in blind_changes(candidates, mueller)] == ["add dop_bias"]
    assert blind_changes(candidates, Likelihood(data, model, observables=["dop", "brdf"]).objects) == []
