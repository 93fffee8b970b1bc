"""Observables: the measured quantities a likelihood compares with the model, one module each."""

from __future__ import annotations

from ..errors import ParameterError
from .aop import AoP
from .base import Observable
from .brdf import BRDF
from .dop import DOP
from .mueller import Mueller
from .stokes import Stokes

OBSERVABLES: dict[str, Observable] = {o.name: o for o in (DOP(), BRDF(), AoP(), Stokes(), Mueller())}
# channel names accepted where an observable is meant (``--observables q,u`` as before)
ALIASES = {"q": "stokes", "u": "stokes"}
DEFAULT = ("dop", "brdf")


def get(name: str) -> Observable:
    key = ALIASES.get(name, name)
    if key not in OBSERVABLES:
        raise ParameterError(f"unknown observable '{name}' (use {', '.join(OBSERVABLES)})")
    return OBSERVABLES[key]


__all__ = ["OBSERVABLES", "Observable", "get", "DEFAULT"]
