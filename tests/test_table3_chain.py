"""The paper's Table 3 limit through the pass chain: Table 2's instrument as a camera of the chain gives
eq 36's sky electrons and eq 35's target electrons exactly, and the chain's intensity detector reaches the required
SNR where a matched filter over the k spot pixels must (closed form); the control, the spot placed across four
superpixels instead of on one, needs about twice the flux."""

import numpy as np
import pytest

from spacepol.detect import radiometry as R
from spacepol.detect.point_source import point_source_stamp
from spacepol.detect.scenario import default_scenario
from spacepol.detect.table3_chain import (STAMP_PIXELS, chain_limit, instrument_camera, paper_spot,
                                          sky_stokes_per_pixel)


@pytest.fixture(params=[22.0, 5.40], ids=["paper's night sky", "daytime sky"])
def inst(request):
    inst = dict(default_scenario().instrument)
    inst["background_magnitude"] = request.param
    return inst


def test_table_2_as_a_camera_gives_eqs_35_and_36(inst):
    camera = instrument_camera(inst)
    for p_sky in (0.0, 0.6):
        stamp = point_source_stamp(camera, sky_stokes_per_pixel(inst, p_sky, 30.0), (0.0, 0.0), STAMP_PIXELS,
                                   psf=paper_spot(inst["spot_pixels"]))
        dark = inst["dark_current_e_per_s"] * inst["integration_time_s"]
        # the superpixel mean: the corrected reading's 1/2 whatever the sky's polarization
        assert np.mean(stamp.sky_e) - dark == pytest.approx(float(R.background_electrons(inst, p_sky, "corrected")), rel=1e-9)
        phi = 1e6  # photons m^-2 s^-1 through the polarizer, as eq 35 counts them
        target = stamp.electrons(np.array([[phi / 0.5, 0.0, 0.0]]))[0]
        spot = target[target > 0]
        assert spot.size == 4 and np.allclose(spot, float(R.target_electrons(phi, inst)), rtol=1e-9)


def test_the_chains_limit_is_a_matched_filter_over_the_spot(inst):
    limit = chain_limit(inst, p_sky=0.3)
    k = inst["spot_pixels"]
    n_b = float(R.background_electrons(inst, 0.3, "corrected"))
    noise2 = n_b + inst["dark_current_e_per_s"] * inst["integration_time_s"] + inst["read_noise_e"] ** 2
    n_s = inst["snr_required"] * np.sqrt(noise2 / k)  # k n_s / sqrt(k noise^2) = SNR
    expected = n_s / R.target_electron_factor(inst) / 0.5
    assert limit["chain"]["limit_flux_photons_m2_s"] == pytest.approx(expected, rel=1e-9)
    assert limit["chain"]["limiting_magnitude"] == pytest.approx(float(R.magnitude(expected, inst)), abs=1e-9)
    assert limit["eq38"]["limit_flux_photons_m2_s"] == pytest.approx(float(R.limit_flux(inst, 0.3, "corrected")) / 0.5, rel=1e-12)
    # the control: the same four pixels' light across four superpixels (one pixel in each)
    camera = instrument_camera(inst)
    straddling = np.roll(paper_spot(k), (1, 1), axis=(0, 1))
    stamp = point_source_stamp(camera, sky_stokes_per_pixel(inst, 0.3), (0.0, 0.0), STAMP_PIXELS, psf=straddling)
    wrong = inst["snr_required"] / float(stamp.deflections(np.array([[1.0, 0.0, 0.0]]))["intensity"][0])
    assert wrong > 1.8 * expected
