"""How the compiled likelihood is cut up: parameter sets into the block sizes it compiles, into chunks that keep
the intermediates in the CPU's cache, and the rows into the parts it sums one by one, each in the slots of its mirror
fold (``Rows``, ``part_slots``).
"""

from __future__ import annotations

from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

CACHE_NUMBERS = 1 << 19  # sets x geometries x (16 or 4) numbers evaluated at once by ``total`` (4 MB per array)
# every likelihood compiles one block of 16 sets (and the callers' exact sizes, e.g. emcee's half-ensemble); a call of
# more sets goes through it in blocks. Each further size is a compilation of its own (the largest part of a
# diagnosis on a small data set: ``benchmarks/diagnose_cost_ratio.py --profile``), so the larger block is compiled
# only once the sets this likelihood has evaluated in calls of at least its size would have paid for it about twice
# over: on the 84-point DOP set a set costs ~4x less in blocks of 256 than in blocks of 16, and the block's compilation
# as much as ~25,000 sets in blocks of 16 (``benchmarks/likelihood_blocks.py``)
BLOCK_SETS = 16
LARGE_BLOCK_SETS = 256
SETS_PAYING_A_COMPILATION = 50_000
ONE_BLOCK_NUMBERS = 1 << 15
# ``total`` reads a large likelihood's pointwise program where a call's block holds at most this many numbers: beyond
# it the unfused values no longer stay in the cache (all of PTFE, 7,296 geometries x 16 elements, ``paper`` at four
# wavelengths: 30 sets 0.78x the fused total's time, 64 sets 1.35x)
POINTWISE_NUMBERS = 4_000_000
# ... until the likelihood has evaluated this many sets in ``total`` calls: then its own summed program, compiled once,
# pays for itself (PTFE, the wavelengths summed one by one: four wavelengths 1.4x (phase_matrix) to 1.6x (paper) as
# fast as the pointwise program summed, one wavelength 1.05-1.3x; a compilation costs some 10,000 sets there)
SETS_PAYING_THE_SUM = 20_000


def block_rows(n_sets: int, sizes: list) -> int:
    """Sets per compiled call: the smallest compiled size that holds them all where padding wastes at most a quarter
    of it (or no size is smaller), else blocks of the largest size that fits (40 sets: three calls of 16, not one
    of 256; 512 sets: two calls of 256)."""
    fit = next((size for size in sizes if size >= n_sets), None)
    below = [size for size in sizes if size <= n_sets]
    if fit is not None and (fit - n_sets <= fit // 4 or not below):
        return fit
    return below[-1]


@dataclass(frozen=True)
class Rows:
    """Rows of the data the compiled likelihood takes together (one wavelength's, or one slot of its mirror fold): how
    many, the measured values, the file's errors and the noise profiles per channel; for a slot, the signs that turn
    each folded geometry's Mueller matrix (or Stokes vector) into its row's, and which entries hold a row."""

    size: int
    y: dict
    errors: dict
    profiles: dict
    signs: object = None
    valid: object = None


def part_slots(y: dict, errors: dict, profiles: dict, program, j: int, mueller: bool) -> tuple[list[Rows], np.ndarray | None]:
    """Part ``j`` of ``program``'s data (``y``, ``errors``, ``profiles``: {channel: (N,)}) as the compiled function's
    constants (as arguments they would be handled on every call): one ``Rows`` per slot of its mirror fold (one
    holding every row where it has none), and where each of the part's rows lies in its slots laid side by side
    (None: in order)."""
    rows, fold = program.part_rows(j), program.folds[j]
    if fold is None:
        return [_rows(y, errors, profiles, rows)], None
    slots = []
    for held in fold.slots:
        # where a slot holds no row its numbers are those of the class's first row, and weigh nothing
        stand_in = np.where(held >= 0, held, fold.slots[0])
        slots.append(_rows(y, errors, profiles, rows[stand_in], fold.signs(held, mueller), held >= 0))
    position = np.empty(rows.size, int)
    for k, held in enumerate(fold.slots):
        position[held[held >= 0]] = k * held.size + np.flatnonzero(held >= 0)
    return slots, position


def _rows(y: dict, errors: dict, profiles: dict, rows: np.ndarray, signs=None, valid=None) -> Rows:
    return Rows(size=rows.size, y={ch: jnp.asarray(v[rows]) for ch, v in y.items()},
                errors={ch: jnp.asarray(e[rows]) for ch, e in errors.items()},
                profiles={ch: jnp.asarray(f[rows]) for ch, f in profiles.items()},
                signs=None if signs is None else jnp.asarray(signs),
                valid=None if valid is None or valid.all() else jnp.asarray(valid))


def in_cache_sized_chunks(summed, numbers_per_set: int):
    """``summed`` over a (P, D) matrix in chunks of sets small enough that the sets x geometries intermediates stay
    in the CPU's cache: above it the evaluation is memory-bound."""

    def total(matrix):
        n_sets = matrix.shape[0]
        chunk = min(n_sets, max(1, CACHE_NUMBERS // numbers_per_set))
        chunk = next(c for c in range(chunk, 0, -1) if n_sets % c == 0)  # the largest that divides the batch
        if chunk >= n_sets:
            return summed(matrix)
        blocks = matrix.reshape(n_sets // chunk, chunk, matrix.shape[1])
        out = jax.lax.map(summed, blocks)
        return out.reshape((n_sets,) + out.shape[2:])

    return total
