"""spacepol: probabilistic inversion of polarimetric reflectance.

Physics lives in :mod:`spacepol.physics` (forward pBRDF model built from effects),
measurements in :mod:`spacepol.io`, inference in :mod:`spacepol.infer`, reporting in
:mod:`spacepol.report`.  The command line is :mod:`spacepol.cli` (``invert-mcmc``).
"""

__version__ = "0.1.0"

from ._runtime import keep_heap, limit_blas_threads, use_float64

limit_blas_threads()
keep_heap()
use_float64()
