"""Speed of the forward model: DOP of the `paper` model, 84 geometries x 4096 parameter sets.

Prints evaluations per second (median of repeats) for the vectorised model and for a
straightforward per-point Python loop of the same formulas (eqs 1-3, 7-8, 11, 14-19, 23 with
the ERRATA corrections), their ratio, and the largest difference between the two (they are
independent implementations, so this is a check too).

    python benchmarks/forward_speed.py
"""

from __future__ import annotations

import math
import statistics
import time

import numpy as np

from spacepol.physics import Model
from spacepol.physics.geometry import default_grid

N_SETS = 4096
LOOP_SETS = 48  # the Python loop is timed on a subset and reported per evaluation
REPEATS = 9


def loop_paper_dop(ti_deg, tr_deg, dphi_deg, n, k, sigma, ks, rho_d, sp=0.0136, sr=0.0136, up=9.0, vp=1.0):
    """One geometry, one parameter set, scalar Python (math module)."""
    ti, tr, dphi = math.radians(ti_deg), math.radians(tr_deg), math.radians(dphi_deg)
    cos2b = math.cos(ti) * math.cos(tr) + math.sin(ti) * math.sin(tr) * math.cos(dphi)  # eq 2
    cb = math.sqrt((1 + cos2b) / 2)
    sb2 = 1 - cb * cb
    ca = (math.cos(ti) + math.cos(tr)) / (2 * cb)  # eq 3
    ca = min(ca, 1.0)
    sa = math.sqrt(max(1 - ca * ca, 0.0))
    tan2a = (sa / ca) ** 2
    # eqs 14-19 (eq 15 corrected)
    d = n * n - k * k - sb2
    c = 4 * n * n * k * k + d * d
    a = math.sqrt((math.sqrt(c) + d) / 2)
    b2 = (math.sqrt(c) - d) / 2
    r_s = ((a - cb) ** 2 + b2) / ((a + cb) ** 2 + b2)
    st = sb2 / cb
    r_p = r_s * ((a - st) ** 2 + b2) / ((a + st) ** 2 + b2)
    # eqs 7-8 (corrected tan beta_p), limit at alpha = 0 along the plane of incidence
    horiz = 2 * sa * cb
    cos_phr = math.cos(dphi)
    if horiz < 1e-9:
        tan_ip, tan_rp, tan_bp = math.tan(ti), -math.tan(tr), abs(math.tan(ti))
    else:
        tan_ip = math.tan(ti) * (math.sin(ti) + math.sin(tr) * cos_phr) / horiz
        tan_rp = math.tan(tr) * (math.sin(tr) + math.sin(ti) * cos_phr) / horiz
        tan_bp = abs(math.cos(ti) - math.cos(tr)) / horiz
    wp = sp * (1 + up * sa / (sa + vp * ca))
    g = (1 + wp * abs(tan_ip * tan_rp) / (1 + sr * tan_bp)) / ((1 + wp * tan_ip**2) * (1 + wp * tan_rp**2))
    # eq 20 (sign corrected) and eq 23 (right-hand form)
    spec = ks / (8 * math.pi * sigma**2 * ca**4) * math.exp(-tan2a / (2 * sigma**2)) / (math.cos(ti) * math.cos(tr)) * g
    body = math.cos(tr) / math.pi * rho_d
    return spec * abs(r_s - r_p) / 2 / (spec * (r_s + r_p) / 2 + body)


def main():
    model = Model.from_string("paper")
    geometry = default_grid()
    rng = np.random.default_rng(2026)
    params = {p.name: p.prior.sample(rng, N_SETS) for p in model.free_parameters}
    params["sigma"] = np.maximum(params["sigma"], 0.05)
    evals = N_SETS * geometry.size

    model.evaluate(params, geometry, check=False)  # compile the kernels, fill the geometry cache
    times = []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        dop = model.evaluate(params, geometry, check=False).dop
        times.append(time.perf_counter() - t0)
    vector_rate = evals / statistics.median(times)

    loop_times, worst = [], 0.0
    for _ in range(3):
        t0 = time.perf_counter()
        out = np.empty((LOOP_SETS, geometry.size))
        for p in range(LOOP_SETS):
            args = [params[name][p] for name in ("n", "k", "sigma", "ks", "rho_d")]
            for j in range(geometry.size):
                out[p, j] = loop_paper_dop(geometry.theta_i[j], geometry.theta_r[j], geometry.dphi[j], *args)
        loop_times.append(time.perf_counter() - t0)
        worst = max(worst, float(np.max(np.abs(out - dop[:LOOP_SETS]))))
    loop_rate = LOOP_SETS * geometry.size / statistics.median(loop_times)

    print(f"paper model DOP, {geometry.size} geometries x {N_SETS} parameter sets ({evals} evaluations)")
    print(f"  vectorised : {vector_rate / 1e6:8.1f} million evaluations/s  (median of {REPEATS}, "
          f"{statistics.median(times) * 1e3:.2f} ms per call)")
    print(f"  python loop: {loop_rate / 1e6:8.3f} million evaluations/s  (median of 3, {LOOP_SETS} sets)")
    print(f"  ratio      : {vector_rate / loop_rate:8.0f} x")
    print(f"  max |DOP difference| between the two: {worst:.2e}")


if __name__ == "__main__":
    main()
