"""A micro-polarizer sensor's raw mosaic: every pixel sits behind a wire-grid analyser, four angles in a 2x2
superpixel. From the four intensities I(theta) = (S0 + S1 cos 2 theta + S2 sin 2 theta) / 2 of ideal analysers the
linear Stokes parameters follow by least squares (for 0, 45, 90 and 135 deg: S0 = (I0 + I45 + I90 + I135) / 2,
S1 = I0 - I90, S2 = I45 - I135); DoLP = sqrt(S1^2 + S2^2) / S0 and AoP = atan2(S2, S1) / 2, measured from the
sensor's x axis (its rows) towards its y axis, in [0, 180) deg.

Two ways to put the four channels on one grid: ``superpixels`` (each 2x2 block is one pixel of half the
resolution: no interpolation, the four analysers 1 pixel apart) and ``demosaic`` (bilinear: each channel
interpolated to every pixel from its nearest samples, edges mirrored; polanalyser's ``COLOR_PolarMono`` is the same
interpolation through OpenCV's Bayer routines).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputFileError


@dataclass(frozen=True)
class Layout:
    """The analyser angle (deg) of each pixel of the 2x2 superpixel: ``angles[row][column]``."""

    name: str
    angles: tuple[tuple[float, float], tuple[float, float]]

    def offset(self, angle: float) -> tuple[int, int]:
        """(row, column) of ``angle``'s pixel in the superpixel."""
        for r in range(2):
            for c in range(2):
                if self.angles[r][c] == angle:
                    return r, c
        raise ValueError(f"{self.name}: no analyser at {angle:g} deg")

    @property
    def order(self) -> tuple[float, ...]:
        """The four angles, ascending."""
        return tuple(sorted(a for row in self.angles for a in row))


# Sony IMX250MZR (as documented by Sony and in polanalyser): 90 45 over 135 0
IMX250MZR = Layout("IMX250MZR", ((90.0, 45.0), (135.0, 0.0)))


def read_raw_frame(path) -> np.ndarray:
    """A raw mosaic from an 8- or 16-bit single-channel image file (PNG, TIFF) as a (H, W) array; one line for a
    missing, unreadable, colour or odd-sized image."""
    from PIL import Image, UnidentifiedImageError

    path = Path(path)
    if not path.is_file():
        raise InputFileError(path, "file not found")
    try:
        with Image.open(path) as image:
            raw = np.asarray(image)
    except (UnidentifiedImageError, OSError) as exc:
        raise InputFileError(path, f"not an image ({exc})") from None
    if raw.ndim != 2:
        raise InputFileError(path, f"a raw mosaic has one channel; this image has shape {raw.shape}")
    if raw.shape[0] % 2 or raw.shape[1] % 2 or min(raw.shape) < 4:
        raise InputFileError(path, f"a raw mosaic needs an even number of rows and columns (at least 4); {raw.shape}")
    return raw


def superpixels(raw: np.ndarray, layout: Layout = IMX250MZR) -> dict[float, np.ndarray]:
    """{angle: (H/2, W/2) intensities}: each 2x2 superpixel's four analysers as one pixel."""
    raw = np.asarray(raw, float)
    return {a: raw[layout.offset(a)[0]::2, layout.offset(a)[1]::2] for a in layout.order}


def demosaic(raw: np.ndarray, layout: Layout = IMX250MZR) -> dict[float, np.ndarray]:
    """{angle: (H, W) intensities}: each channel bilinearly interpolated to every pixel (its own samples kept; a
    pixel between two samples of a row or column takes their mean, one between four diagonal samples theirs), the
    image mirrored at its edges."""
    raw = np.asarray(raw, float)
    h, w = raw.shape
    out = {}
    for angle in layout.order:
        r0, c0 = layout.offset(angle)
        sparse = np.zeros((h, w))
        sparse[r0::2, c0::2] = raw[r0::2, c0::2]
        padded = np.pad(sparse, 2, mode="reflect")
        # the bilinear kernel on a 1-in-4 lattice: samples weigh 1, row/column neighbours 1/2, diagonals 1/4
        kernel = np.array([[0.25, 0.5, 0.25], [0.5, 1.0, 0.5], [0.25, 0.5, 0.25]])
        filled = sum(kernel[i, j] * padded[1 + i:1 + i + h, 1 + j:1 + j + w] for i in range(3) for j in range(3))
        out[angle] = filled
    return out


def linear_stokes(channels: dict[float, np.ndarray]) -> np.ndarray:
    """(3, ...) linear Stokes parameters S0, S1, S2 from intensities behind ideal linear analysers at the angles
    (deg) of ``channels``' keys (least squares; exact for four angles 45 deg apart)."""
    angles = np.radians(np.array(list(channels), float))
    design = 0.5 * np.stack([np.ones_like(angles), np.cos(2 * angles), np.sin(2 * angles)], axis=1)  # (N, 3)
    intensities = np.stack([np.asarray(v, float) for v in channels.values()])  # (N, ...)
    return np.tensordot(np.linalg.pinv(design), intensities, axes=(1, 0))


def dolp(stokes: np.ndarray) -> np.ndarray:
    """sqrt(S1^2 + S2^2) / S0 (NaN where S0 <= 0)."""
    s0 = np.where(stokes[0] > 0, stokes[0], np.nan)
    return np.hypot(stokes[1], stokes[2]) / s0


def aop_deg(stokes: np.ndarray) -> np.ndarray:
    """atan2(S2, S1) / 2 in [0, 180) deg, from the sensor's x axis towards its y axis."""
    return np.degrees(0.5 * np.arctan2(stokes[2], stokes[1])) % 180.0


@dataclass
class StokesMaps:
    """A raw frame's linear Stokes maps (3, H', W'), with ``dolp`` and ``aop_deg`` (from the sensor's x axis towards
    its y axis); ``method``: ``superpixel`` (half resolution) or ``bilinear`` (full resolution)."""

    stokes: np.ndarray
    method: str
    source: str = ""

    @property
    def dolp(self) -> np.ndarray:
        """Degree of linear polarization per pixel."""
        return dolp(self.stokes)

    @property
    def aop_deg(self) -> np.ndarray:
        """Angle of polarization per pixel, [0, 180) deg."""
        return aop_deg(self.stokes)

    def to_json(self) -> dict:
        """What was read and the maps' statistics: shape, method, source, S0's mean and DoLP's quantiles."""
        finite = self.dolp[np.isfinite(self.dolp)]
        q05, median, q95 = (float(x) for x in np.percentile(finite, [5, 50, 95])) if finite.size else (None,) * 3
        return {"source": self.source, "method": self.method, "shape": list(self.stokes.shape[1:]),
                "s0_mean_counts": float(np.mean(self.stokes[0])), "dolp": {"median": median, "q05": q05, "q95": q95}}

    def region(self, centre_xy: tuple[float, float], radius: float) -> dict:
        """The mean Stokes vector, DoLP and AoP (of the mean vector) in a disc (centre and radius in raw pixels)."""
        scale = 2.0 if self.method == "superpixel" else 1.0
        yy, xx = np.mgrid[0:self.stokes.shape[1], 0:self.stokes.shape[2]]
        inside = (xx * scale - centre_xy[0]) ** 2 + (yy * scale - centre_xy[1]) ** 2 < radius**2
        mean = self.stokes[:, inside].mean(axis=1)
        return {"pixels": int(inside.sum()), "s0": float(mean[0]), "dolp": float(dolp(mean)), "aop_deg": float(aop_deg(mean))}


def stokes_maps(raw, layout: Layout = IMX250MZR, method: str = "superpixel", source: str = "") -> StokesMaps:
    """The Stokes maps of a raw mosaic (an array, or an image file's path)."""
    if not isinstance(raw, np.ndarray):
        source, raw = str(raw), read_raw_frame(raw)
    if method not in ("superpixel", "bilinear"):
        raise ValueError(f"method '{method}': superpixel or bilinear")
    channels = superpixels(raw, layout) if method == "superpixel" else demosaic(raw, layout)
    return StokesMaps(linear_stokes(channels), method, source)
