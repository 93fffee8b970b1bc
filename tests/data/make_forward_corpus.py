"""Records the forward model's outputs on a fixed corpus, for ``tests/test_forward_corpus.py``.

Run once with the numpy/numba implementation (commit 7870214, before the JAX forward model) to make
``forward_corpus.npz``: the JAX model must reproduce these numbers to 1e-12. The corpus follows the
property tests (``test_properties.py``): every built-in effect, parameters drawn over each prior's
whole support, geometries over the whole hemisphere, plus the special geometries (exact specular,
normal incidence and exit, retro-reflection, grazing) and both scalar and batched parameter sets.

    python tests/data/make_forward_corpus.py
"""

import pathlib

import numpy as np

from spacepol.physics import Geometry, Model

MODELS = [
    "specular+shadowing+body+polarized_diffuse+depolarization+oxide_layer+angle_offset+extinction+dop_bias",
    "specular+smith+ggx+anisotropy+body+polarized_diffuse+lambertian+subsurface",
    "specular+shadowing+body+polarized_diffuse+depolarization+extinction+dop_bias",
    "specular+smith+ggx+body",
    "paper",
    "specular+smith+subsurface+oxide_layer",
]
SCALAR_EXAMPLES = 40  # one parameter set at 16 random geometries each (as a hypothesis example)
BATCH_SETS, BATCH_GEOMETRIES = 24, 40


def draw_params(model, rng, size=None):
    return {p.name: rng.uniform(*p.prior.bounds, size) for p in model.parameters}


def random_geometry(rng, n):
    return Geometry(rng.uniform(0, 89.99, n), rng.uniform(0, 89.99, n), rng.uniform(-360, 360, n),
                    np.full(n, rng.uniform(0.3, 2.0)))


def special_geometry():
    t = np.array([0.0, 1e-9, 30.0, 45.0, 89.999])
    ti, tr, dp = np.meshgrid(t, t, [0.0, 90.0, 180.0, -180.0, 270.0, 1e-9], indexing="ij")
    return Geometry(ti.ravel(), tr.ravel(), dp.ravel(), np.full(ti.size, 0.6))


def record(model, params, geometry, prefix, out):
    for key, value in params.items():
        out[f"{prefix}/param/{key}"] = np.asarray(value, float)
    out[f"{prefix}/geometry"] = np.stack([geometry.theta_i, geometry.theta_r, geometry.dphi, geometry.wavelength_um])
    stokes = model.evaluate(params, geometry)
    full = model.evaluate(params, geometry, mueller=True)
    out[f"{prefix}/stokes"], out[f"{prefix}/dop"] = stokes.stokes, stokes.dop
    out[f"{prefix}/mueller"], out[f"{prefix}/mueller_dop"] = full.mueller, full.dop


def main():
    rng = np.random.default_rng(20261123)
    out = {}
    for m, spec in enumerate(MODELS):
        model = Model.from_string(spec)
        out[f"model{m}"] = np.array(spec)
        for e in range(SCALAR_EXAMPLES):
            record(model, draw_params(model, rng), random_geometry(rng, 16), f"model{m}/scalar{e}", out)
        record(model, draw_params(model, rng, BATCH_SETS), random_geometry(rng, BATCH_GEOMETRIES), f"model{m}/batch", out)
        record(model, model.defaults(), special_geometry(), f"model{m}/special", out)
    target = pathlib.Path(__file__).with_name("forward_corpus.npz")
    np.savez_compressed(target, **out)
    print(f"{target}: {len(out)} arrays, {target.stat().st_size / 1e6:.1f} MB")


if __name__ == "__main__":
    main()
