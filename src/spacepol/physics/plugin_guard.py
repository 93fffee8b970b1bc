"""Plug-in effects run user code inside every evaluation.  When that code raises, exits or
returns NaN/inf, the user must learn *which* effect did it, in one line, not read a traceback
through spacepol's internals.  Built-in effects are not guarded (their failures are our bugs)."""

from __future__ import annotations

import traceback
from contextlib import contextmanager

import jax
import numpy as np

from ..errors import SpacepolError

HOOKS = ("transform_geometry", "configure", "specular_factor", "modify_specular", "lobe", "modify_stokes", "modify_dop")


class EffectError(SpacepolError):
    """A user's effect raised, exited or returned non-finite values."""


def is_plugin(effect) -> bool:
    """True for an effect defined outside spacepol (a user's plug-in)."""
    return not type(effect).__module__.startswith("spacepol.")


def culprit(effects, exc: BaseException):
    """The plug-in effect whose code is deepest in the traceback of ``exc`` (None if none)."""
    plugins = [e for e in effects if is_plugin(e)]
    if not plugins:
        return None
    found = None
    for frame, _ in traceback.walk_tb(exc.__traceback__):
        owner = frame.f_locals.get("self")
        match = next((e for e in plugins if e is owner), None)
        if match is None:
            module = frame.f_globals.get("__name__")
            match = next((e for e in plugins if type(e).__module__ == module), None)
        found = match or found
    return found


_TRACING_ERRORS = (jax.errors.TracerArrayConversionError, jax.errors.ConcretizationTypeError,
                   jax.errors.TracerBoolConversionError, jax.errors.TracerIntegerConversionError)


def untraceable(effect, exc: BaseException) -> EffectError | None:
    """The EffectError for a hook JAX cannot compile (numpy on traced values, an in-place update, a
    Python branch on a parameter), or None when ``exc`` is another failure."""
    immutable = isinstance(exc, TypeError) and ("immutable" in str(exc) or "does not support item assignment" in str(exc))
    if not (immutable or isinstance(exc, _TRACING_ERRORS)):
        return None
    why = ("updates an array in place (JAX arrays are immutable: write lobe = lobe.at[1:].multiply(f))" if immutable
           else f"uses a traced value where a concrete one is needed ({type(exc).__name__}: numpy calls, float() or "
                "Python if on parameters)")
    return EffectError(f"effect '{effect.name}' ({type(effect).__module__}) cannot be compiled by JAX: it {why}; "
                       "write its hooks with jax.numpy (see spacepol.physics.effect)")


def effect_failure(effect, exc: BaseException) -> EffectError:
    """The EffectError that names a plug-in effect and what it did (raised, exited) instead of a traceback."""
    if isinstance(exc, SystemExit):
        what = f"called sys.exit({exc.code!r})"
    else:
        what = f"raised {type(exc).__name__}: {exc}"
    return EffectError(f"effect '{effect.name}' ({type(effect).__module__}) {what}")


def _finite(value) -> bool:
    if value is None:
        return True
    if hasattr(value, "intensity"):  # DepolarizedLobe
        value = value.intensity
    if hasattr(value, "theta_i"):  # a Geometry
        value = np.concatenate([np.ravel(value.theta_i), np.ravel(value.theta_r)])
    try:
        return bool(np.all(np.isfinite(np.asarray(value, dtype=float))))
    except (TypeError, ValueError):
        return True


@contextmanager
def checking_outputs(effects):
    """Within the block, every hook of every plug-in effect checks that what it returns is finite."""
    patched = []
    for e in effects:
        if not is_plugin(e):
            continue
        for hook in HOOKS:
            original = getattr(e, hook)

            def checked(*args, _original=original, _hook=hook, _effect=e):
                value = _original(*args)
                if not _finite(value):
                    raise EffectError(f"effect '{_effect.name}' ({type(_effect).__module__}) returned non-finite "
                                      f"values (NaN or inf) from {_hook}()")
                return value

            setattr(e, hook, checked)
            patched.append((e, hook))
    try:
        yield
    finally:
        for e, hook in patched:
            delattr(e, hook)
