"""spacepol from Python: every command of ``invert-mcmc`` is a call here first.

    import spacepol
    data = spacepol.load("data/ptfe/ptfe_mueller_brdf.csv", wavelength_um=0.633, in_plane=True)
    result = spacepol.invert(data, "paper", seed=0, out="runs/ptfe")   # a Result
    again = spacepol.Result.load("runs/ptfe")
    table3 = spacepol.contrast(again)                                  # a Contrast

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from .inputs import parse_wavelengths, load, build_model, parse_observables, build_posterior, parameter_values
from .inversion import invert, calibrate, optimize, compare, Comparison
from .forward import forward, synth
from .observing import Contrast, contrast, observe, frame, Sky, sky
from .criticism import Diagnosis, diagnose, Ladder, ladder, Design, design
from .light_curves import invert_lightcurve, synth_pass

__all__ = [
    "synth_pass",
    "invert_lightcurve",
    "parse_wavelengths",
    "load",
    "build_model",
    "parse_observables",
    "build_posterior",
    "parameter_values",
    "invert",
    "calibrate",
    "optimize",
    "compare",
    "Comparison",
    "forward",
    "synth",
    "Contrast",
    "contrast",
    "observe",
    "frame",
    "Sky",
    "sky",
    "Diagnosis",
    "diagnose",
    "Ladder",
    "ladder",
    "Design",
    "design",
]
