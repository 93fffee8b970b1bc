"""Real micro-polarizer frames: the project's demosaicking and Stokes maps against polanalyser's
on the raw IMX250MZR mosaics in data/dofp/, and the four labelled filters' angles of polarization about 45 deg apart
in their order, one sense of rotation."""

import numpy as np
import polanalyser as pa
import pytest

from spacepol.camera import IMX250MZR, Layout, demosaic, linear_stokes, read_raw_frame, stokes_maps
from spacepol.camera.mosaic import aop_deg, dolp
from spacepol.errors import SpacepolError
from spacepol.paths import bundled

ANGLES = (0.0, 45.0, 90.0, 135.0)
# the four filters of polarizer_IMX250MZR.png, labelled 0, 45, 90 and 135 deg from left to right: centres (x, y) in
# raw pixels, read off the S0 image; discs of 120 px stay inside their rims (radius about 200 px)
FILTERS = {0: (380, 1088), 45: (1000, 1092), 90: (1556, 1092), 135: (2108, 1104)}


@pytest.fixture(scope="module", params=["polarizer_IMX250MZR.png", "camera_IMX250MZR.png"])
def raw(request):
    return read_raw_frame(bundled("dofp", request.param))


def test_the_stokes_maps_equal_polanalysers_from_the_same_channels(raw):
    channels = pa.demosaicing(raw, pa.COLOR_PolarMono)  # [0, 45, 90, 135]
    theirs = pa.calcStokes(np.array(channels, float), np.radians(ANGLES))  # (H, W, 3)
    ours = linear_stokes(dict(zip(ANGLES, [c.astype(float) for c in channels])))
    scale = np.abs(theirs).max()
    assert np.abs(np.moveaxis(ours, 0, -1) - theirs).max() <= 1e-6 * scale
    lit = theirs[..., 0] > 1.0
    assert np.abs(dolp(ours)[lit] - pa.cvtStokesToDoLP(theirs)[lit]).max() < 1e-6
    aop_theirs = np.degrees(pa.cvtStokesToAoLP(theirs))
    diff = (aop_deg(ours) - aop_theirs + 90.0) % 180.0 - 90.0
    assert np.abs(diff[lit & (pa.cvtStokesToDoLP(theirs) > 0.01)]).max() < 1e-6


def test_the_demosaicking_is_polanalysers_up_to_its_8_bit_rounding(raw):
    """Bilinear interpolation of each analyser's samples: away from the edges (where OpenCV's border rule differs)
    the project's floats round to polanalyser's 8-bit values (|difference| <= 0.5). The control: the layout with the
    0 and 90 deg analysers swapped is far off."""
    ours = demosaic(raw)
    theirs = pa.demosaicing(raw, pa.COLOR_PolarMono)
    inner = (slice(4, -4), slice(4, -4))
    for k, angle in enumerate(ANGLES):
        assert np.abs(ours[angle][inner] - theirs[k][inner].astype(float)).max() <= 0.5 + 1e-9
    swapped = demosaic(raw, Layout("swapped", ((0.0, 45.0), (135.0, 90.0))))
    assert np.abs(swapped[0.0][inner] - theirs[0][inner].astype(float)).mean() > 2.0


def test_the_four_filters_angles_of_polarization_step_by_45_degrees_in_their_order():
    """The light through each hand-placed filter: its AoP (of the disc's mean Stokes vector) steps by 45 deg +- 8 deg
    from filter to filter in the labelled order, all steps in one sense, and each filter polarizes (DoLP > 0.2)."""
    maps = stokes_maps(bundled("dofp", "polarizer_IMX250MZR.png"))
    found = [maps.region(FILTERS[label], 120.0) for label in (0, 45, 90, 135)]
    assert all(f["dolp"] > 0.2 and f["pixels"] > 5000 for f in found), found
    steps = [(b["aop_deg"] - a["aop_deg"] + 90.0) % 180.0 - 90.0 for a, b in zip(found, found[1:])]
    assert all(abs(abs(s) - 45.0) < 8.0 for s in steps), steps
    assert len({np.sign(s) for s in steps}) == 1, steps
    # the control: the filters taken out of their labelled order do not step by 45 deg
    shuffled = [found[i] for i in (0, 2, 1, 3)]
    wrong = [(b["aop_deg"] - a["aop_deg"] + 90.0) % 180.0 - 90.0 for a, b in zip(shuffled, shuffled[1:])]
    assert not all(abs(abs(s) - 45.0) < 8.0 for s in wrong)


def test_a_frame_that_is_not_a_raw_mosaic_is_one_line(tmp_path):
    from PIL import Image

    colour = tmp_path / "colour.png"
    Image.fromarray(np.zeros((8, 8, 3), np.uint8)).save(colour)
    with pytest.raises(SpacepolError, match="one channel"):
        read_raw_frame(colour)
    odd = tmp_path / "odd.png"
    Image.fromarray(np.zeros((9, 8), np.uint8)).save(odd)
    with pytest.raises(SpacepolError, match="even number"):
        read_raw_frame(odd)
    with pytest.raises(SpacepolError, match="not an image"):
        read_raw_frame(tmp_path / "x.png") if (tmp_path / "x.png").write_text("no") else None
    assert IMX250MZR.offset(0.0) == (1, 1) and IMX250MZR.offset(90.0) == (0, 0)


def test_a_raw_frame_from_the_command_line_and_the_api(tmp_path, capsys):
    """``invert-mcmc frame RAW.png``: the maps' files, the API's maps equal ``stokes_maps`` of the file; a colour
    image or a missing file is one line, exit status 2, nothing written."""
    import json

    import spacepol
    from spacepol import cli
    from spacepol.camera.mosaic import stokes_maps

    raw = bundled("dofp", "polarizer_IMX250MZR.png")
    assert cli.main(["frame", str(raw), "--out", str(tmp_path / "frame")]) == 0
    content = json.loads((tmp_path / "frame" / "frame.json").read_text())
    arrays = np.load(tmp_path / "frame" / "stokes.npz")
    expected = stokes_maps(raw)
    assert content["shape"] == list(expected.stokes.shape[1:]) and np.array_equal(arrays["s1"], expected.stokes[1])
    assert (tmp_path / "frame" / "frame.png").stat().st_size > 0 and 0 < content["dolp"]["median"] < 1
    maps = spacepol.frame(raw, "bilinear")  # full resolution: twice the superpixels' on each side
    assert maps.stokes.shape[1:] == tuple(2 * n for n in expected.stokes.shape[1:])
    from PIL import Image

    Image.fromarray(np.zeros((8, 8, 3), np.uint8)).save(tmp_path / "colour.png")
    capsys.readouterr()
    for bad, words in ((tmp_path / "colour.png", "one channel"), (tmp_path / "missing.png", "not found")):
        rc = cli.main(["frame", str(bad), "--out", str(tmp_path / "bad")])
        err = capsys.readouterr().err.strip()
        assert rc == 2 and words in err and len(err.splitlines()) == 1 and not (tmp_path / "bad").exists(), err
