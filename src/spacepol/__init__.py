"""spacepol: probabilistic inversion of polarimetric reflectance.

Physics lives in :mod:`spacepol.physics` (forward pBRDF model built from effects),
measurements in :mod:`spacepol.io`, inference in :mod:`spacepol.infer`, reporting in
:mod:`spacepol.report`.  The command line is :mod:`spacepol.cli` (``invert-mcmc``).

Importing it changes no process-wide setting. The command line opts in to the settings that decide speed on a
small shared machine (one BLAS thread, a kept heap, JAX's wide vectors and on-disk compilation cache) with
:func:`configure_process`; a library user may call it too. JAX's double precision, which the physics needs, is
turned on where spacepol first builds a model or compiles a program (``_runtime.ensure_double_precision``).
"""

__version__ = "0.1.0"

from ._runtime import configure_process

__all__ = ["configure_process", "__version__"]
