"""What a posterior says about index-like parameters (a surface's n, n@LAMBDA, an interface's n_pm, a film's
n_film): whether the data determine each one, and whether its value is physical for the material named.

An index counts as determined where its 90 % interval is narrower than ``DETERMINED_WIDTH``; a determined index
outside the material's band is a model failure (the index absorbs a misfit), not a measurement of the material.
"""

from __future__ import annotations

from dataclasses import dataclass

INDEX_LIKE = ("n", "n_pm", "n_film")
DETERMINED_WIDTH = 0.3  # a 90 % interval at least this wide: the data leave the index open


@dataclass(frozen=True)
class IndexFinding:
    """One index-like parameter: its median and 90 % interval, whether the data determine it and, against
    ``band`` (the material's physical range; None: not judged), whether it is physical."""

    name: str
    median: float
    q05: float
    q95: float
    band: tuple[float, float] | None

    @property
    def determined(self) -> bool:
        """The 90 % interval is narrower than ``DETERMINED_WIDTH``."""
        return self.q95 - self.q05 < DETERMINED_WIDTH

    @property
    def physical(self) -> bool | None:
        """The 90 % interval overlaps ``band`` (None without a band or where the data leave the index open)."""
        if self.band is None or not self.determined:
            return None
        return self.q95 >= self.band[0] and self.q05 <= self.band[1]

    @property
    def text(self) -> str:
        """The finding in one sentence."""
        value = f"{self.name} {self.median:.3f} [90 %: {self.q05:.3f}, {self.q95:.3f}]"
        if not self.determined:
            return f"{value}: not determined by the data (90 % interval {self.q95 - self.q05:.2f} wide >= {DETERMINED_WIDTH:g})"
        if self.physical is None:
            return f"{value}: determined by the data"
        lo, hi = self.band
        if self.physical:
            return f"{value}: determined, and physical (inside [{lo:g}, {hi:g}])"
        return (f"{value}: determined, and UNPHYSICAL (outside [{lo:g}, {hi:g}]): the index absorbs a misfit of the "
                "model; it is not a measurement of the material")


def index_findings(parameters: dict, band: tuple[float, float] | None = None) -> list[IndexFinding]:
    """Findings for every index-like entry of ``parameters`` ({name: {"median", "q05", "q95"}}, as summary.json's
    parameters and derived values), ``NAME`` or ``NAME@LAMBDA`` with NAME in ``INDEX_LIKE``."""
    out = []
    for name, q in parameters.items():
        if name.split("@")[0] in INDEX_LIKE:
            out.append(IndexFinding(name, float(q["median"]), float(q["q05"]), float(q["q95"]), band))
    return out


def unphysical(findings: list[IndexFinding]) -> list[IndexFinding]:
    """The determined findings outside their band."""
    return [f for f in findings if f.physical is False]
