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


def default_for(present: list[str]) -> tuple[list[str], dict[str, str]]:
    """Every present observable except those another present one contains (each measured number is
    counted once): ``(chosen, {left out: the observable holding it})``. BRDF is always independent."""
    chosen = [n for n in present if not any(n in OBSERVABLES[h].contains for h in present)]
    left_out = {n: next(h for h in chosen if n in OBSERVABLES[h].contains) for n in present if n not in chosen}
    return chosen, left_out


def get(name: str) -> Observable:
    """The registered observable of that name (or alias); one clear error for an unknown one."""
    key = ALIASES.get(name, name)
    if key not in OBSERVABLES:
        raise ParameterError(f"unknown observable '{name}' (use {', '.join(OBSERVABLES)})")
    return OBSERVABLES[key]


__all__ = ["OBSERVABLES", "Observable", "get", "default_for"]
