"""Read back the posterior of an ``invert-mcmc run`` folder (summary.json + posterior.nc)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import SpacepolError


def load_run(run_dir) -> tuple[dict | str, dict[str, np.ndarray], dict]:
    """(model spec, {parameter: flat samples}, summary) of a run folder. The spec is the whole model
    (``physics.model_spec``); a folder written before specs were stored gives the model's name."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise SpacepolError(f"{run_dir}: not a folder (give the --out folder of `invert-mcmc run`)")
    summary_path, posterior_path = run_dir / "summary.json", run_dir / "posterior.nc"
    for path in (summary_path, posterior_path):
        if not path.is_file():
            raise SpacepolError(f"{path}: missing; is {run_dir} the output folder of `invert-mcmc run`?")
    try:
        summary = json.loads(summary_path.read_text(encoding="utf-8"))
        model = summary["model"]
    except (json.JSONDecodeError, KeyError, UnicodeDecodeError):
        raise SpacepolError(f"{summary_path}: not a spacepol summary (no 'model')") from None
    import arviz as az

    try:
        idata = az.from_netcdf(str(posterior_path))
        post = idata.posterior
    except Exception as exc:  # netCDF/HDF5 raise many types for a damaged file
        raise SpacepolError(f"{posterior_path}: cannot read the posterior ({type(exc).__name__})") from None
    samples = {name: np.asarray(post[name]).reshape(-1) for name in post.data_vars}
    for name, fixed in summary.get("fixed", {}).items():
        samples.setdefault(name, float(fixed))
    return summary.get("spec", model), samples, summary
