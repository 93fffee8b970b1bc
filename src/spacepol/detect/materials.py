"""Named spacecraft surface materials for light-curve inversion (``aluminium``, ``kapton``, ``white_paint``,
``solar_glass``): each ``specular+smith+lambertian`` with physical priors at the camera's band (indices from
``data/nk`` where tabulated).

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import UnknownNameError
from ..io.nk import RefractiveIndex
from ..paths import bundled
from ..priors import Prior, TruncatedNormal, Uniform

MODEL = "specular+smith+lambertian"


@dataclass(frozen=True)
class Material:
    """A named material: its ``model`` spec, the ``priors`` of that model's parameters (every one given), and what it
    stands for in words (``description``)."""

    name: str
    model: str
    priors: dict[str, Prior]
    description: str


def _index(table: str, wavelength_um: float) -> complex:
    index = RefractiveIndex(bundled("nk", table))
    low, high = index.range_um
    return index(min(max(wavelength_um, low), high))


def _aluminium(wavelength_um: float) -> Material:
    nk = _index("main_Al_nk_Rakic.yml", wavelength_um)
    n, k = float(nk.real), float(nk.imag)
    return Material("aluminium", MODEL, {
        "n": TruncatedNormal(n, 0.15 * n, 0.1, 5.0), "k": TruncatedNormal(k, 0.15 * k, 0.0, 20.0),
        "sigma": Uniform(0.02, 0.5), "ks": Uniform(0.6, 1.0), "rho_l": Uniform(0.0, 0.3)},
        f"bare aluminium: n {n:.2f} + {k:.2f}i (Rakic 1995) within 15 %, mostly specular")


def _kapton(wavelength_um: float) -> Material:
    n = float(_index("other_commercial_polymers_Kapton_nk_French.yml", wavelength_um).real)
    return Material("kapton", MODEL, {
        "n": TruncatedNormal(n, 0.05, 1.3, 2.1), "k": Uniform(0.0, 0.05), "sigma": Uniform(0.02, 0.6),
        "ks": Uniform(0.3, 1.0), "rho_l": Uniform(0.0, 0.5)},
        f"polyimide film (MLI): n {n:.2f} (French 2011), glossy, some diffuse light")


def _white_paint(wavelength_um: float) -> Material:
    return Material("white_paint", MODEL, {
        "n": Uniform(1.45, 1.6), "k": Uniform(0.0, 1e-3), "sigma": Uniform(0.1, 0.6), "ks": Uniform(0.0, 0.3),
        "rho_l": Uniform(0.5, 0.95)},
        "white thermal-control paint: a dielectric binder, bright diffuse pigment")


def _solar_glass(wavelength_um: float) -> Material:
    return Material("solar_glass", MODEL, {
        "n": Uniform(1.42, 1.55), "k": Uniform(0.0, 1e-3), "sigma": Uniform(0.02, 0.1), "ks": Uniform(0.85, 1.0),
        "rho_l": Uniform(0.0, 0.1)},
        "solar-cell cover glass: smooth, specular, over a dark cell")


LIBRARY = {"aluminium": _aluminium, "kapton": _kapton, "white_paint": _white_paint, "solar_glass": _solar_glass}


def material(name: str, wavelength_um: float) -> Material:
    """The named material with its priors at ``wavelength_um``; an unknown name is one line listing the known."""
    if name not in LIBRARY:
        raise UnknownNameError(f"unknown material '{name}' (known: {', '.join(LIBRARY)})")
    return LIBRARY[name](wavelength_um)
