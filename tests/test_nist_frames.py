"""NIST's Mueller BRDF files hold each matrix in SCATMECH's x-y basis ("xyxy"); spacepol's model works in the s-p basis
("psps"). A file written from SCATMECH's own x-y matrices at PTFE's geometries, read by spacepol, must give
SCATMECH's s-p matrices: the independent implementation decides the conversion and its sign. Control: the x-y
matrices themselves differ from the s-p ones out of the plane of incidence (and agree in it)."""

import numpy as np
import pytest

from spacepol.io import read_measurements
from spacepol.io.measurements import InputFileError

pytest.importorskip("pySCATMECH")

HEADER = "lambda,thetai,phi,thetar,phir,f_r11," + ",".join(f"f_r{i}{j}/f_r11" for i in range(1, 5) for j in range(1, 5)
                                                        if (i, j) != (1, 1))


def _scatmech():
    from pySCATMECH.brdf import BRDF_Model

    # a rough dielectric with light scattered once beneath it: every Mueller element non-zero out of the plane
    return BRDF_Model("First_Diffuse_BRDF_Model", {
        "lambda": 0.633, "substrate": "(1.35,0)", "type": 0, "phase_function": "CodeWhitney_Phase_Function",
        "phase_function.phase_function": "Henyey_Greenstein_Phase_Function", "phase_function.phase_function.g": 0.3,
        "phase_function.plmax": 0.6, "phase_function.pcmax": 0.3, "phase_function.s": 0.2})


def _geometries(rng, size=60):
    """(theta_i, theta_r, phi_s) deg in NIST's ranges; phi_s = 0 the specular direction, a sixth in the plane."""
    ti, tr = rng.uniform(1, 75, size), rng.uniform(1, 80, size)
    phi = rng.uniform(-179, 180, size)
    phi[: size // 6] = rng.choice([0.0, 180.0], size // 6)
    return ti, tr, phi


def _file(tmp_path, model, ti, tr, phi, coords):
    rows = []
    for a, b, c in zip(ti, tr, phi):
        m = np.array(model.MuellerBRDF(np.radians(a), np.radians(b), np.radians(c), 0, coords))
        ratios = (m / m[0, 0]).ravel()[1:]
        rows.append(",".join(repr(float(x)) for x in [0.633, -a, 0.0, b, c, m[0, 0], *ratios]))
    path = tmp_path / f"{coords}.csv"
    path.write_text(HEADER + "\n" + "\n".join(rows) + "\n")
    return path


def test_a_file_of_xy_matrices_reads_as_scatmechs_sp_matrices(tmp_path):
    model = _scatmech()
    ti, tr, phi = _geometries(np.random.default_rng(0))
    data = read_measurements(_file(tmp_path, model, ti, tr, phi, "xyxy"))
    sp = np.stack([np.array(model.MuellerBRDF(np.radians(a), np.radians(b), np.radians(c), 0, "psps"))
                   for a, b, c in zip(ti, tr, phi)], axis=-1)
    np.testing.assert_allclose(data.mueller / data.mueller[0, 0], sp / sp[0, 0], atol=1e-12)
    np.testing.assert_allclose(data.brdf, sp[0, 0], rtol=1e-12)
    np.testing.assert_allclose(data.dphi % 360, (180.0 - phi) % 360, atol=1e-9)
    # control: the x-y matrices are not the s-p ones out of the plane, and are in it
    xy = np.stack([np.array(model.MuellerBRDF(np.radians(a), np.radians(b), np.radians(c), 0, "xyxy"))
                   for a, b, c in zip(ti, tr, phi)], axis=-1)
    off, plane = np.abs(np.sin(np.radians(phi))) > 0.2, np.sin(np.radians(phi)) == 0
    gap = np.abs(xy / xy[0, 0] - sp / sp[0, 0]).max(axis=(0, 1))
    assert gap[off].min() > 1e-3 and gap[plane].max() < 1e-12, (gap[off].min(), gap[plane].max())


def test_an_incidence_azimuth_other_than_zero_is_refused(tmp_path):
    """The conversion holds for incidence in the x-z plane (phi_i = 0, every row of NIST's file); another azimuth's
    x-y basis is not taken on trust."""
    path = tmp_path / "rotated.csv"
    path.write_text(HEADER + "\n" + ",".join(["0.633", "-30", "20", "40", "10", "0.3"] + ["0"] * 15) + "\n")
    with pytest.raises(InputFileError) as err:
        read_measurements(path)
    assert "line 2" in str(err.value) and "phi" in str(err.value) and "\n" not in str(err.value)
