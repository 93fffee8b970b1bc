"""Which nested sampler the ``nested`` engine uses, by measurement: nautilus against dynesty on one posterior.

    python benchmarks/nested_choice.py [--seeds 3] [--live 500]

The posterior: the paper's model (n, k, sigma, ks, rho_d free) on its 84 in-plane geometries, DOP (noise 0.01) and
BRDF (5 %) made by ``spacepol.synth`` (seed 4). nautilus (``--live`` live points, one network, likelihood in
batches) from ``--seeds`` seeds, and dynesty (``--live`` live points, random-walk proposals, one point at a time:
its interface) from one, each run as its documentation suggests. Prints per run the seconds, likelihood calls,
effective draws (Kish, of the weights) and ln Z (dynesty's with its own error); for nautilus the scatter of ln Z
between seeds against its within-shell sampling error, the reason the engine takes its error from replicates; the
posterior means of both. Load printed before and after.
"""

import argparse
import os
import time

import numpy as np
from scipy.special import logsumexp


def kish(log_w):
    w = np.exp(log_w - logsumexp(log_w))
    return float(1.0 / np.sum(w**2)), w


def within_shell_error(sampler) -> float:
    """The sampling error of nautilus' ln Z from the spread of the likelihood within each shell (volumes exact)."""
    parts, variances = [], []
    for log_v, log_l in zip(sampler.shell_log_v, sampler.log_l):
        log_l = np.asarray(log_l)
        if log_l.size < 2:
            continue
        top = log_l.max()
        e = np.exp(log_l - top)
        parts.append(log_v + top + np.log(e.mean()))
        variances.append(2 * (log_v + top) + np.log(e.var(ddof=1) / log_l.size + 1e-300))
    log_z = logsumexp(parts)
    return float(np.sqrt(np.exp(logsumexp(variances) - 2 * log_z)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--live", type=int, default=500)
    args = ap.parse_args()
    import spacepol

    spacepol.configure_process(small_calls=True)
    print(f"load before: {os.getloadavg()[0]:.2f} (1-minute average, {os.cpu_count()} CPUs)")
    data = spacepol.synth("paper", {"n": 1.6, "sigma": 0.25, "ks": 0.6, "rho_d": 0.2}, noise_dop=0.01,
                          noise_brdf=0.05, seed=4)
    post = spacepol.build_posterior(data, "paper")
    names, ndim = post.names, post.ndim

    def log_likelihood(theta):
        value = post.log_likelihood(np.atleast_2d(theta))
        return np.where(np.isfinite(value), value, -1e300)

    log_likelihood(post.priors.sample(np.random.default_rng(0), 64))  # compile outside the timings
    from nautilus import Sampler

    rows, log_zs, means = [], [], {}
    for seed in range(args.seeds):
        start = time.perf_counter()
        sampler = Sampler(post.priors.rescale, log_likelihood, n_dim=ndim, n_live=args.live, n_networks=1,
                          vectorized=True, seed=seed)
        sampler.run(discard_exploration=True, verbose=False)
        seconds = time.perf_counter() - start
        points, log_w, _ = sampler.posterior()
        ess, w = kish(log_w)
        log_zs.append(sampler.log_z)
        means.setdefault("nautilus", np.sum(w[:, None] * points, axis=0))
        rows.append(("nautilus", seed, seconds, sampler.n_like, ess, f"{sampler.log_z:.4f}",
                     f"within-shell error {within_shell_error(sampler):.4f}"))
    import dynesty

    start = time.perf_counter()
    sampler = dynesty.NestedSampler(lambda x: float(log_likelihood(x[None])[0]), lambda u: post.priors.rescale(u[None])[0],
                                    ndim, nlive=args.live, sample="rwalk", rstate=np.random.default_rng(0))
    sampler.run_nested(print_progress=False, dlogz=0.1)
    seconds = time.perf_counter() - start
    res = sampler.results
    ess, w = kish(res.logwt)
    means["dynesty"] = np.sum(w[:, None] * res.samples, axis=0)
    rows.append(("dynesty", 0, seconds, int(np.sum(res.ncall)), ess, f"{res.logz[-1]:.4f} +- {res.logzerr[-1]:.4f}", ""))
    print(f"{'sampler':9s} {'seed':>4s} {'seconds':>8s} {'calls':>8s} {'eff. draws':>10s} {'eff./s':>7s}  ln Z")
    for name, seed, seconds, calls, ess, log_z, note in rows:
        print(f"{name:9s} {seed:4d} {seconds:8.1f} {calls:8d} {ess:10.0f} {ess / seconds:7.1f}  {log_z}  {note}")
    if len(log_zs) > 1:
        print(f"nautilus ln Z over {len(log_zs)} seeds: mean {np.mean(log_zs):.4f}, scatter (SD) {np.std(log_zs, ddof=1):.4f}")
    for name, m in means.items():
        print(f"posterior mean ({name}): " + ", ".join(f"{n} {v:.4f}" for n, v in zip(names, m)))
    print(f"load after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
