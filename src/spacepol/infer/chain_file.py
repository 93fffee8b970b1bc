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
                if "random_state" not in g.attrs and not any(k.startswith("random_state") for k in g.attrs):
                    raise _damaged(path, "no random state stored")
            return iteration
    except ChainFileError:
        raise
    except BlockingIOError:
        raise ChainFileError(f"{path}: in use by another process (another run on this folder?); "
                             f"wait for it or use another --out") from None
    except (OSError, KeyError, ValueError, RuntimeError) as exc:
        raise _damaged(path, f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'unreadable'}") from None


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
