"""Where diagnose's emcee refits stop when the ELPD-LOO of the chain's two halves agree (``infer.elpd_settled``),
and whether the delta ELPD they give is the one a long chain gives (issue 24).

    python studies/elpd_settled_stop.py [--seeds 1 2 3] [MODEL ...]

Each model is refitted as diagnose refits it (``invert`` from the global multistart's optimum, 20 tau, 2,000 draws
for PSIS-LOO), with the split-half stop on, capped at 16,000 steps. Printed per seed: the step it stopped at, its
seconds, its delta ELPD-LOO against ``paper+lambertian`` and the checks (step, the halves' ELPD-LOO). The references
are ``studies/emcee_cap_elpd.py``'s readings of one long chain: ``+oxide_layer`` +70.5, +69.6, +71.6, +69.8 at
2,000-16,000 steps (stable), ``+oxide_layer+ggx`` +139.6, +95.2, +139.2, +106.7 (walkers switching between two
modes). The data: the 278-geometry PTFE set of ``benchmarks/diagnose_rounds_speed.py``.
"""

import argparse
import time

import numpy as np

MODELS = ("paper+lambertian+oxide_layer", "paper+lambertian+oxide_layer+ggx")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("models", nargs="*", default=list(MODELS))
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--max-steps", type=int, default=16000)
    args = ap.parse_args()
    from spacepol import configure_process

    configure_process(small_calls=True)
    from ridge_base import base_pointwise, ptfe_set
    from spacepol.criticism.candidate_fits import ELPD_DRAWS, ELPD_TAU_MULTIPLE, _build
    from spacepol.infer import elpd_settled
    from spacepol.infer.inversion import invert
    from spacepol.infer.optimum import multistart
    from spacepol.physics import Model

    data = ptfe_set()
    base_loo = base_pointwise(data)
    checks = []
    original = elpd_settled.settled

    def recording(*a, **k):
        enough = original(*a, **k)
        checks.append(enough.checks)
        return enough

    import spacepol.infer.inversion as inversion

    inversion.settled = recording
    for spec in args.models:
        post = _build(data, Model.from_string(spec), None, None)
        _, centre = multistart(post, np.random.default_rng(1))
        for seed in args.seeds:
            start = time.perf_counter()
            inv = invert(post, seed=seed, max_steps=args.max_steps, progress=False, centre=centre,
                         tau_multiple=ELPD_TAU_MULTIPLE, max_pointwise_draws=ELPD_DRAWS,
                         elpd_tolerance=elpd_settled.TOLERANCE)
            diff = inv.loo["pointwise"] - base_loo
            s = inv.summary.sampler
            how = ("converged" if inv.diagnostics.converged else "ELPD settled" if s.get("stopped_early") else "at the cap")
            print(f"{spec}, seed {seed}: {how} at {s['steps']} steps ({time.perf_counter() - start:.0f} s), R-hat "
                  f"{inv.diagnostics.rhat_max:.3f}, delta ELPD {diff.sum():+.1f} +- {np.sqrt(len(diff) * np.var(diff)):.1f}; "
                  "checks " + ", ".join(f"{step}: {a:.1f}/{b:.1f} (bad k {100 * bad:.1f} %)" for step, a, b, bad in checks[-1]), flush=True)


if __name__ == "__main__":
    main()
