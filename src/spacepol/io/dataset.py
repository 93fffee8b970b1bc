"""A data set of polarimetric measurements: the geometries and the arrays of whatever observables a file holds.

The Dataset knows no observable by name: it keeps the arrays each registered observable declares (``dop`` and
``dop_err``, the (4, N) ``stokes``, the (4, 4, N) ``mueller`` ...), rows on the last axis, and selects and joins
them generically. ``data.dop`` reads an array (None where absent); ``Dataset(..., dop=values)`` sets one.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputFileError
from ..observables import registry
from ..physics.geometry import Geometry

GEOMETRY_COLUMNS = ("theta_i", "theta_r", "dphi", "wavelength_um")
_CORE = ("theta_i", "theta_r", "dphi", "wavelength_um", "metadata", "source", "arrays")


class Dataset:
    """Measurements at N geometries: angles in degrees (``theta_i``, ``theta_r``, ``dphi``), ``wavelength_um``
    per row (or None), and ``arrays``, {name: array with the rows on its last axis} for the observables present;
    an array an observable declares but the data lack reads as None."""

    def __init__(self, theta_i, theta_r, dphi, wavelength_um=None, metadata: dict | None = None, source: str = "",
                 **arrays):
        self.theta_i = np.asarray(theta_i)
        self.theta_r = np.asarray(theta_r)
        self.dphi = np.asarray(dphi)
        self.wavelength_um = None if wavelength_um is None else np.asarray(wavelength_um)
        self.metadata = dict(metadata or {})
        self.source = source
        self.arrays: dict[str, np.ndarray] = {}
        for name, value in arrays.items():
            self.set(name, value)

    def set(self, name: str, value) -> None:
        """Store the array ``name`` (one an observable declares; None removes it)."""
        known = registry.array_names()
        if name not in known:
            raise TypeError(f"Dataset has no array '{name}' (the observables keep {', '.join(sorted(known))})")
        if value is None:
            self.arrays.pop(name, None)
        else:
            self.arrays[name] = np.asarray(value)

    def get(self, name: str):
        """The array ``name``, or None where the data lack it."""
        return self.arrays.get(name)

    def __getattr__(self, name):
        # only reached for names that are not attributes: the observables' arrays (data.dop, data.mueller)
        if name.startswith("_") or "arrays" not in self.__dict__:
            raise AttributeError(name)
        if name in registry.array_names():
            return self.arrays.get(name)
        raise AttributeError(f"'Dataset' object has no attribute '{name}'")

    def __setattr__(self, name, value):
        if name in _CORE or name.startswith("_"):
            object.__setattr__(self, name, value)
        else:
            self.set(name, value)

    def __len__(self):
        return len(self.theta_i)

    def __repr__(self):
        return f"Dataset({len(self)} rows, observables {', '.join(self.observables) or 'none'}, source {self.source!r})"

    @property
    def geometry(self) -> Geometry:
        """The rows' geometry (angles and wavelength), computed once."""
        if "_geometry" not in self.__dict__:
            self._geometry = Geometry(self.theta_i, self.theta_r, self.dphi, self.wavelength_um)
        return self._geometry

    @property
    def observables(self) -> list[str]:
        """The observables the data hold, in the registry's listing order."""
        return [o.name for o in registry.every() if o.present(self)]

    def _with_rows(self, take) -> "Dataset":
        geometry = {name: take(getattr(self, name)) for name in GEOMETRY_COLUMNS if getattr(self, name) is not None}
        arrays = {name: take(value) for name, value in self.arrays.items()}
        return Dataset(**geometry, metadata=dict(self.metadata), source=self.source, **arrays)

    def select(self, mask) -> "Dataset":
        """A subset of the rows (boolean mask or indices)."""
        idx = np.arange(len(self))[mask]
        return self._with_rows(lambda value: np.take(value, idx, axis=-1))

    def in_plane(self, tolerance_deg: float = 1e-6) -> "Dataset":
        """Rows in the plane of incidence: dphi = 0 (retro side) or 180 deg (specular side)."""
        off = np.abs(np.sin(np.radians(self.dphi)))
        return self.select(off < np.sin(np.radians(tolerance_deg)) + 1e-12)

    def at_wavelengths(self, wavelengths_um, tolerance_um: float = 1e-4) -> "Dataset":
        """The rows at any of ``wavelengths_um`` (each must be present)."""
        keep = np.zeros(len(self), bool)
        for w in wavelengths_um:
            keep |= self._rows_at(w, tolerance_um)
        return self.select(keep)

    def _rows_at(self, wavelength_um: float, tolerance_um: float):
        """Boolean mask of the rows at ``wavelength_um``; absent -> one line naming the wavelengths there are."""
        if self.wavelength_um is None:
            raise InputFileError(self.source, "has no wavelength to select on")
        keep = np.abs(self.wavelength_um - wavelength_um) < tolerance_um
        if not keep.any():
            have = ", ".join(f"{w:g}" for w in np.unique(self.wavelength_um))
            raise InputFileError(self.source, f"no rows at wavelength {wavelength_um:g} um (have {have})")
        return keep

    def at_wavelength(self, wavelength_um: float, tolerance_um: float = 1e-4) -> "Dataset":
        """The rows at one wavelength (it must be present); the metadata record it."""
        out = self.select(self._rows_at(wavelength_um, tolerance_um))
        out.metadata = {**self.metadata, "wavelength_um": wavelength_um}
        return out

    @classmethod
    def concatenate(cls, parts: list["Dataset"]) -> "Dataset":
        """The rows of several data sets in one (e.g. one file per wavelength). Every part must hold the same
        observables and error columns; the metadata are the first part's, the source names every part."""
        if not parts:
            raise ValueError("Dataset.concatenate: no data sets given")
        joined = {}
        names = list(GEOMETRY_COLUMNS) + list(dict.fromkeys(a for p in parts for a in p.arrays))
        for name in names:
            values = [getattr(p, name) if name in GEOMETRY_COLUMNS else p.get(name) for p in parts]
            present = [v is not None for v in values]
            if any(present) and not all(present):
                missing = ", ".join(p.source or f"part {i + 1}" for i, p in enumerate(parts) if not present[i])
                raise InputFileError(missing, f"has no '{name}' while the other data sets have it")
            if all(present):
                joined[name] = np.concatenate(values, axis=-1)
        return cls(**joined, metadata=dict(parts[0].metadata), source=" + ".join(p.source for p in parts))
