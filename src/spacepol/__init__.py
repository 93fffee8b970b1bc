"""spacepol: probabilistic inversion of polarimetric reflectance.

The Python API (:mod:`spacepol.api`) is what the ``invert-mcmc`` command line calls: ``load``, ``invert``,
``diagnose``, ``contrast``, ``observe``, ... and the ``Result`` every engine returns. The names are imported on
first use, so ``import spacepol`` stays light, and importing it changes no process-wide setting
(``configure_process`` opts in to the command line's speed settings).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
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
    "SpacepolError": "errors", "SamplerStalled": "errors", "observe": "api", "synth_pass": "api", "invert_lightcurve": "api", "LightCurve": "io.light_curve", "frame": "api", "optimize": "api", "compare": "api", "Comparison": "api",
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
