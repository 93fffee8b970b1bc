"""The chain file of a run (``DIR/chain.h5``, emcee's HDF backend): what state it is in, whether
it is damaged, and setting it aside for ``--restart``.

A kill during a write, a full disk or a copy cut short can leave an HDF5 file that h5py cannot
open or whose datasets disagree with the iteration count; such a file is reported in one line
with the remedy instead of an h5py traceback.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import SpacepolError


class ChainFileError(SpacepolError):
    """A chain file that cannot be used as it is."""


def _damaged(path: Path, reason: str) -> ChainFileError:
    return ChainFileError(f"{path}: damaged chain file ({reason}); run the same command with --restart to start "
                          f"afresh (the damaged file is kept as {path.name}.old)")


def chain_iterations(path, group: str = "mcmc") -> int:
    """Steps stored in ``path`` (0 if the file or its chain does not exist yet); ChainFileError if damaged."""
    import h5py

    path = Path(path)
    if not path.exists():
        return 0
    if path.stat().st_size == 0:
        raise _damaged(path, "empty file")
    try:
        with h5py.File(path, "r") as f:
            if group not in f:
                return 0
            g = f[group]
            iteration = int(g.attrs["iteration"])
            chain, log_prob = g["chain"], g["log_prob"]
            if chain.shape[0] < iteration or log_prob.shape[0] < iteration:
                raise _damaged(path, f"{iteration} steps recorded but {chain.shape[0]} stored")
            if iteration > 0:  # read the last step: it is the one a kill during a write leaves broken
                chain[iteration - 1]
                log_prob[iteration - 1]
            return iteration
    except ChainFileError:
        raise
    except BlockingIOError:
        raise ChainFileError(f"{path}: in use by another process (another run on this folder?); "
                             f"wait for it or use another --out") from None
    except (OSError, KeyError, ValueError, RuntimeError) as exc:
        raise _damaged(path, f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'unreadable'}") from None


def random_state_readable(path, group: str = "mcmc") -> bool:
    """Whether the sampler's random state stored beside the chain can be read back. emcee rewrites it (an
    attribute holding a string, in HDF5's global heap) at every step, so a kill can break it while every
    stored step is intact."""
    import h5py

    try:
        with h5py.File(path, "r") as f:
            attrs = f[group].attrs
            keys = [k for k in attrs if k.startswith("random_state")]
            for k in keys:
                attrs[k]
            return bool(keys)
    except (OSError, KeyError, ValueError, RuntimeError):
        return False


def replace_random_state(path, state, group: str = "mcmc") -> None:
    """Rewrite ``path`` with every dataset and readable attribute, and ``state`` (numpy's RandomState
    tuple) as the random state, as emcee stores it; atomic (a copy renamed into place). The chain is kept;
    only the stream of random numbers after it differs from an uninterrupted run's."""
    import h5py

    from ..io.atomic import atomic_path

    path = Path(path)
    with atomic_path(path) as tmp, h5py.File(path, "r") as src, h5py.File(tmp, "w") as dst:
        _copy_attrs(src.attrs, dst.attrs)
        for name in src:
            out = dst.create_group(name)
            _copy_attrs(src[name].attrs, out.attrs)
            for key in src[name]:
                src[name].copy(src[name][key], out, name=key)
        for i, value in enumerate(state):
            dst[group].attrs[f"random_state_{i}"] = value


def _copy_attrs(source, target) -> None:
    for key in list(source.keys()):
        if key.startswith("random_state"):
            continue
        try:
            target[key] = source[key]
        except (OSError, KeyError, ValueError, RuntimeError):
            continue  # unreadable after the kill: emcee rewrites what it needs at the next step


def set_aside(path) -> Path | None:
    """Move ``path`` to ``path.old`` (replacing an older one); returns the new name, None if absent."""
    path = Path(path)
    if not path.exists():
        return None
    old = path.with_name(path.name + ".old")
    os.replace(path, old)
    return old


def compact(path) -> None:
    """Rewrite a finished chain file without the free space HDF5 leaves behind: emcee rewrites the
    random state at every step and grows the datasets block by block, and HDF5 never reclaims the old
    space (a PTFE run's 15 MB of chain filled a 42 MB file).  Atomic: a copy renamed into place."""
    import h5py

    from ..io.atomic import atomic_path

    path = Path(path)
    with atomic_path(path) as tmp, h5py.File(path, "r") as src, h5py.File(tmp, "w") as dst:
        dst.attrs.update(src.attrs)
        for name in src:
            src.copy(src[name], dst, name=name)
