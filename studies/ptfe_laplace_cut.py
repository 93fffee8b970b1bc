"""Why no Gaussian holds the four-wavelength PTFE posterior of the phase-matrix model: where its maximum sits against
the phase matrix's realizability limit, and whether the log posterior is smooth there.

    python studies/ptfe_laplace_cut.py [--search-every 8] [--seed 0] [--wavelength-um all]

The model and held values are those of ``docs/ptfe.md``'s four-wavelength fit. The maximum is found as
``studies/ptfe_models.py`` finds it (``find_optimum_on_every``); then, at the maximum:

1. The phase matrix against its realizable set K (``physics.constrained_phase``): the nodes' gauge (1 on K's
   boundary) and the gauge of the spline's Bezier control points, before the pull that keeps the spline inside K,
   with the scattering angles of the control points at the limit. Where several tie at the largest gauge, the pull's
   scale factor is a maximum of smooth functions that switch there: the log posterior has a kink.
2. For each free shape coordinate, the log posterior along it in the samplers' coordinates (+-1/4 of its Laplace
   SD, 21 points): the largest residual of a quadratic fit, at the maximum itself where a kink sits there. A smooth
   coordinate (an index) is the control.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import ptfe_models  # noqa: E402

from spacepol.infer.laplace import mode_and_precision  # noqa: E402
from spacepol.infer.optimum import find_optimum_on_every  # noqa: E402
from spacepol.infer.posterior import Posterior  # noqa: E402
from spacepol.infer.sampling_space import SamplingSpace  # noqa: E402
from spacepol.physics import constrained_phase  # noqa: E402
from spacepol.physics.effects.phase_matrix import SHAPE_NAMES  # noqa: E402

HELD = "w_pm=1 dl_pm=0 fc_pm=0 pm_m44_0=1 pm_m44_180=1 k@0.351=0 k@0.532=0 k@0.633=0 k@1.064=0 ks=1"
SPEC = f"specular+smith+subsurface+phase_matrix [{HELD}]"
ARC_DEG = 60.0 / constrained_phase.SUBDIVISIONS


def control_point_angle_deg(index: int) -> float:
    """The scattering angle (deg) of Bezier control point ``index``: its arc's start plus a third of the arc per point."""
    arc, point = divmod(index, 4)
    return arc * ARC_DEG + point * ARC_DEG / 3


def limit_contact(shape: list) -> dict:
    """The phase matrix of box coordinates ``shape`` against K: nodes' gauge, spline gauge, control points within
    1e-4 of the largest gauge (index, angle in deg, gauge)."""
    nodes = constrained_phase.node_values(shape)
    gauges = np.asarray(constrained_phase.control_point_gauges(nodes), float)
    top = gauges.max()
    near = [(int(j), control_point_angle_deg(int(j)), float(gauges[j])) for j in np.flatnonzero(gauges > top - 1e-4)]
    return {"nodes_gauge": float(constrained_phase.nodes_gauge(nodes)), "spline_gauge": float(top), "at_limit": near}


def kink_sizes(posterior, theta, names) -> list[tuple[str, float, float]]:
    """(name, Laplace SD in z, largest residual of a quadratic fit along the name's axis and where it is, in SDs)."""
    space = SamplingSpace(posterior.priors)
    log_prob_z = space.log_prob(posterior)
    z0 = space.to_z(np.asarray(theta, float)[None, :])[0]
    found = mode_and_precision(log_prob_z, z0)
    covariance = np.linalg.inv(found[1]) if found else np.eye(len(z0))
    out = []
    for name in names:
        j = list(posterior.names).index(name)
        sd = float(np.sqrt(covariance[j, j]))
        steps = np.linspace(-0.25, 0.25, 21) * sd
        rows = np.repeat(z0[None, :], len(steps), axis=0)
        rows[:, j] += steps
        values = log_prob_z(rows)
        residual = values - np.polyval(np.polyfit(steps, values, 2), steps)
        k = int(np.argmax(np.abs(residual)))
        out.append((name, sd, float(residual[k]), float(steps[k] / sd)))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--search-every", type=int, default=8)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--wavelength-um", default="all")
    args = parser.parse_args()
    data = ptfe_models.load(args.wavelength_um)
    model = ptfe_models.model_for(data, SPEC)
    posterior = Posterior.build(data, model, prior_overrides=ptfe_models.entry_priors(model, SPEC))
    start = time.perf_counter()
    best, theta = find_optimum_on_every(posterior, args.search_every, np.random.default_rng(args.seed), evaluations=3000)
    print(f"{SPEC}\nmaximum log posterior {best:.1f} ({time.perf_counter() - start:.0f} s)")
    values = posterior.priors.to_params(np.asarray(theta, float)[None, :])
    shape = [float(np.ravel(values[name])[0]) for name in SHAPE_NAMES]
    contact = limit_contact(shape)
    print(f"\nnodes' gauge {contact['nodes_gauge']:.6f}, spline gauge before the pull {contact['spline_gauge']:.6f}")
    print("control points at the largest gauge (within 1e-4):")
    for index, angle, value in contact["at_limit"]:
        print(f"  {index:2d} at {angle:5.1f} deg: {value:.7f}")
    free_shape = [n for n in SHAPE_NAMES if n in posterior.names]
    control = [n for n in posterior.names if n.startswith("n@")][:1]
    print("\n| coordinate | Laplace SD (z) | largest residual of a quadratic (log posterior) | where (SDs from the maximum) |")
    print("|---|---|---|---|")
    for name, sd, residual, where in kink_sizes(posterior, theta, free_shape + control):
        print(f"| {name}{' (control)' if name in control else ''} | {sd:.2e} | {residual:+.4f} | {where:+.3f} |")


if __name__ == "__main__":
    main()
