"""Speed of `volume` and `phase_matrix` (first-order volume scattering under the interface), in one process, against
NIST SCATMECH's First_Diffuse_BRDF_Model (pySCATMECH, C++ called once per geometry from Python: the independent
implementation the tests compare with) and against `subsurface`, the other lobe under the same interface.

Cases: the full Mueller matrix (and the Stokes vector alone, for DOP and BRDF data) of `specular+volume`, `specular+phase_matrix` (one draw from its prior) and
`specular+subsurface` for 64 parameter sets x 600 geometries
(random over the hemisphere, a third in the plane), and SCATMECH's matrix at one parameter set over the same
geometries. Evaluations per second (sets x geometries), medians of repeats, the load average, and the largest
difference from SCATMECH (a check, not only a timing).

    python benchmarks/volume_speed.py
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

SETS = 64
CASE = {"n": 1.35, "k": 0.0, "g": 0.4, "pl": 0.8, "pc": 0.3, "s": 0.0, "la": -1.0}


def _median_seconds(call, repeats: int) -> float:
    call()  # compiled and warm
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    from spacepol import configure_process

    configure_process()  # the settings the command line makes
    from pySCATMECH.brdf import BRDF_Model

    from spacepol.physics import Geometry, Model
    from test_volume import _albedo, _corpus

    ti, tr, ps = _corpus()
    geometry = Geometry(ti, tr, 180.0 - ps)
    c = CASE
    values = {"n": c["n"], "k": c["k"], "sigma": 0.2, "ks": 0.0, "w_vol": _albedo(c["la"], c["k"]), "g_vol": c["g"],
              "pl_vol": c["pl"], "pc_vol": c["pc"], "s_vol": c["s"], "dl_vol": 0.0, "dc_vol": 0.0, "rho_s": 0.5}
    from spacepol.physics.effects.phase_matrix import PhaseMatrix

    rng = np.random.default_rng(0)
    phase = {p.name: rng.uniform(*p.prior.bounds) for p in PhaseMatrix.parameters}
    values.update(phase)
    batch = {k: np.full(SETS, v) for k, v in values.items()}
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}; {SETS} sets x {geometry.size} geometries")
    rates = {}
    for spec in ("specular+volume", "specular+phase_matrix", "specular+subsurface"):
        model = Model.from_string(spec)
        own = {p.name for p in model.parameters}
        params = {k: v for k, v in batch.items() if k in own}
        seconds = _median_seconds(lambda: model.evaluate(params, geometry, mueller=True), 20)
        rates[spec] = SETS * geometry.size / seconds
        print(f"  {spec:22s} full Mueller {seconds * 1e3:8.2f} ms per call, {rates[spec] / 1e6:7.2f} M evaluations/s")
        seconds = _median_seconds(lambda: model.evaluate(params, geometry), 20)  # what DOP and BRDF data need
        print(f"  {spec:22s} Stokes only  {seconds * 1e3:8.2f} ms per call, "
              f"{SETS * geometry.size / seconds / 1e6:7.2f} M evaluations/s")
    peer = BRDF_Model("First_Diffuse_BRDF_Model", {
        "lambda": 0.633, "substrate": f"({c['n']},{c['k']})", "type": 0, "phase_function": "CodeWhitney_Phase_Function",
        "phase_function.phase_function": "Henyey_Greenstein_Phase_Function", "phase_function.phase_function.g": c["g"],
        "phase_function.plmax": c["pl"], "phase_function.pcmax": c["pc"], "phase_function.s": c["s"],
        "phase_function.log_absorption": c["la"], "phase_function.log_scattering": 0})
    angles = np.radians(np.column_stack([ti, tr, ps]))

    def scatmech():
        return np.stack([np.array(peer.MuellerBRDF(*a)) for a in angles], axis=-1)

    seconds = _median_seconds(scatmech, 3)
    rate = geometry.size / seconds
    volume = Model.from_string("specular+volume")
    ours = volume.evaluate({p.name: values[p.name] for p in volume.parameters}, geometry, mueller=True).mueller
    theirs = scatmech()
    print(f"  SCATMECH (pySCATMECH, one geometry per call) {seconds * 1e3:8.2f} ms for {geometry.size}, {rate / 1e6:7.3f} M evaluations/s")
    print(f"  volume / SCATMECH {rates['specular+volume'] / rate:8.0f}x; volume / subsurface "
          f"{rates['specular+volume'] / rates['specular+subsurface']:.2f}x; phase_matrix / volume "
          f"{rates['specular+phase_matrix'] / rates['specular+volume']:.2f}x")
    print(f"  largest difference from SCATMECH: M11 {np.max(np.abs(ours[0, 0] / theirs[0, 0] - 1)):.1e} relative, "
          f"m_ij {np.max(np.abs(ours / ours[0, 0] - theirs / theirs[0, 0])):.1e}")


if __name__ == "__main__":
    main()
