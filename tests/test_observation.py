"""A pass observed with a micro-polarizer camera: the CIE sky's normalisation, observe.json's
fields, P_d at the false-alarm rate where the target sends no light, and the Stokes detector never below intensity."""

import numpy as np
import pytest

from spacepol.camera.sensor import Camera
from spacepol.detect.observation import auto_exposure_s, cie_relative_radiance, observe_pass
from spacepol.orbit import Face, pass_geometry, read_tle
from spacepol.paths import bundled
from spacepol.physics.model import Model

SITE = (43 + 8 / 60, 125 + 32 / 60, 200.0)


def test_the_cie_clear_sky_is_one_at_the_zenith_and_brightest_near_the_sun():
    sun_zenith = np.array([20.0, 50.0, 80.0])
    assert np.allclose(cie_relative_radiance(0.0, sun_zenith, sun_zenith), 1.0)
    near, far = cie_relative_radiance(50.0, 5.0, 50.0), cie_relative_radiance(50.0, 90.0, 50.0)
    assert near > 5 * far  # the circumsolar brightening of a clear sky


@pytest.fixture(scope="module")
def observation():
    tle = read_tle(bundled("tle", "iss_zarya_2014-01-20.tle"))
    faces = [Face("body", 20.0, "nadir", (0, 0, 1)), Face("panel", 60.0, "sun")]
    g = pass_geometry(tle, SITE, "2014-01-21T00:33:00Z", "2014-01-21T00:40:00Z", 30.0, faces)
    rng = np.random.default_rng(0)
    draws = {"n": rng.normal(1.3, 0.05, 40), "k": rng.normal(7.5, 0.3, 40), "sigma": rng.uniform(0.1, 0.2, 40),
             "ks": np.full(40, 0.9)}
    camera = Camera(exposure_s=auto_exposure_s(Camera(), g))  # the brightest sky of the pass at half the well
    return observe_pass(g, Model.from_string("specular+smith"), draws, camera)


def test_observe_json_has_designs_fields_and_pd_is_the_false_alarm_rate_without_light(observation):
    j = observation.to_json()
    assert {"satellite", "site", "window", "camera", "detectors", "times", "p_false_alarm"} <= set(j)
    row = j["times"][0]
    assert {"time_utc", "range_km", "elevation_deg", "sun_elevation_deg", "phase_angle_deg", "sunlit", "target", "sky",
            "p_detect"} <= set(row)
    assert set(row["target"]) == {"flux", "dolp", "aop_deg"} and set(row["p_detect"]) == {"intensity", "stokes", "dolp"}
    dark = observation.light.lit_faces == 0
    assert dark.any() and (~dark).any()
    for detector, p in observation.p_detect.items():
        assert np.allclose(p[:, dark & (observation.geometry.elevation_deg > 0)], observation.p_false_alarm)
        # the matched filters' P_d never fall below P_fa; the DoLP image's is a Monte-Carlo figure (2,000 frames)
        low = observation.p_false_alarm - (1e-12 if detector != "dolp" else 4 * np.sqrt(observation.p_false_alarm / 2000))
        assert np.all((p[np.isfinite(p)] >= low) & (p[np.isfinite(p)] <= 1.0)), detector


def test_the_stokes_detector_is_never_below_intensity(observation):
    d_i, d_s = observation.deflection["intensity"], observation.deflection["stokes"]
    seen = np.isfinite(d_i)
    assert np.all(d_s[seen] >= d_i[seen] * (1 - 1e-12))
    assert np.nanmax(d_i) > 1.0  # the target is seen somewhere in the pass (the check above is not of zeros)
    # the exposure chosen for the pass keeps the sky out of saturation: half the well at its brightest
    assert 1e-7 < observation.camera.exposure_s < 1e-2


def test_a_brighter_sky_lowers_the_deflection_and_an_unpolarized_one_leaves_only_the_targets_polarization(observation):
    """The sky's level and P_max are the user's to set: a sky 0.5 mag brighter (1.58x, below saturation with the
    exposure kept) costs the intensity filter deflection (more background noise: about 1 / sqrt(1.58) where the sky
    dominates the noise), and with P_max 0 the sky has no DoLP anywhere."""
    g, camera = observation.geometry, observation.camera
    model = Model.from_string("specular+smith")
    draws = {k: v[:5] for k, v in {"n": np.full(40, 1.3), "k": np.full(40, 7.5), "sigma": np.full(40, 0.15),
                                   "ks": np.full(40, 0.9)}.items()}
    base = observe_pass(g, model, draws, camera, dolp_frames=160, positions_per_side=1)
    bright = observe_pass(g, model, draws, camera, sky_magnitude_zenith=5.40 - 0.5, dolp_frames=160, positions_per_side=1)
    seen = np.nan_to_num(base.deflection["intensity"]) > 1.0
    ratio = bright.deflection["intensity"][seen] / base.deflection["intensity"][seen]
    assert seen.any() and np.all((ratio > 0.7) & (ratio < 0.9)), ratio
    flat = observe_pass(g, model, draws, camera, p_max=0.0, dolp_frames=160, positions_per_side=1)
    assert np.all(flat.sky_dolp == 0.0) and np.nanmax(base.sky_dolp) > 0.1


def test_observe_from_the_command_line_writes_its_files_and_bad_input_is_one_line(tmp_path):
    import json
    from cli_runner import run_cli
    from test_contrast import _run_dir

    run = _run_dir(tmp_path, spread=1.0)
    summary = json.loads((run / "summary.json").read_text())  # a run that held a parameter fixed, as most do
    summary["fixed"] = {"sigma_p": Model.from_string(summary["model"]).parameter("sigma_p").default}
    (run / "summary.json").write_text(json.dumps(summary))
    tle = bundled("tle", "iss_zarya_2014-01-20.tle")
    args = ["observe", str(run), "--tle", str(tle), "--site", "43.1333,125.5333,200",
            "--start", "2014-01-21T00:33:00Z", "--end", "2014-01-21T00:39:00Z", "--step", "30", "--draws", "10"]
    done = run_cli(*args, "--out", tmp_path / "obs")
    assert done.returncode == 0, done.stderr
    content = json.loads((tmp_path / "obs" / "observe.json").read_text())
    assert content["satellite"] == "ISS (ZARYA)" and len(content["times"]) == 13 and content["p_false_alarm"] == 1e-3
    assert (tmp_path / "obs" / "light_curves.png").stat().st_size > 0 and "P_d" in (tmp_path / "obs" / "report.html").read_text()
    assert "best P_d" in done.stdout
    # the exposure follows the user's sky: 2.4 mag brighter, the pass's auto exposure at that sky, not at the default
    bright = run_cli(*args, "--sky-zenith-mag", "3.0", "--out", tmp_path / "bright")
    assert bright.returncode == 0, bright.stderr
    g = pass_geometry(read_tle(tle), (43.1333, 125.5333, 200.0), "2014-01-21T00:33:00Z", "2014-01-21T00:39:00Z", 30.0)
    exposure = json.loads((tmp_path / "bright" / "observe.json").read_text())["camera"]["exposure_s"]
    assert exposure == auto_exposure_s(Camera(), g, 3.0) != auto_exposure_s(Camera(), g, 5.40), exposure
    for bad, words in ((["--site", "95,125"], "--site '95,125'"), (["--start", "2014-01-21T00:33:00"], "UTC offset"),
                       (["--p-max", "1.5"], "--p-max 1.5")):
        argv = list(args)
        flag = bad[0]
        if flag in argv:
            argv[argv.index(flag) + 1] = bad[1]
        else:
            argv += bad
        failed = run_cli(*argv, "--out", tmp_path / "bad")
        assert failed.returncode == 2 and words in failed.stderr, failed.stderr
        assert len(failed.stderr.strip().splitlines()) == 1 and not (tmp_path / "bad").exists()


def test_the_demos_pass_writes_its_report_and_names_every_detector(tmp_path):
    """``invert-mcmc demo``'s sixth step: a run's material on the bundled daytime pass."""
    from test_contrast import _run_dir

    from spacepol.report.demo import observe_demo_pass

    observation, lines = observe_demo_pass(_run_dir(tmp_path, spread=1.0), tmp_path / "observe", 0)
    assert {"intensity", "stokes", "dolp"} == set(observation.p_detect)
    assert all(any(line.startswith(f"{d}: best median P_d") for line in lines) for d in observation.p_detect)
    assert (tmp_path / "observe" / "report.html").exists() and (tmp_path / "observe" / "light_curves.png").exists()
    over = observation.p_detect_over_pass()
    assert over["stokes"].shape == (100,) and np.all(over["stokes"] >= over["false_alarm"] - 1e-12)


def test_an_automatic_exposure_never_outlasts_the_time_step():
    """Under a twilight sky (the ISS over Perth, sun 10 deg down) half the well takes minutes to fill; the exposure
    set for a pass in 20 s steps is the step itself, one a camera can take within it, and a step long enough leaves
    the sky's own choice."""
    from spacepol.detect.observation import exposed_for

    tle = read_tle(bundled("tle", "iss_zarya_2014-01-20.tle"))
    g = pass_geometry(tle, (-31.95, 115.86, 20.0), "2014-01-23T12:10:00Z", "2014-01-23T12:15:00Z", 20.0)
    free = auto_exposure_s(Camera(), g)
    assert free > 100.0, free  # the sky alone would ask for minutes
    assert exposed_for(Camera(exposure_set=False), g, 5.40, 20.0).exposure_s == 20.0
    assert exposed_for(Camera(exposure_set=False), g, 5.40, 10 * free).exposure_s == free
    assert exposed_for(Camera(exposure_s=300.0), g, 5.40, 20.0).exposure_s == 300.0  # the user's own is kept
