"""The changes of a model that diagnose weighs: every addition of a registered effect, every
replacement of a slot's member by another of the same slot ("replace shadowing by smith",
"replace body by lambertian") or by an effect that declares it may stand in for it (``Effect.substitutes``),
and every removal of an effect that declares itself removable.
What an effect may do comes from the effect itself (``Effect.slot``, ``removable``, ``applicable``),
so a plug-in takes part like a built-in."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SpacepolError
from ..physics.effect import Effect
from ..physics.model import Model, Prediction
from ..physics.registry import registry
from ..physics.spectral import SpectralModel


@dataclass
class Change:
    """One change of a model that diagnose screens: an effect added, a slot member replaced, or an effect removed,
    with the model after it."""
    kind: str  # "add" | "replace" | "remove"
    effect: str  # the effect added, the slot's new member, or the effect removed
    model: Model  # the model after the change
    replaced: str | None = None

    @property
    def label(self) -> str:
        """The change in words, as diagnose and ladder name it ("add lambertian", "replace shadowing by smith")."""
        if self.kind == "replace":
            return f"replace {self.replaced} by {self.effect}"
        return f"{self.kind} {self.effect}"

    @property
    def verdict(self) -> str:
        """What diagnose's ``verdict`` says: the effect's name for an addition (DESIGN's contract), the
        change itself otherwise."""
        return self.effect if self.kind == "add" else self.label


def apply(model: Model, label: str) -> Model:
    """The model after a change written as ``add E``, ``replace A by B`` or ``remove E``. Over several
    wavelengths the change is made to the inner model, kept over the same wavelengths."""
    if isinstance(model, SpectralModel):
        return model.with_model(apply(model.model, label))
    words = label.split()
    try:
        if words[0] == "add" and len(words) == 2:
            return model + words[1]
        if words[0] == "remove" and len(words) == 2:
            _index(model, words[1])
            return Model([type(e) for e in model.effects if e.name != words[1]])
        if words[0] == "replace" and len(words) == 4 and words[2] == "by":
            i = _index(model, words[1])
            classes = [type(e) for e in model.effects]
            classes[i] = registry.get(words[3])
            return Model(classes)
    except IndexError:
        pass
    raise SpacepolError(f"change '{label}': write 'add E', 'replace A by B' or 'remove E'")


def parse(model: Model, label: str) -> Change:
    """``"add E"`` / ``"E"``, ``"replace A by B"`` or ``"remove E"`` applied to ``model``, as a Change."""
    label = label.strip()
    if " " not in label:
        label = f"add {label}"
    words = label.split()
    new = apply(model, label)
    if words[0] == "replace":
        return Change("replace", words[3], new, replaced=words[1])
    return Change(words[0], words[1], new)


def _index(model: Model, name: str) -> int:
    names = [e.name for e in model.effects]
    if name not in names:
        raise SpacepolError(f"change: '{name}' is not in model {model.name}")
    return names.index(name)


def changes(model: Model, data, names=None) -> list[Change]:
    """Every change of ``model`` that composes and that the data allow; ``names`` restricts the
    effects considered (added, brought in or removed). Effects without a slot (pure additions) already in
    the model may be removed or replaced by another pure addition: an addition taken early, while another
    part of the model was still wrong, can then give way to the one the data prefer once the rest is right."""
    present = [e.name for e in model.effects]
    additions = [e.name for e in model.effects if not e.slot and not e.essential]
    out: list[Change] = []
    for name in names or registry.names():
        if name in present:
            continue
        cls = registry.get(name)
        if cls().applicable(data) is not None:
            continue
        replaced = [e.name for e in model.effects if cls.slot and e.slot == cls.slot] if cls.slot else additions
        replaced += [e.name for e in model.effects if e.name in cls.substitutes and e.name not in replaced]
        for change in [("add", None)] + [("replace", old) for old in replaced]:
            try:
                label = f"add {name}" if change[0] == "add" else f"replace {change[1]} by {name}"
                out.append(Change(change[0], name, apply(model, label), replaced=change[1]))
            except SpacepolError:
                continue  # does not compose (e.g. smith beside shadowing, ggx without specular)
    for e in model.effects:
        if (e.removable or not (e.slot or e.essential)) and (names is None or e.name in names):
            try:
                out.append(Change("remove", e.name, apply(model, f"remove {e.name}")))
            except SpacepolError:
                continue  # another effect needs it
    return out


# the hooks through which an effect changes the Stokes vector or Mueller matrix (``physics.effect``); ``modify_dop``
# changes only the measured DOP read from them
_LIGHT_HOOKS = ("transform_geometry", "configure", "specular_factor", "modify_specular", "lobe", "modify_stokes")


def measured_dop_only(effect_class) -> bool:
    """Whether an effect changes the measured DOP alone (its only hook is ``modify_dop``, as a DOP estimator's bias):
    it cannot change any observable computed from the Stokes vector or Mueller matrix."""
    cls = effect_class if isinstance(effect_class, type) else type(effect_class)  # a plug-in may be an instance
    return (cls.modify_dop is not Effect.modify_dop
            and all(getattr(cls, hook) is getattr(Effect, hook) for hook in _LIGHT_HOOKS))


class _Probe(Prediction):
    """A prediction that records whether the measured DOP was read."""

    def __getattribute__(self, name):
        if name == "dop":
            object.__setattr__(self, "dop_read", True)
        return super().__getattribute__(name)


def reads_measured_dop(observable) -> bool:
    """Whether ``observable``'s prediction reads the model's measured DOP (``Prediction.dop``), found by running its
    ``predict`` on a probe that records what it reads (so a plug-in observable needs to declare nothing); one that
    fails on the probe counts as reading it."""
    stokes = np.array([[1.0], [0.3], [0.2], [0.1]])
    mueller = np.eye(4)[:, :, None] * 0.5
    mueller[:, 0] = stokes
    probe = _Probe(stokes=stokes, dop=np.array([0.37]), mueller=mueller)
    try:
        observable.predict(probe)
    except Exception:
        return True
    return bool(getattr(probe, "dop_read", False))


# why ``blind_changes`` are not screened, as diagnose's progress and JSON say it
BLIND_REASON = ("it changes only the measured DOP, which none of the fitted observables reads: its fit would differ "
                "from the model's by its prior alone")


def blind_changes(candidates: list[Change], fitted) -> list[Change]:
    """The additions and replacements among ``candidates`` that cannot change the likelihood of the ``fitted``
    observables: the new effect changes the measured DOP alone (``measured_dop_only``) and no fitted observable
    reads it (the normalised Mueller matrix, BRDF or Stokes data). Their fit would differ from the model's by their
    prior alone."""
    if any(reads_measured_dop(o) for o in fitted):
        return []
    return [c for c in candidates if c.kind != "remove" and measured_dop_only(registry.get(c.effect))]


def slot_alternatives(model: Model, data, slots, names=None) -> list[str]:
    """The changes of ``model`` that put another member into each of ``slots``, fill it when it is empty
    or empty it: what the data must be able to tell from the member the path chose. (A second member
    beside a filled slot's is an addition, not an alternative.)"""
    filled = {e.slot for e in model.effects if e.slot}
    out = []
    for change in changes(model, data, names):
        cls = registry.get(change.effect)
        if cls.slot not in slots or (change.kind == "add" and cls.slot in filled):
            continue
        out.append(change.label)
    return out


def start_points(base_best: dict, change: Change, posterior) -> np.ndarray:
    """Where the optimiser starts the changed model: at the base model's optimum, the new effect's own
    parameters at its ``neutral`` values (where it changes nothing), its default, the prior's ends and
    middle; a parameter that refines one of the base model's (``splits``) at that value; for a
    replacement the new member's intensity at the old member's (a diffuse albedo carried over); and for an
    addition beside a member of its own slot, one more row with that member's intensity moved to the new one
    (the two share what the old one fitted alone: from the base optimum a local search cannot reach that trade,
    since at first every step of the new intensity adds light the old one already accounts for)."""
    effect = registry.get(change.effect)
    params = {p.name: p for p in change.model.parameters}
    carried, emptied = {}, {}
    if change.kind == "replace":
        old = registry.get(change.replaced)
        if effect.intensity and old.intensity in base_best:
            carried[effect.intensity] = base_best[old.intensity]
    if change.kind == "add" and effect.slot and effect.intensity:
        mate = next((e for e in change.model.effects if e.slot == effect.slot and e.name != effect.name
                     and e.intensity in base_best), None)
        if mate is not None:
            carried[effect.intensity] = base_best[mate.intensity]
            emptied[mate.intensity] = mate.neutral.get(mate.intensity, 0.0)
    rows = []
    for option in range(6 if emptied else 5):
        row = []
        for name in posterior.priors.names:
            if name in base_best:
                row.append(emptied[name] if option == 5 and name in emptied else base_best[name])
                continue
            lo, hi = posterior.priors.priors[name].bounds
            default = params[name].default if name in params else 0.5 * (lo + hi)
            bare, at, label = name.partition("@")  # n_film@0.633 refines n@0.633 over several wavelengths
            refined = effect.splits.get(bare) if change.kind != "remove" else None
            refined = f"{refined}{at}{label}" if refined else None
            if refined in base_best:
                row.append(base_best[refined])
            else:
                # option 5 (the slot mate emptied) carries over as option 4 does
                row.append([effect.neutral.get(bare, lo), default, hi, 0.5 * (lo + hi), carried.get(name, default)][min(option, 4)])
        rows.append(row)
    bounds = posterior.priors.bounds
    return np.clip(np.array(rows, float), bounds[:, 0], bounds[:, 1])


def separating_measurement(a: str, b: str) -> str | None:
    """What separates two effects declared twins (by either of them), or None if neither declares it."""
    ea, eb = registry.get(a), registry.get(b)
    return ea.twins.get(b) or eb.twins.get(a)


def separating_observables(a: str, b: str) -> tuple:
    """The observables whose fit separates twins ``a`` and ``b``, as either declares them (``Effect.separated_by``)."""
    ea, eb = registry.get(a), registry.get(b)
    return tuple(ea.separated_by.get(b, ())) + tuple(eb.separated_by.get(a, ()))
