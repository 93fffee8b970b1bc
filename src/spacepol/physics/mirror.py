"""Mirror pairs: an isotropic sample's Mueller matrix at -dphi is D M(dphi) D with D = diag(1, 1, -1, -1) in DESIGN's
(s, p, d) basis, so rows measured on both sides of the plane of incidence need the model at one geometry of each
pair. ``MirrorFold`` says which geometries, and which rows each stands for; the likelihood folds where every effect
of the model declares ``mirror_symmetric`` (``tests/test_mirror_fold.py`` checks each built-in's declaration, both
ways).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import jax.numpy as jnp
import numpy as np

from .geometry import Geometry

MIRROR_SIGNS = np.array([1.0, 1.0, -1.0, -1.0])
# fold only where it saves at least this share of the rows
MIN_SAVED = 0.1
_DECIMALS = 9  # angles (deg) equal to this many decimals are one geometry: the mod-360 arithmetic moves the last bits


@dataclass(frozen=True)
class MirrorFold:
    """The folded geometries of a fixed geometry and the rows each stands for.

    ``geometry``: one geometry per class of rows that are the same geometry or each other's mirror image (dphi folded
    into [0, 180]); ``slots``: (K, U) the rows of each class, one per slot (-1 where a class has fewer than K);
    ``flipped``: per row, whether it is its class's geometry seen in the mirror; ``index``: per row, its class."""

    geometry: Geometry
    slots: np.ndarray
    flipped: np.ndarray
    index: np.ndarray  # per row, its class

    @classmethod
    def of(cls, geometry: Geometry) -> MirrorFold | None:
        """The fold of a fixed (N,) geometry, or None where it would save less than ``MIN_SAVED`` of the rows."""
        if np.ndim(geometry.theta_i) != 1 or geometry.xp is not np:
            return None
        folded, flipped, first, index = _classes(geometry)
        if len(first) > (1.0 - MIN_SAVED) * geometry.size:
            return None
        order = np.argsort(index, kind="stable")
        rank = np.empty(geometry.size, int)
        starts = np.searchsorted(index[order], np.arange(len(first)))
        rank[order] = np.arange(geometry.size) - np.repeat(starts, np.bincount(index, minlength=len(first)))
        slots = np.full((rank.max() + 1, len(first)), -1)
        slots[rank, index] = np.arange(geometry.size)
        wavelength = None if geometry.wavelength_um is None else np.asarray(geometry.wavelength_um, float)[first]
        kept = Geometry(np.asarray(geometry.theta_i)[first], np.asarray(geometry.theta_r)[first], folded[first],
                        wavelength)
        return cls(geometry=kept, slots=slots, flipped=flipped, index=index)

    def signs(self, rows: np.ndarray, mueller: bool) -> np.ndarray:
        """For ``rows`` (row indices, -1 where a slot holds none) the signs that turn each class's Mueller matrix
        (4, 4, 1, n) or Stokes vector (4, 1, n) into its row's (1 where there is no row)."""
        signs = np.outer(MIRROR_SIGNS, MIRROR_SIGNS) if mueller else MIRROR_SIGNS
        flipped = np.where(rows >= 0, self.flipped[np.maximum(rows, 0)], False)
        return np.where(flipped, signs[..., None], 1.0)[..., None, :]

    def unfold(self, total, dop, mueller: bool):
        """(total, dop) at every row from the folded evaluation's (classes on the last axis): gathered, with the
        mirror signs on the flipped rows (for callers that need every row; the likelihood never unfolds)."""
        signs = self.signs(np.arange(self.index.size), mueller)
        signs = signs.reshape(signs.shape[:-2] + (1,) * (jnp.ndim(total) - signs.ndim + 1) + signs.shape[-1:])
        index = jnp.asarray(self.index)
        return total[..., index] * jnp.asarray(signs), dop[..., index]


def _classes(geometry: Geometry):
    """Per row its folded dphi (deg) and whether it is the mirror image; the first row of each class; each row's class."""
    turned = np.mod(np.asarray(geometry.dphi, float), 360.0)
    folded = np.round(np.minimum(turned, 360.0 - turned), _DECIMALS)
    flipped = np.round(turned, _DECIMALS) > folded
    wavelength = np.zeros(geometry.size) if geometry.wavelength_um is None else np.asarray(geometry.wavelength_um, float)
    keys = np.column_stack([np.round(geometry.theta_i, _DECIMALS), np.round(geometry.theta_r, _DECIMALS), folded,
                            wavelength])
    _, first, index = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return folded, flipped, first, np.ravel(index)
