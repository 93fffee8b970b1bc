"""The attitude the draws miss: a mirrored optimum as good as the best draw, outside every draw, is found and named."""

import numpy as np
import pytest

from spacepol.detect.attitude_modes import MARGIN, unsampled_mode

NAMES = ["n", "yaw_deg", "pitch_deg", "roll_deg"]
ANGLES = ["yaw_deg", "pitch_deg", "roll_deg"]
BOUNDS = [(1.0, 2.0), (-60.0, 60.0), (-60.0, 60.0), (-60.0, 60.0)]
FIRST = np.array([1.5, -56.0, 27.6, -38.9])
# near the mirror (-yaw, pitch, -roll) of the first, not on it: the sun and the site are not mirrored
SECOND = np.array([1.5, 53.5, 34.4, 44.0])
SD = np.array([0.01, 1.0, 1.0, 1.0])


def _density(second_below: float):
    def log_posterior(theta):
        a = -0.5 * np.sum(((theta - FIRST) / SD) ** 2, axis=1)
        b = -0.5 * np.sum(((theta - SECOND) / SD) ** 2, axis=1) - second_below
        return np.logaddexp(a, b)
    return log_posterior


def _draws(rng, centres):
    parts = [c + SD * rng.standard_normal((1000, 4)) for c in centres]
    return np.concatenate(parts)


@pytest.mark.parametrize("second_below", [1.1, -0.5])
def test_a_mirrored_mode_the_draws_miss_is_found(second_below):
    rng = np.random.default_rng(3)
    log_posterior = _density(second_below)
    draws = _draws(rng, [FIRST])  # nested sampling kept the first mode only
    mode = unsampled_mode(log_posterior, NAMES, BOUNDS, draws, log_posterior(draws), np.random.default_rng(1))
    assert mode is not None
    found = np.array([mode.attitude[a] for a in ANGLES])
    assert np.allclose(found, SECOND[1:], atol=0.05), found
    assert abs(mode.below_best - second_below) < 0.5, mode.below_best
    assert "outside every draw" in mode.finding and "yaw 53.5" in mode.finding, mode.finding


def test_nothing_is_named_where_the_draws_hold_both_modes_or_the_second_is_far_below():
    rng = np.random.default_rng(4)
    both = _density(1.1)
    draws = _draws(rng, [FIRST, SECOND])
    assert unsampled_mode(both, NAMES, BOUNDS, draws, both(draws), np.random.default_rng(2)) is None
    low = _density(MARGIN + 10.0)  # holds e^-13 of the first's mass: not a mode worth naming
    draws = _draws(rng, [FIRST])
    assert unsampled_mode(low, NAMES, BOUNDS, draws, low(draws), np.random.default_rng(3)) is None


def test_a_known_attitude_has_nothing_to_check():
    rng = np.random.default_rng(5)
    draws = 1.5 + 0.01 * rng.standard_normal((100, 1))
    assert unsampled_mode(lambda t: -0.5 * ((t[:, 0] - 1.5) / 0.01) ** 2, ["n"], [(1.0, 2.0)], draws,
                          np.zeros(100), np.random.default_rng(4)) is None
