"""Which mode of the `replace shadowing by smith` alternative holds the posterior mass on PTFE (issue 24)?

    python studies/ridge_modes.py

Model `specular+smith+body+lambertian+oxide_layer` on the 278-geometry PTFE set at 0.633 um (chosen as
``benchmarks/laplace_vs_emcee.py`` chooses it). The low-index mode is found by the same search with n held in
[0.6, 1.0], then polished with n free. A global multistart found a mode at n ~ 1.8, k ~ 1.8;
nested sampling (two replicates) put all the mass near n 0.75, k 0.06. Here: both modes polished, their
log posterior, the Laplace evidence of each (ln p(mode) + D/2 ln 2 pi + 1/2 ln det Sigma in the sampling space)
and the importance-sampling evidence of the Laplace proposal at each (with its Pareto k: where k > 0.7 it is not to
be trusted). The mode with the larger evidence holds the mass; the other is where a start search can strand a chain.
"""

import os
import time

import numpy as np


def main():
    from spacepol import configure_process

    configure_process(small_calls=True)
    from spacepol.infer.laplace import _hessian, laplace_importance
    from spacepol.infer.measured_noise import reciprocal_pairs
    from spacepol.infer.optimum import find_optimum, polish_posterior
    from spacepol.infer.posterior import Posterior
    from spacepol.infer.sampling_space import SamplingSpace
    from spacepol.io import read_measurements
    from spacepol.paths import bundled
    from spacepol.physics import Model

    print(f"load average before: {os.getloadavg()[0]:.2f}")
    first = read_measurements(bundled("ptfe", "ptfe_mueller_brdf.csv")).at_wavelength(0.633)
    rows = np.union1d(np.arange(0, len(first), max(1, len(first) // 260)), reciprocal_pairs(first).ravel())
    data = first.select(rows)
    post = Posterior.build(data, Model.from_string("specular+smith+body+lambertian+oxide_layer"))
    names = post.names
    start = time.perf_counter()
    value_a, mode_a = find_optimum(post, np.random.default_rng(0))
    # the low-index mode: the best point with n held in [0.6, 1.0], then polished in the full posterior
    from spacepol.priors import Uniform

    low = Posterior.build(data, post.likelihood.model, {"n": Uniform(0.6, 1.0)})
    _, inside = find_optimum(low, np.random.default_rng(0))
    value_b, mode_b = polish_posterior(post, inside)
    space = SamplingSpace(post.priors)
    log_prob_z = space.log_prob(post)
    print(f"{len(data)} geometries; parameters {names}; searches {time.perf_counter() - start:.0f} s")
    for label, value, mode in (("multistart", value_a, mode_a), ("n in [0.6, 1]", value_b, mode_b)):
        z = space.to_z(mode[None, :])[0]
        precision = -_hessian(log_prob_z, z, np.full(z.size, 1e-3))
        sign, logdet = np.linalg.slogdet(precision)
        laplace = (float(log_prob_z(z[None, :])[0]) + 0.5 * z.size * np.log(2 * np.pi) - 0.5 * logdet
                   if sign > 0 else float("nan"))
        sample = laplace_importance(post, mode, np.random.default_rng(1), adapt=False)
        is_z = sample.log_evidence if sample is not None else (np.nan, np.nan)
        k = sample.pareto_k if sample is not None else np.nan
        print(f"{label:12s} log posterior {value:10.2f} | n {mode[names.index('n')]:.3f} k {mode[names.index('k')]:.3f} | "
              f"Laplace ln Z {laplace:10.2f} | IS ln Z {is_z[0]:10.2f} +- {is_z[1]:.2f} (Pareto k {k:.2f})")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
