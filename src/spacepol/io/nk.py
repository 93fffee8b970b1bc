"""Optical constants from refractiveindex.info database files (CC0; ``data/nk/``).

Supports the entry types the bundled files use: ``tabulated nk``, ``tabulated n`` with
``tabulated k``, and ``formula 1`` (Sellmeier).  Wavelengths in micrometres; interpolation
is linear and outside the tabulated range is an error, not an extrapolation.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import InputFileError


def _blocks(path: Path):
    """Yield (type, fields dict, data rows) for each entry under DATA:."""
    lines = path.read_text(encoding="utf-8").splitlines()
    entries, current, in_data = [], None, False
    for line in lines:
        stripped = line.strip()
        if stripped.startswith("- type:"):
            current = {"type": stripped.split(":", 1)[1].strip(), "rows": []}
            entries.append(current)
            in_data = False
        elif current is None:
            continue
        elif stripped.startswith("data:"):
            in_data = True
        elif in_data and stripped and stripped[0].isdigit():
            current["rows"].append([float(x) for x in stripped.split()])
        elif ":" in stripped and not line.startswith(" " * 8):
            key, value = stripped.split(":", 1)
            current[key.strip()] = value.strip()
            in_data = False
    return entries


class RefractiveIndex:
    """N(lambda) = n + ik of one material."""

    def __init__(self, path):
        self.path = Path(path)
        if not self.path.is_file():
            raise InputFileError(self.path, "file not found")
        self._n = self._k = None
        self._formula = None
        for entry in _blocks(self.path):
            kind, rows = entry["type"], np.asarray(entry["rows"])
            if kind == "tabulated nk":
                self._n, self._k = rows[:, [0, 1]], rows[:, [0, 2]]
            elif kind == "tabulated n":
                self._n = rows
            elif kind == "tabulated k":
                self._k = rows
            elif kind == "formula 1":
                coeffs = [float(c) for c in entry["coefficients"].split()]
                lo, hi = (float(x) for x in entry["wavelength_range"].split())
                self._formula = (coeffs, lo, hi)
            else:
                raise InputFileError(self.path, f"unsupported entry type '{kind}'")
        if self._n is None and self._formula is None:
            raise InputFileError(self.path, "no refractive index data found")

    @property
    def range_um(self) -> tuple[float, float]:
        """(shortest, longest) wavelength in um at which the file gives n."""
        if self._formula is not None:
            return self._formula[1], self._formula[2]
        return float(self._n[0, 0]), float(self._n[-1, 0])

    def __call__(self, wavelength_um):
        wl = np.asarray(wavelength_um, dtype=float)
        if self._formula is not None:
            coeffs, lo, hi = self._formula
            self._check_range(wl, lo, hi)
            w2 = wl**2
            n2 = 1.0 + coeffs[0] + sum(coeffs[i] * w2 / (w2 - coeffs[i + 1] ** 2) for i in range(1, len(coeffs) - 1, 2))
            n = np.sqrt(n2)
        else:
            self._check_range(wl, self._n[0, 0], self._n[-1, 0])
            n = np.interp(wl, self._n[:, 0], self._n[:, 1])
        k = np.zeros_like(n) if self._k is None else np.interp(wl, self._k[:, 0], self._k[:, 1], left=np.nan, right=np.nan)
        if np.any(np.isnan(k)):
            raise InputFileError(self.path, f"k not tabulated at {wl} um")
        return n + 1j * k

    def _check_range(self, wl, lo, hi):
        if np.any((wl < lo) | (wl > hi)):
            raise InputFileError(self.path, f"wavelength {wl} um outside the tabulated range [{lo}, {hi}] um")
