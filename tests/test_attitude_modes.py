"""The attitude the draws miss: an optimum as good as the best draw or better, outside every draw, is found and named."""

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


def _prior(rng, count=32):
    return np.column_stack([rng.uniform(lo, hi, count) for lo, hi in BOUNDS])


def _draws(rng, centres):
    parts = [c + SD * rng.standard_normal((1000, 4)) for c in centres]
    return np.concatenate(parts)


@pytest.mark.parametrize("second_below", [1.1, -0.5])
def test_a_mirrored_mode_the_draws_miss_is_found(second_below):
    rng = np.random.default_rng(3)
    log_posterior = _density(second_below)
    draws = _draws(rng, [FIRST])  # nested sampling kept the first mode only
    mode = unsampled_mode(log_posterior, NAMES, BOUNDS, draws, log_posterior(draws), _prior(rng))
    assert mode is not None
    found = np.array([mode.attitude[a] for a in ANGLES])
    assert np.allclose(found, SECOND[1:], atol=0.05), found
    assert abs(mode.below_best - second_below) < 0.5, mode.below_best
    assert "outside every draw" in mode.finding and "yaw 53.5" in mode.finding, mode.finding


def test_nothing_is_named_where_the_draws_hold_both_modes_or_the_second_is_far_below():
    rng = np.random.default_rng(4)
    both = _density(1.1)
    draws = _draws(rng, [FIRST, SECOND])
    assert unsampled_mode(both, NAMES, BOUNDS, draws, both(draws), _prior(rng)) is None
    low = _density(MARGIN + 10.0)  # holds e^-13 of the first's mass: not a mode worth naming
    draws = _draws(rng, [FIRST])
    assert unsampled_mode(low, NAMES, BOUNDS, draws, low(draws), _prior(rng)) is None


def test_a_known_attitude_has_nothing_to_check():
    rng = np.random.default_rng(5)
    draws = 1.5 + 0.01 * rng.standard_normal((100, 1))
    assert unsampled_mode(lambda t: -0.5 * ((t[:, 0] - 1.5) / 0.01) ** 2, ["n"], [(1.0, 2.0)], draws,
                          np.zeros(100), draws[:32]) is None


DEEP = np.array([1.62, -33.3, 26.6, 23.0])  # a narrow basin among ripples, nowhere near the draws' mirror
RIPPLED = np.array([1.5, -56.0, 28.0, -42.0])  # on a ripple's crest


def _rugged(with_deep_mode: bool):
    """A broad optimum at RIPPLED under ripples 7 deg apart (basins 0.2 deg wide), and (where asked) a basin one degree
    wide, 1,000 above it, at DEEP: a nested run with few live points keeps the broad one."""
    def log_posterior(theta):
        angles = theta[:, 1:]
        broad = -0.5 * np.sum(((angles - RIPPLED[1:]) / 2.0) ** 2, axis=1) - 0.5 * ((theta[:, 0] - 1.5) / 0.2) ** 2
        ripples = 30.0 * np.sum(np.cos(2 * np.pi * angles / 7.0), axis=1)
        value = -2000.0 + broad + ripples
        if with_deep_mode:
            deep = -0.5 * np.sum(((theta - DEEP) / np.array([0.02, 1.0, 1.0, 1.0])) ** 2, axis=1)
            value = np.logaddexp(value, deep - 1000.0)
        return value
    return log_posterior


def test_a_far_better_mode_the_exploration_missed_is_found_among_ripples():
    rng = np.random.default_rng(6)
    log_posterior = _rugged(True)
    draws = RIPPLED + np.array([0.01, 0.2, 0.2, 0.2]) * rng.standard_normal((1000, 4))
    mode = unsampled_mode(log_posterior, NAMES, BOUNDS, draws, log_posterior(draws), _prior(rng))
    assert mode is not None
    found = np.array([mode.attitude[a] for a in ANGLES])
    assert np.allclose(found, DEEP[1:], atol=0.1), found
    assert mode.below_best < -500, mode.below_best
    assert "far better" in mode.finding and "main mode" in mode.finding, mode.finding
    # control: the same ripples without the basin hold nothing worth naming
    plain = _rugged(False)
    assert unsampled_mode(plain, NAMES, BOUNDS, draws, plain(draws), _prior(rng)) is None
