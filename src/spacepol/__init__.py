"""spacepol: probabilistic inversion of polarimetric reflectance.

The Python API (:mod:`spacepol.api`, every name below) is what the ``invert-mcmc`` command line calls:

    import spacepol
    data = spacepol.load("data/ptfe/ptfe_mueller_brdf.csv", wavelength_um=0.633, in_plane=True)
    result = spacepol.invert(data, "paper", seed=0)       # a Result: ArviZ groups, diagnostics, model spec
    result.save("runs/ptfe"); again = spacepol.Result.load("runs/ptfe")
    table3 = spacepol.contrast(again)                     # the paper's Table 3 as distributions

Physics lives in :mod:`spacepol.physics` (the forward pBRDF model built from effects), measurements in
:mod:`spacepol.io`, inference in :mod:`spacepol.infer`, criticism in :mod:`spacepol.criticism`, reports in
:mod:`spacepol.report`. The names are imported on first use, so ``import spacepol`` stays light.

Importing it changes no process-wide setting. The command line opts in to the settings that decide speed on a
small shared machine (one BLAS thread, a kept heap, JAX's wide vectors and on-disk compilation cache) with
:func:`configure_process`; a library user may call it too. JAX's double precision, which the physics needs, is
turned on where spacepol first builds a model or compiles a program (``_runtime.ensure_double_precision``).
"""

__version__ = "0.1.0"

from ._runtime import configure_process

# name -> the module that defines it; imported on first access (PEP 562)
_API = {
    "load": "api", "parse_wavelengths": "api", "build_model": "api", "build_posterior": "api",
    "parse_observables": "api", "invert": "api", "forward": "api", "synth": "api", "contrast": "api",
    "parameter_values": "api", "Contrast": "api", "sky": "api", "Sky": "api",
    "diagnose": "api", "Diagnosis": "api", "calibrate": "api", "Calibration": "infer.calibration", "ladder": "api", "Ladder": "api", "design": "api", "Design": "api",
    "Result": "infer.result", "Diagnostics": "infer.result", "Fit": "infer.result",
    "Dataset": "io.dataset", "Model": "physics.model", "Geometry": "physics.geometry",
    "SpacepolError": "errors", "observe": "api", "frame": "api",
}

__all__ = ["configure_process", "__version__", *_API]


def __getattr__(name):
    module = _API.get(name)
    if module is None:
        raise AttributeError(f"module 'spacepol' has no attribute '{name}'")
    import importlib

    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(__all__)
