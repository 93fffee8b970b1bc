"""A satellite's light curve: attitude offsets against scipy's rotations, the light-curve CSV and its bad input,
and ``synth-pass``'s camera noise, whose stated errors must be the scatter of what it draws (a calibration over many
noise draws, with a negative control)."""

from dataclasses import replace

from datetime import datetime, timezone

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import spacepol
from cli_runner import run_cli
from spacepol.camera.sensor import Camera
from spacepol.detect.light_curve_synth import synthesized_light_curve
from spacepol.detect.target import target_light
from spacepol.errors import ParameterError
from spacepol.io.light_curve import LightCurve, read_light_curve, write_light_curve
from spacepol.orbit import Attitude, Face, faces_from_toml, pass_geometry, read_tle, turned
from spacepol.orbit.attitude import attitude_from_table, rotations
from spacepol.paths import bundled

TLE = bundled("tle", "iss_zarya_2014-01-20.tle")
SITE = "43.1333,125.5333,200"  # the paper's site (Changchun)
START, END = "2014-01-21T00:32:00Z", "2014-01-21T00:41:00Z"  # a daytime pass of the ISS, 9 h after the epoch
ALUMINIUM = 'material = {model = "specular+smith+lambertian", n = 1.37, k = 7.6, sigma = 0.15, ks = 0.9, rho_l = 0.1}'


def target_file(tmp_path, attitude: str = "", bare: bool = False):
    """A four-face box of aluminium (one face without its material where ``bare``)."""
    faces = [("nadir", (0, 0, 1)), ("starboard", (0, 1, 0)), ("port", (0, -1, 0)), ("ram", (1, 0, 0))]
    text = attitude + "\n"
    for k, (name, normal) in enumerate(faces):
        text += f'[[faces]]\nname = "{name}"\narea_m2 = 2.0\norientation = "nadir"\nnormal = {list(normal)}\n'
        text += "" if bare and k == 0 else ALUMINIUM + "\n"
    path = tmp_path / "target.toml"
    path.write_text(text)
    return path


def test_attitude_rotations_agree_with_scipys_intrinsic_zyx_sequence():
    rng = np.random.default_rng(0)
    angles = rng.uniform(-180, 180, (50, 3))
    ours = rotations(angles[:, 0], angles[:, 1], angles[:, 2])
    theirs = Rotation.from_euler("ZYX", angles, degrees=True).as_matrix()
    np.testing.assert_allclose(ours, theirs, atol=1e-14)
    assert not np.allclose(rotations(angles[:, 0], angles[:, 1], -angles[:, 2]), theirs)  # negative control
    np.testing.assert_allclose(Attitude().rotation(), np.eye(3), atol=0)


def test_an_attitude_turns_the_body_faces_only():
    faces = [Face("nadir", 1.0, "nadir", (0.0, 0.0, 1.0)), Face("panel", 4.0, "sun"),
             Face("fixed", 1.0, "inertial", (1.0, 0.0, 0.0))]
    out = turned(faces, Attitude(yaw_deg=0.0, pitch_deg=90.0, roll_deg=0.0))
    np.testing.assert_allclose(out[0].normal, (1.0, 0.0, 0.0), atol=1e-15)  # pitch 90: nadir -> along the velocity
    assert out[1] == faces[1] and out[2] == faces[2]


def test_a_target_files_attitude_turns_its_faces_as_observe_and_synth_pass_read_them(tmp_path):
    """``target_faces`` (what observe and synth-pass read): the file's attitude turns each nadir face's normal by its
    rotation; a file without one is read as written."""
    from spacepol.orbit import target_faces

    turned_file = target_file(tmp_path, "attitude = {yaw_deg = 30.0, pitch_deg = 10.0, roll_deg = -5.0}")
    faces = target_faces(turned_file)
    rotation = Rotation.from_euler("ZYX", [30.0, 10.0, -5.0], degrees=True).as_matrix()
    for face, plain in zip(faces, faces_from_toml(turned_file)):
        np.testing.assert_allclose(face.normal, rotation @ np.asarray(plain.normal, float), atol=1e-14)
    (tmp_path / "plain").mkdir()
    plain_file = target_file(tmp_path / "plain")
    assert target_faces(plain_file) == faces_from_toml(plain_file)


@pytest.mark.parametrize("table, words", [
    ({"yaw": 3.0}, "attitude has no key yaw"),
    ({"yaw_deg": "ten"}, "yaw_deg = 'ten'"),
    ({"roll_deg": float("nan")}, "roll_deg = nan"),
    (5.0, "attitude must be a table"),
])
def test_a_bad_attitude_table_is_one_line(table, words):
    with pytest.raises(ParameterError, match=words):
        attitude_from_table(table, "--target t.toml")


def test_the_csv_round_trips_and_a_subset_of_observables_is_read(tmp_path):
    times = [datetime(2014, 1, 21, 0, 32, s, tzinfo=timezone.utc) for s in (0, 10, 20)]
    curve = LightCurve(times, dolp=np.array([0.1, 0.2, 0.15]), dolp_err=np.array([0.01, 0.01, 0.02]))
    write_light_curve(tmp_path / "lc.csv", curve)
    back = read_light_curve(tmp_path / "lc.csv")
    assert back.observables == ["dolp"] and back.times_utc == times
    np.testing.assert_array_equal(back.dolp, curve.dolp)
    np.testing.assert_array_equal(back.dolp_err, curve.dolp_err)


@pytest.mark.parametrize("text, words", [
    ("time_utc,flux\n2014-01-21T00:32:00Z,1.0\n", "flux needs its error column flux_err"),
    ("time_utc,dolp,dolp_err,colour\n2014-01-21T00:32:00Z,0.1,0.01,red\n", "unknown column colour"),
    ("time_utc,dolp,dolp_err\n2014-01-21T00:32:00Z,0.1,nan\n", "line 2, dolp_err: 'nan' is not a finite number"),
    ("time_utc,dolp,dolp_err\n2014-01-21T00:32:00Z,0.1,-0.01\n", "line 2, dolp_err: -0.01 is not an error > 0"),
    ("time_utc,dolp,dolp_err\n2014-01-21T00:32:00,0.1,0.01\n", "line 2, time_utc: give the UTC offset"),
    ("time_utc\n2014-01-21T00:32:00Z\n", "no observable"),
    ("time_utc,aop_deg,aop_err_deg\n", "no rows"),
])
def test_a_bad_light_curve_file_is_one_line_naming_the_place(tmp_path, text, words):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ParameterError, match=words):
        read_light_curve(path)


@pytest.fixture(scope="module")
def daytime_pass(tmp_path_factory):
    """The four-face aluminium box over the daytime pass, every 20 seconds, yawed 20 deg."""
    path = target_file(tmp_path_factory.mktemp("target"), "attitude = {yaw_deg = 20.0, pitch_deg = -10.0, roll_deg = 5.0}")
    faces = turned(faces_from_toml(path), Attitude(20.0, -10.0, 5.0))
    return path, pass_geometry(read_tle(TLE), (43.1333, 125.5333, 200.0), START, END, 20.0, faces)


def _residuals(geometry, camera, exposures: int, draws: int, rng) -> dict:
    """{flux, dolp, aop: (measured - true) / stated error} over ``draws`` noise draws of the pass; DoLP and AoP at
    the times whose polarized signal is 20 errors or more (the delta method's range), chosen once from the truth."""
    light = target_light(geometry, None, {}, (1.5, 1.8))
    truth = light.stokes_w_m2[:3, 0, :] * light.photons_per_joule
    keep = (geometry.elevation_deg > 0) & geometry.sunlit & (truth[0] > 0)
    s0, dolp = truth[0][keep], np.hypot(truth[1], truth[2])[keep] / truth[0][keep]
    aop = 0.5 * np.degrees(np.arctan2(truth[2], truth[1]))[keep]
    z = {"flux": [], "dolp": [], "aop": []}
    bright = dolp / synthesized_light_curve(geometry, camera, rng, exposures=exposures).dolp_err > 20
    for _ in range(draws):
        c = synthesized_light_curve(geometry, camera, rng, exposures=exposures)
        z["flux"].append((c.flux - s0) / c.flux_err)
        z["dolp"].append(((c.dolp - dolp) / c.dolp_err)[bright])
        wrapped = (c.aop_deg - aop + 90.0) % 180.0 - 90.0
        z["aop"].append((wrapped / c.aop_err_deg)[bright])
    return {name: np.concatenate(values) for name, values in z.items()}


def _standard_normal(v: np.ndarray, name: str) -> None:
    """Mean 0 and SD 1 within 5 Monte-Carlo SEs, from at least 1,000 values."""
    n = v.size
    assert n >= 1000, (name, n)
    assert abs(v.mean()) < 5 / np.sqrt(n), (name, v.mean(), n)
    assert abs(v.std() - 1) < 5 / np.sqrt(2 * n), (name, v.std(), n)


def test_synthetic_errors_are_the_scatter_of_the_draws(daytime_pass):
    """Over 400 noise draws of the pass, (measured - true) / stated error has mean 0 and SD 1 for the flux, and for
    DoLP and AoP where the polarized signal is 20 errors or more (the delta method's range); the same residuals over
    errors half as large (the negative control) are far from it. Tolerances: 5 Monte-Carlo SEs."""
    _, geometry = daytime_pass
    z = _residuals(geometry, replace(Camera(), exposure_s=1e-3), 50, 400, np.random.default_rng(11))
    for name, v in z.items():
        _standard_normal(v, name)
        assert abs(2 * v.std() - 1) > 0.5  # errors half as large: the SD of the residuals over them is 2


def test_a_bright_targets_errors_are_scintillation_and_the_polarimeters_calibration(daytime_pass):
    """With 200 one-second frames per time the photon noise is far below the floors: the flux's stated error is
    scintillation's and the DoLP's the camera's calibration accuracy (0.005), and (measured - true) / stated error is N(0, 1)
    over 300 draws (5 Monte-Carlo SEs). Control: a camera without the floors states errors several times smaller
    than that scatter. Scintillation itself agrees with Young's original formula (0.09 D_cm^-2/3 X^1.75 (2t)^-1/2 at
    sea level) to 10 % at the zenith with C_Y = 1."""
    from spacepol.skylight.scintillation import scintillation_relative

    young = 0.09 * 180.0 ** (-2 / 3) / np.sqrt(2 * 200.0)
    assert abs(scintillation_relative(1.8, 90.0, 0.0, 200.0, correction=1.0) / young - 1) < 0.1
    _, geometry = daytime_pass
    camera = Camera()  # one-second exposures, calibrated to 0.005
    z = _residuals(geometry, camera, 200, 300, np.random.default_rng(12))
    for name, v in z.items():
        _standard_normal(v, name)
    curve = synthesized_light_curve(geometry, camera, np.random.default_rng(13), exposures=200)
    bare = synthesized_light_curve(geometry, replace(camera, polarimetric_accuracy=0.0, scintillation_correction=0.0),
                                   np.random.default_rng(13), exposures=200)
    assert np.all(curve.dolp_err >= 0.005) and np.median(curve.dolp_err) < 0.0051  # the floor, photon noise under it
    assert np.median(curve.flux_err / bare.flux_err) > 3 and np.median(curve.dolp_err / bare.dolp_err) > 3


def test_synth_pass_writes_the_curve_and_bad_input_is_one_line_with_nothing_left(tmp_path, daytime_pass):
    target, _ = daytime_pass
    out = tmp_path / "pass.csv"
    run = run_cli("synth-pass", "--tle", TLE, "--site", SITE, "--start", START, "--end", END, "--step", "30",
                  "--target", target, "--seed", "3", "--out", out)
    assert run.returncode == 0, run.stderr
    curve = read_light_curve(out)
    assert curve.observables == ["flux", "dolp", "aop_deg"] and len(curve) >= 10
    again = spacepol.synth_pass(TLE, SITE, START, END, target=target, step_s=30, seed=3)
    np.testing.assert_allclose(again.flux, curve.flux, rtol=1e-12)  # the same seed, the same curve
    (tmp_path / "bare").mkdir()
    bare = target_file(tmp_path / "bare", bare=True)
    cases = [
        ({"--target": bare}, "face nadir has no material"),
        ({"--start": "2014-01-21T03:32:00Z", "--end": "2014-01-21T03:41:00Z"}, "below the horizon, in Earth's shadow"),
        ({"--start": "2014-03-21T00:32:00Z", "--end": "2014-03-21T00:41:00Z"}, "days from the window"),
        ({"--site": "95,0"}, "--site"),
    ]
    for changed, words in cases:
        options = {"--target": target, "--site": SITE, "--start": START, "--end": END} | changed
        bad = tmp_path / "bad.csv"
        run = run_cli("synth-pass", "--tle", TLE, *(a for item in options.items() for a in item), "--out", bad)
        assert run.returncode == 2 and words in run.stderr and len(run.stderr.strip().splitlines()) == 1, run.stderr
        assert not bad.exists()


def test_a_written_target_reads_back_as_its_faces_and_attitude(tmp_path):
    """write_target then read_target gives the same faces (materials included) and attitude; without an attitude
    the file has none; the hand-written box of this module reads as the same faces the writer is given."""
    from spacepol.orbit import read_target, write_target

    faces = [Face("nadir", 3.0, "nadir", (0.0, 0.0, 1.0), {"model": "specular+smith", "n": 1.37, "k": 7.6}),
             Face("panel", 4.0, "sun"), Face("star", 0.5, "inertial", (0.6, 0.0, 0.8))]
    read, attitude = read_target(write_target(tmp_path / "t.toml", faces, Attitude(12.5, -3.0, 0.25)))
    assert read == faces and attitude == Attitude(12.5, -3.0, 0.25)
    assert read_target(write_target(tmp_path / "u.toml", faces))[1] is None
    hand = faces_from_toml(target_file(tmp_path))
    assert faces_from_toml(write_target(tmp_path / "v.toml", hand)) == hand
