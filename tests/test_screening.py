"""Screening a change near the model it changes (``optimum.screen_optimum``; diagnose's step 2).

A thin film makes the log posterior a comb of interference orders in its thickness: from the base model's optimum
with the film's thickness at 0 (where it changes nothing) local polishes and a seeded DE end on a lower tooth. The
scan over the change's own parameters is what reaches the global search's maximum; the control is the same search
without it. A second member added beside a filled slot starts with the first member's share carried over too
(``changes.start_points``)."""

import numpy as np
from test_residuals import _data as measured

from spacepol.criticism.changes import parse, start_points
from spacepol.infer.optimum import find_optimum, screen_optimum
from spacepol.infer.posterior import Posterior
from spacepol.physics import Model

SUBSTRATE = {"n": 1.24, "k": 6.6, "sigma": 0.2, "ks": 0.7, "rho_d": 0.05}
FILM = {"thickness_um": 0.25, "n_film": 1.65}


def _data(spec, truth, seed=3):
    return measured(spec, truth, seed, wavelength_um=0.633)  # a film needs the wavelength


def _film_screening(points_list, seeds):
    """{points: [screening gain per seed]} for `add oxide_layer` to `paper` on a film over a metal, and the global
    search's gain (``find_optimum``, with its multistart)."""
    data = _data("paper+oxide_layer", {**SUBSTRATE, **FILM})
    base = Posterior.build(data, Model.from_string("paper"))
    base_value, base_theta = find_optimum(base, np.random.default_rng(0))
    base_best = dict(zip(base.priors.names, base_theta))
    change = parse(Model.from_string("paper"), "add oxide_layer")
    post = Posterior.build(data, change.model)
    starts = start_points(base_best, change, post)
    new = [j for j, name in enumerate(post.priors.names) if name not in base_best]
    gains = {points: [screen_optimum(post, np.random.default_rng(seed), starts, new, points=points)[0] - base_value
                      for seed in seeds] for points in points_list}
    return gains, find_optimum(post, np.random.default_rng(100))[0] - base_value


def test_screening_reaches_the_global_maximum_with_a_film_from_every_seed_and_without_its_scan_does_not():
    # a film on a metal seen in DOP and BRDF: its thickness trades against the substrate's n and k, a comb of
    # interference orders for a local search (here the maximum lies above the truth's, at another order)
    gains, global_gain = _film_screening((512, 0), range(8))
    # a screening gain is a lower bound (loose polishes: optimum.SCREEN_FTOL); 3 units is below any gain diagnose acts on
    assert min(gains[512]) > global_gain - 3.0, (gains, global_gain)
    # control: without the scan over the film's own parameters some seeds end on a lower order
    assert min(gains[0]) < global_gain - 5.0, (gains, global_gain)


def test_an_addition_beside_its_slots_member_starts_with_that_members_share_carried_over():
    model = Model.from_string("paper")
    change = parse(model, "add subsurface")
    post = Posterior.build(_data("paper", SUBSTRATE), change.model)
    base_best = {**SUBSTRATE, "k": 6.6}
    rows = start_points(base_best, change, post)
    names = post.priors.names
    moved = [r for r in rows if r[names.index("rho_d")] == 0.0 and r[names.index("rho_s")] == SUBSTRATE["rho_d"]]
    assert len(rows) == 6 and len(moved) == 1
    # a replacement or an addition without a slot gets no such row
    assert len(start_points(base_best, parse(model, "add extinction"), Posterior.build(_data("paper", SUBSTRATE),
                                                                                        parse(model, "add extinction").model))) == 5
