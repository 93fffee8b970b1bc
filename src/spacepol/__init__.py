"""spacepol: probabilistic inversion of polarimetric reflectance.

Physics lives in :mod:`spacepol.physics` (forward pBRDF model built from effects),
measurements in :mod:`spacepol.io`, inference in :mod:`spacepol.infer`, reporting in
:mod:`spacepol.report`.  The command line is :mod:`spacepol.cli` (``invert-mcmc``).
"""

__version__ = "0.1.0"

from ._runtime import configure_jax, keep_heap, limit_blas_threads

limit_blas_threads()
keep_heap()
configure_jax()
