"""Speed of the forward model, in one process: DOP and full Mueller matrix of the `paper` model.

Cases (evaluations = parameter sets x geometries):
  * DOP, 4,096 sets x 84 in-plane geometries (the bundled grid);
  * full Mueller matrix, 4,096 x 84 and 64 x 100,000 (random hemisphere geometries);
  * the compiled log-likelihood on those (what an inversion calls: no Mueller array is written out);
  * DOP, 10^6 x 84, when JAX sees a GPU.
The DOP is timed as ``model.dop`` (a program with the DOP as its only output) and as ``model.evaluate`` (the
Stokes vector, 4 x sets x geometries, written out as well); the ratios are model.dop's.
Baselines, each measured here and printed as a ratio:
  * a straightforward numpy implementation of the same equations (eqs 1-3, 7-8, 11, 14-21, 23 with the
    ERRATA corrections), vectorised over (sets, geometries); measured FIRST, before spacepol is imported,
    i.e. with glibc's default heap as any numpy program runs, and again after the import, with the heap
    spacepol keeps (``spacepol/_runtime.py``: MB-sized temporaries no longer mmap'ed per call). With the
    default heap numpy's speed depends on whether the caller still holds the previous call's result (glibc
    then keeps the top of its heap; measured 60 against 19 M/s): both are timed, "result dropped" is what a
    sampler's loop does and what the issue measured (15-21 M/s);
  * a per-point Python loop (math module) on a subset.
The numpy and loop versions are independent implementations, so their largest differences from spacepol
are printed too (a check, not only a timing). Medians of repeats; the load average is printed.

    python benchmarks/forward_speed.py [--quick]
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time

import numpy as np

N_SETS = 4096
LOOP_SETS = 48
KEPT = "numpy, spacepol's heap"
DOP_ALONE = "spacepol (JAX) model.dop"
EVALUATE = "spacepol (JAX) evaluate"
DROPPED = "numpy, default heap, dropped"
WARM_S = 0.03  # warm-up of each contender in the interleaved rounds (seconds)


def timed(fn, repeats, keep=True, warm_s=0.0):
    """(median seconds, last result) over ``repeats`` calls after warm-up calls (one, or as many as fill
    ``warm_s`` seconds); ``keep=False`` lets each result go before the next call (as a loop that uses and
    discards it)."""
    out = fn()
    t_end = time.perf_counter() + warm_s
    while time.perf_counter() < t_end:
        out = fn()
    times = []
    for _ in range(repeats):
        if not keep:
            out = None
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def in_plane_grid():
    theta_i = np.repeat([20.0, 35.0, 50.0, 65.0], 21)
    theta_r = np.tile(np.arange(0.0, 81.0, 4.0), 4)
    return theta_i, theta_r, np.full(theta_i.shape, 180.0)


def draw_sets(rng, n_sets):
    """Parameter sets over the `paper` model's default priors (sigma >= 0.05 to keep the lobe resolvable)."""
    return {"n": rng.uniform(0.1, 5.0, n_sets), "k": rng.uniform(0.0, 20.0, n_sets), "sigma": rng.uniform(0.05, 0.8, n_sets),
            "ks": rng.uniform(0.0, 1.0, n_sets), "rho_d": rng.uniform(0.0, 1.0, n_sets)}


def numpy_paper_dop(ti_deg, tr_deg, dphi_deg, n, k, sigma, ks, rho_d, sp=0.0136, sr=0.0136, up=9.0, vp=1.0):
    """The paper's DOP, straightforward numpy over (sets, geometries): sets as (P, 1), geometries (N,)."""
    ti, tr, dphi = np.radians(ti_deg), np.radians(tr_deg), np.radians(dphi_deg)
    cos2b = np.cos(ti) * np.cos(tr) + np.sin(ti) * np.sin(tr) * np.cos(dphi)  # eq 2
    cb = np.sqrt((1 + cos2b) / 2)
    sb2 = 1 - cb * cb
    ca = np.minimum((np.cos(ti) + np.cos(tr)) / (2 * cb), 1.0)  # eq 3
    sa = np.sqrt(np.maximum(1 - ca * ca, 0.0))
    tan2a = (sa / ca) ** 2
    d = n * n - k * k - sb2  # eqs 14-19, eq 15 corrected
    c = 4 * n * n * k * k + d * d
    a = np.sqrt((np.sqrt(c) + d) / 2)
    b2 = (np.sqrt(c) - d) / 2
    r_s = ((a - cb) ** 2 + b2) / ((a + cb) ** 2 + b2)
    st = sb2 / cb
    r_p = r_s * ((a - st) ** 2 + b2) / ((a + st) ** 2 + b2)
    horiz = 2 * sa * cb  # eqs 7-8, tan(beta_p) corrected; alpha = 0 limit along the plane of incidence
    peak = horiz < 1e-9
    safe = np.where(peak, 1.0, horiz)
    tan_ip = np.where(peak, np.tan(ti), np.tan(ti) * (np.sin(ti) + np.sin(tr) * np.cos(dphi)) / safe)
    tan_rp = np.where(peak, -np.tan(tr), np.tan(tr) * (np.sin(tr) + np.sin(ti) * np.cos(dphi)) / safe)
    tan_bp = np.where(peak, np.abs(np.tan(ti)), np.abs(np.cos(ti) - np.cos(tr)) / safe)
    wp = sp * (1 + up * sa / (sa + vp * ca))
    g = (1 + wp * np.abs(tan_ip * tan_rp) / (1 + sr * tan_bp)) / ((1 + wp * tan_ip**2) * (1 + wp * tan_rp**2))
    spec = ks / (8 * np.pi * sigma**2 * ca**4) * np.exp(-tan2a / (2 * sigma**2)) / (np.cos(ti) * np.cos(tr)) * g  # eq 20
    body = np.cos(tr) / np.pi * rho_d  # eq 11
    return spec * np.abs(r_s - r_p) / 2 / (spec * (r_s + r_p) / 2 + body)  # eq 23



def loop_paper_dop(ti_deg, tr_deg, dphi_deg, n, k, sigma, ks, rho_d, sp=0.0136, sr=0.0136, up=9.0, vp=1.0):
    """One geometry, one parameter set, scalar Python (math module): the same equations."""
    ti, tr, dphi = math.radians(ti_deg), math.radians(tr_deg), math.radians(dphi_deg)
    cos2b = math.cos(ti) * math.cos(tr) + math.sin(ti) * math.sin(tr) * math.cos(dphi)
    cb = math.sqrt((1 + cos2b) / 2)
    sb2 = 1 - cb * cb
    ca = min((math.cos(ti) + math.cos(tr)) / (2 * cb), 1.0)
    sa = math.sqrt(max(1 - ca * ca, 0.0))
    tan2a = (sa / ca) ** 2
    d = n * n - k * k - sb2
    c = 4 * n * n * k * k + d * d
    a = math.sqrt((math.sqrt(c) + d) / 2)
    b2 = (math.sqrt(c) - d) / 2
    r_s = ((a - cb) ** 2 + b2) / ((a + cb) ** 2 + b2)
    st = sb2 / cb
    r_p = r_s * ((a - st) ** 2 + b2) / ((a + st) ** 2 + b2)
    horiz = 2 * sa * cb
    if horiz < 1e-9:
        tan_ip, tan_rp, tan_bp = math.tan(ti), -math.tan(tr), abs(math.tan(ti))
    else:
        tan_ip = math.tan(ti) * (math.sin(ti) + math.sin(tr) * math.cos(dphi)) / horiz
        tan_rp = math.tan(tr) * (math.sin(tr) + math.sin(ti) * math.cos(dphi)) / horiz
        tan_bp = abs(math.cos(ti) - math.cos(tr)) / horiz
    wp = sp * (1 + up * sa / (sa + vp * ca))
    g = (1 + wp * abs(tan_ip * tan_rp) / (1 + sr * tan_bp)) / ((1 + wp * tan_ip**2) * (1 + wp * tan_rp**2))
    spec = ks / (8 * math.pi * sigma**2 * ca**4) * math.exp(-tan2a / (2 * sigma**2)) / (math.cos(ti) * math.cos(tr)) * g
    body = math.cos(tr) / math.pi * rho_d
    return spec * abs(r_s - r_p) / 2 / (spec * (r_s + r_p) / 2 + body)


def numpy_paper_mueller(geo, g, n, k, sigma, ks, rho_d):
    """The paper's Mueller matrix, straightforward numpy: eq 21's M = ks D G / (4 cos ti cos tr) L(eta_r) M_F L(eta_i)
    with explicit 4 x 4 products (einsum), plus eq 11's body term; geometry terms from spacepol's Geometry and
    the paper's shadowing ``g`` (N,), parameters (P, 1). Returns (4, 4, P, N)."""
    big_n = n + 1j * k
    root = np.sqrt(big_n**2 - geo.sin2_beta)
    r_s = (geo.cos_beta - root) / (geo.cos_beta + root)
    r_p = (big_n**2 * geo.cos_beta - root) / (big_n**2 * geo.cos_beta + root)
    rs2, rp2, cross = np.abs(r_s) ** 2, np.abs(r_p) ** 2, r_s * np.conj(r_p)
    m_f = np.zeros(r_s.shape + (4, 4))
    m_f[..., 0, 0] = m_f[..., 1, 1] = (rs2 + rp2) / 2
    m_f[..., 0, 1] = m_f[..., 1, 0] = (rs2 - rp2) / 2
    m_f[..., 2, 2] = m_f[..., 3, 3] = cross.real
    m_f[..., 2, 3], m_f[..., 3, 2] = cross.imag, -cross.imag

    def rotation(eta):
        out = np.zeros(eta.shape + (4, 4))
        out[..., 0, 0] = out[..., 3, 3] = 1.0
        out[..., 1, 1] = out[..., 2, 2] = np.cos(2 * eta)
        out[..., 1, 2], out[..., 2, 1] = np.sin(2 * eta), -np.sin(2 * eta)
        return out

    dist = np.exp(-geo.tan2_alpha / (2 * sigma**2)) / (2 * np.pi * sigma**2 * geo.cos_alpha**4)  # eq 1
    scalar = ks * dist * g / (4 * geo.cos_ti * geo.cos_tr)
    m = scalar[..., None, None] * np.einsum("nij,pnjk,nkl->pnil", rotation(geo.eta_r), m_f, rotation(geo.eta_i))
    m[..., 0, 0] += rho_d * geo.cos_tr / np.pi
    return np.moveaxis(m, (-2, -1), (0, 1))


def back_to_back(model, sets, geometry, calls=200):
    """``model.dop`` called back to back: this VM's calls fall into two groups, both vCPUs running and the
    single-thread time (XLA splits the loop in two fixed halves); printed so a reader sees which one a run had."""
    times = []
    for _ in range(calls):
        t0 = time.perf_counter()
        model.dop(sets, geometry, check=False)
        times.append(time.perf_counter() - t0)
    times = np.array(times) * 1e6
    fast = np.percentile(times, 10)
    evals = N_SETS * geometry.size
    print(f"  model.dop, {calls} calls back to back: p10 {fast:.0f} us ({evals / fast:.0f} M/s), median "
          f"{np.median(times):.0f} us, p90 {np.percentile(times, 90):.0f} us; {np.mean(times > 1.5 * fast):.0%} of the calls "
          f"took over 1.5x the p10 (one vCPU lagging)")


def up_to_scale_versus_divided(model, sets, geometry, repeats):
    """The DOP program as ``model.dop`` compiles it (the total up to a positive factor: no Fresnel division, the
    Stokes rows kept apart, ``compiled.evaluate_values``) against the same hooks with every lobe divided out, both
    compiled here without the call's conversions, in interleaved rounds."""
    import jax

    from spacepol.physics import Geometry
    from spacepol.physics.compiled import batch_of, evaluate_values

    values, _ = model._resolve(sets, False)
    traced = {k: v for k, v in values.items() if k in sets}  # N_SETS is a bucket size: nothing to pad
    fixed = {k: v for k, v in values.items() if k not in sets}
    terms = geometry.device_terms()

    def program(up_to_scale):
        def dop(values, terms):
            return evaluate_values(model.effects, {**fixed, **values}, batch_of(values),
                                   Geometry.from_terms(terms, geometry.all_visible), False, up_to_scale)[1]
        compiled = jax.jit(dop)
        return lambda: compiled(traced, terms).block_until_ready()

    variants = {"divided": program(False), "up to scale": program(True)}
    rounds = {name: [] for name in variants}
    for _ in range(repeats):
        for name, run in variants.items():
            rounds[name].append(timed(run, 5)[0])
    evals = N_SETS * geometry.size
    rates = {name: evals / statistics.median(t) / 1e6 for name, t in rounds.items()}
    ratio = statistics.median(a / b for a, b in zip(rounds["divided"], rounds["up to scale"]))
    print(f"  DOP program alone, {repeats} interleaved rounds: every lobe divided {rates['divided']:.0f} M/s, up to a "
          f"positive scale (model.dop's) {rates['up to scale']:.0f} M/s; per round {ratio:.2f}x")


def main():
    from spacepol import configure_process

    configure_process()  # the settings the command line makes
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="fewer repeats, no 64 x 100,000 case")
    args = parser.parse_args()
    repeats = 3 if args.quick else 7
    rng = np.random.default_rng(2026)
    sets = draw_sets(rng, N_SETS)
    columns = {k: v[:, None] for k, v in sets.items()}
    ti, tr, dphi = in_plane_grid()
    evals = N_SETS * ti.size
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")

    # 1. numpy baseline before spacepol changes the process (glibc's default heap)
    t_np_dropped, _ = timed(lambda: numpy_paper_dop(ti, tr, dphi, *columns.values()), repeats, keep=False)
    t_np_default, dop_np = timed(lambda: numpy_paper_dop(ti, tr, dphi, *columns.values()), repeats)

    import jax  # noqa: E402  (after the baseline on purpose)

    from spacepol.infer.likelihood import Likelihood
    from spacepol.io.measurements import Dataset
    from spacepol.physics import Geometry, Model
    from spacepol.physics.shadowing import PAPER_CONSTANTS, paper_shadowing

    model = Model.from_string("paper")
    geometry = Geometry(ti, tr, dphi)
    t_first = time.perf_counter()
    pred = model.evaluate(sets, geometry, check=False)
    compile_s = time.perf_counter() - t_first
    data = Dataset(ti, tr, dphi)
    data.dop, data.dop_err = pred.dop[0], np.full(ti.size, 0.01)
    dop_likelihood = Likelihood(data, model)
    # rounds of (numpy, spacepol, likelihood) one after the other: the machine's speed drifts by 2x over
    # minutes (shared cores), so each round's ratio compares runs that saw the same load
    rounds = {KEPT: [], DOP_ALONE: [], EVALUATE: [], "spacepol likelihood (DOP)": []}
    # each contender warmed up for WARM_S first: this VM's second vCPU, idle while numpy runs on one core,
    # runs the next two-thread calls about half as fast for some tens of ms (measured: 1 warm-up call 9.0x,
    # 40 calls 10.0x, medians of 10 rounds); a sampler's or a batch's calls come back to back
    cold = []
    for _ in range(repeats):
        rounds[KEPT].append(timed(lambda: numpy_paper_dop(ti, tr, dphi, *columns.values()), 3, warm_s=WARM_S)[0])
        cold.append(timed(lambda: model.dop(sets, geometry, check=False), 3)[0])
        t, dop_alone = timed(lambda: model.dop(sets, geometry, check=False), 3, warm_s=WARM_S)
        rounds[DOP_ALONE].append(t)
        t, pred = timed(lambda: model.evaluate(sets, geometry, check=False), 3, warm_s=WARM_S)
        rounds[EVALUATE].append(t)
        rounds["spacepol likelihood (DOP)"].append(timed(lambda: dop_likelihood.total(sets), 3, warm_s=WARM_S)[0])
    t_np_kept, t_alone, t_jax, t_lik = (statistics.median(v) for v in rounds.values())
    round_ratio = statistics.median(a / b for a, b in zip(rounds[KEPT], rounds[DOP_ALONE]))

    t0 = time.perf_counter()
    loop = np.array([[loop_paper_dop(ti[j], tr[j], dphi[j], *(sets[name][p] for name in sets)) for j in range(ti.size)]
                     for p in range(LOOP_SETS)])
    loop_rate = loop.size / (time.perf_counter() - t0)

    rate = {DROPPED: evals / t_np_dropped, "numpy, default heap": evals / t_np_default, KEPT: evals / t_np_kept,
            DOP_ALONE: evals / t_alone, EVALUATE: evals / t_jax, "spacepol likelihood (DOP)": evals / t_lik}
    print(f"\nDOP of `paper`, {N_SETS} sets x {ti.size} geometries ({evals:,} evaluations), medians of {repeats} "
          f"(numpy's default heap) or of {repeats} interleaved rounds of 3 after {WARM_S * 1e3:.0f} ms of warm-up (the rest):")
    for name, r in rate.items():
        print(f"  {name:28s} {r / 1e6:8.1f} M evaluations/s")
    print(f"  {'per-point Python loop':28s} {loop_rate / 1e6:8.3f} M evaluations/s ({LOOP_SETS} sets)")
    best_numpy = max(rate[DROPPED], rate["numpy, default heap"], rate[KEPT])
    print(f"  ratio spacepol (model.dop) / numpy: {rate[DOP_ALONE] / rate[DROPPED]:.1f}x (default heap, result dropped), "
          f"{rate[DOP_ALONE] / best_numpy:.1f}x (numpy's fastest of the three); / loop: "
          f"{rate[DOP_ALONE] / loop_rate:.0f}x; evaluate (Stokes vector too) / fastest numpy: {rate[EVALUATE] / best_numpy:.1f}x; "
          f"likelihood / fastest numpy: {rate['spacepol likelihood (DOP)'] / best_numpy:.1f}x")
    print(f"  per round, model.dop / numpy with spacepol's heap: median {round_ratio:.1f}x "
          f"(rounds {', '.join(f'{a / b:.1f}' for a, b in zip(rounds[KEPT], rounds[DOP_ALONE]))}); each warmed up "
          f"{WARM_S * 1e3:.0f} ms; model.dop right after numpy, one warm-up call: median "
          f"{statistics.median(a / b for a, b in zip(rounds[KEPT], cold)):.1f}x")
    print(f"  first call (compilation included): {compile_s:.2f} s")
    print(f"  max |DOP difference| spacepol vs numpy: {np.max(np.abs(pred.dop - dop_np)):.1e}, vs loop: "
          f"{np.max(np.abs(pred.dop[:LOOP_SETS] - loop)):.1e}; model.dop vs evaluate's: {np.max(np.abs(dop_alone - pred.dop)):.1e}")

    back_to_back(model, sets, geometry)
    up_to_scale_versus_divided(model, sets, geometry, repeats)

    cases = [(N_SETS, 84)] + ([] if args.quick else [(64, 100_000)])
    for n_sets, n_geo in cases:
        sub = {k: v[:n_sets] for k, v in sets.items()}
        g_ti, g_tr, g_dphi = rng.uniform(0, 85, n_geo), rng.uniform(0, 85, n_geo), rng.uniform(-180, 180, n_geo)
        geo = Geometry(g_ti, g_tr, g_dphi)
        g = paper_shadowing(geo, *PAPER_CONSTANTS.values())
        g = np.asarray(g)
        n_evals = n_sets * n_geo
        reps = max(1, repeats // (3 if n_geo > 1000 else 1))  # numpy's 819 MB case takes 7 s a call
        t_np, m_np = timed(lambda: numpy_paper_mueller(geo, g, *(v[:, None] for v in sub.values())), reps)
        t_first = time.perf_counter()
        model.evaluate(sub, geo, mueller=True, check=False)
        first = time.perf_counter() - t_first
        t_m, m_jax = timed(lambda: model.evaluate(sub, geo, mueller=True, check=False).mueller, repeats)
        data = Dataset(g_ti, g_tr, g_dphi)
        data.mueller = m_jax[:, :, 0]
        data.brdf = m_jax[0, 0, 0]
        mueller_likelihood = Likelihood(data, model)
        noise = {"sigma_m_pol": 0.01, "sigma_m_lin": 0.01, "sigma_m_circ": 0.01, "sigma_brdf_rel": 0.05}
        t_ml, _ = timed(lambda: mueller_likelihood.total({**sub, **noise}), repeats)
        scale = np.max(np.abs(m_np[0, 0]))
        print(f"\nfull Mueller matrix of `paper`, {n_sets} sets x {n_geo:,} geometries ({n_evals:,} evaluations of 16 elements), "
              f"median of {reps} (numpy) or {repeats} (spacepol), each caller keeping its previous result:")
        print(f"  numpy (spacepol's heap)        {n_evals / t_np / 1e6:8.1f} M evaluations/s")
        print(f"  spacepol (JAX) evaluate        {n_evals / t_m / 1e6:8.1f} M evaluations/s  ({n_evals / t_m / (n_evals / t_np):.1f}x numpy; "
              f"first call {first:.2f} s)")
        print(f"  spacepol likelihood (15 m_ij + BRDF) {n_evals / t_ml / 1e6:8.1f} M evaluations/s  "
              f"({n_evals / t_ml / (n_evals / t_np):.1f}x numpy's forward model alone)")
        print(f"  max |M difference| spacepol vs numpy: {np.max(np.abs(m_jax - m_np)) / scale:.1e} of the largest M11")
        del m_np, m_jax

    gpus = [d for d in jax.devices() if d.platform == "gpu"]
    if gpus:
        big = draw_sets(rng, 1_000_000)
        t_gpu, _ = timed(lambda: model.dop(big, geometry, check=False), 3)
        print(f"\nGPU {gpus[0].device_kind}: DOP of `paper`, 10^6 sets x 84: {1e6 * 84 / t_gpu / 1e9:.1f} G evaluations/s "
              f"(model.dop, numpy arrays back on the host)")
        t_gpu_lik, _ = timed(lambda: dop_likelihood.total(big), 3)
        print(f"  likelihood (DOP): {1e6 * 84 / t_gpu_lik / 1e9:.1f} G evaluations/s")
    else:
        print("\nno GPU visible to JAX (pip install spacepol[gpu] on a machine with one)")
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
