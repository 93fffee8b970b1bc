"""A data set of polarimetric measurements: the geometries and whatever observables a file holds."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InputFileError
from ..physics.geometry import Geometry

GEOMETRY_COLUMNS = ("theta_i", "theta_r", "dphi", "wavelength_um")
MUELLER_COLUMNS = tuple(f"m{i}{j}" for i in range(1, 5) for j in range(1, 5))[1:]  # m12 ... m44 = M_ij / M_11
OBSERVABLE_COLUMNS = (("dop", "dop_err", "brdf", "brdf_err", "s0", "s1", "s2", "s3", "aop", "aop_err")
                      + MUELLER_COLUMNS + ("m_err",) + tuple(f"{m}_err" for m in MUELLER_COLUMNS))
KNOWN_COLUMNS = GEOMETRY_COLUMNS + OBSERVABLE_COLUMNS


@dataclass
class Dataset:
    """Measurements at N geometries.  Absent observables are ``None``; angles in degrees."""

    theta_i: np.ndarray
    theta_r: np.ndarray
    dphi: np.ndarray
    wavelength_um: np.ndarray | None = None
    dop: np.ndarray | None = None
    dop_err: np.ndarray | None = None
    brdf: np.ndarray | None = None  # sr^-1
    brdf_err: np.ndarray | None = None
    stokes: np.ndarray | None = None  # (4, N): s0..s3 for unpolarized incidence (s3 may be 0)
    aop: np.ndarray | None = None  # deg
    aop_err: np.ndarray | None = None
    mueller: np.ndarray | None = None  # (4, 4, N) BRDF Mueller matrix (sr^-1; M_11 = 1 when no BRDF was measured)
    mueller_err: np.ndarray | None = None  # (4, 4, N) 1-sigma errors of the normalised elements m_ij (M_11's unused)
    metadata: dict = field(default_factory=dict)
    source: str = ""

    def __len__(self):
        return len(self.theta_i)

    # Normalised Stokes parameters q = S1/S0, u = S2/S0 (s-polarized light has q > 0).
    @property
    def q(self):
        """Normalised Stokes q = S1/S0 per row (None without Stokes columns)."""
        return None if self.stokes is None else self.stokes[1] / np.where(self.stokes[0] > 0, self.stokes[0], np.inf)

    @property
    def u(self):
        """Normalised Stokes u = S2/S0 per row (None without Stokes columns)."""
        return None if self.stokes is None else self.stokes[2] / np.where(self.stokes[0] > 0, self.stokes[0], np.inf)

    q_err = None
    u_err = None

    @property
    def geometry(self) -> Geometry:
        """The rows' geometry (angles and wavelength), computed once."""
        if not hasattr(self, "_geometry"):
            self._geometry = Geometry(self.theta_i, self.theta_r, self.dphi, self.wavelength_um)
        return self._geometry

    @property
    def observables(self) -> list[str]:
        """The observables the data hold: dop, brdf, aop, stokes, mueller."""
        names = [n for n in ("dop", "brdf", "aop") if getattr(self, n) is not None]
        if self.stokes is not None:
            names.append("stokes")
        if self.mueller is not None:
            names.append("mueller")
        return names

    def select(self, mask) -> "Dataset":
        """A subset of the rows (boolean mask or indices)."""
        idx = np.arange(len(self))[mask]
        changes = {name: None if (value := getattr(self, name)) is None else np.take(value, idx, axis=axis)
                   for name, axis in _ROW_ARRAYS.items()}
        return replace(self, **changes)

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
        arrays = {}
        for name, axis in _ROW_ARRAYS.items():
            values = [getattr(p, name) for p in parts]
            present = [v is not None for v in values]
            if any(present) and not all(present):
                missing = ", ".join(p.source or f"part {i + 1}" for i, p in enumerate(parts) if getattr(p, name) is None)
                raise InputFileError(missing, f"has no '{name}' while the other data sets have it")
            arrays[name] = np.concatenate(values, axis=axis) if all(present) else None
        return cls(**arrays, metadata=dict(parts[0].metadata), source=" + ".join(p.source for p in parts))


# every per-row array of a Dataset and the axis its rows lie on
_ROW_ARRAYS = {"theta_i": 0, "theta_r": 0, "dphi": 0, "wavelength_um": 0, "dop": 0, "dop_err": 0, "brdf": 0,
               "brdf_err": 0, "stokes": 1, "aop": 0, "aop_err": 0, "mueller": 2, "mueller_err": 2}
