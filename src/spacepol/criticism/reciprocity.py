"""Reciprocity (Helmholtz): swapping source and detector leaves a BRDF unchanged and transposes its
Mueller matrix, M(theta_r -> theta_i, -dphi) = Q M(theta_i -> theta_r, dphi)^T Q with Q = diag(1, 1, -1, 1) in
spacepol's frames; how far a model or a measurement is from it, and the mirror asymmetry of pairs (dphi, -dphi)
that an isotropic sample must measure equal.

The reasoning behind it, and what was measured: the internals page of the documentation (``docs/internals.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..infer.measured_noise import RECIPROCITY_SIGNS, mirror_pairs, reciprocal_pairs, sd_from_pair_differences
from ..observables.mueller import GROUPS, index
from ..physics.geometry import Geometry

Q = np.diag(RECIPROCITY_SIGNS)


def reciprocal_image(mueller) -> np.ndarray:
    """Q M^T Q for (4, 4, ...) Mueller arrays: what the swapped geometry must measure."""
    return np.einsum("ij,jk...,kl->il...", Q, np.swapaxes(mueller, 0, 1), Q)


def swapped(geometry: Geometry) -> Geometry:
    """Source and detector exchanged: theta_i <-> theta_r, dphi -> -dphi."""
    return Geometry(geometry.theta_r, geometry.theta_i, -geometry.dphi, geometry.wavelength_um)


def model_violation(model, params: dict, geometry: Geometry, max_angle_deg: float = 89.0) -> dict:
    """How far ``model`` at ``params`` is from reciprocal at the geometries (those whose swapped incidence
    angle is below ``max_angle_deg``): the relative BRDF change |f(r->i) / f(i->r) - 1| and the largest
    normalised element difference max_ij |m(r->i) - (D m(i->r)^T D)|, as median and 95th percentile."""
    keep = geometry.theta_r < max_angle_deg
    geo = Geometry(geometry.theta_i[keep], geometry.theta_r[keep], geometry.dphi[keep],
                   None if geometry.wavelength_um is None else geometry.wavelength_um[keep])
    forward = model.evaluate(params, geo, mueller=True, check=False).mueller
    backward = model.evaluate(params, swapped(geo), mueller=True, check=False).mueller
    return _compare(forward, backward)


def _compare(forward, backward) -> dict:
    f0, b0 = forward[0, 0], backward[0, 0]
    ok = (f0 > 0) & (b0 > 0)
    brdf = np.abs(b0[ok] / f0[ok] - 1.0)
    image = reciprocal_image(forward[..., ok] / f0[ok])
    diff = backward[..., ok] / b0[ok] - image
    elements = np.max(np.abs(diff), axis=(0, 1))
    return {"element_rms": float(np.sqrt(np.sum(diff**2) / (15 * max(int(ok.sum()), 1)))),  # compare with sqrt(2) x noise
            "brdf_relative_median": float(np.median(brdf)), "brdf_relative_p95": float(np.percentile(brdf, 95)),
            "element_median": float(np.median(elements)), "element_p95": float(np.percentile(elements, 95)),
            "n_geometries": int(ok.sum())}


data_pairs = reciprocal_pairs  # the measured geometries that are each other's swap (infer.measured_noise)


def data_violation(data, pairs: np.ndarray | None = None) -> dict:
    """Reciprocity of the measurement itself on its swapped pairs (``data_pairs``): the BRDF's relative
    difference and the normalised elements' largest difference per pair, median and 95th percentile.
    Needs the Mueller matrix."""
    pairs = data_pairs(data) if pairs is None else pairs
    if len(pairs) == 0 or data.mueller is None:
        return {"n_pairs": int(len(pairs))}
    forward, backward = data.mueller[..., pairs[:, 0]], data.mueller[..., pairs[:, 1]]  # sr^-1 (M_11 = BRDF)
    out = _compare(forward, backward)
    out.update({"n_pairs": int(len(pairs)), "n_self_pairs": int(np.sum(pairs[:, 0] == pairs[:, 1]))})
    return out


# Mirror symmetry of an isotropic surface: M(theta_i, theta_r, -dphi) = D M(theta_i, theta_r, dphi) D
MIRROR = np.diag([1.0, 1.0, -1.0, -1.0])
# Reciprocity and mirror symmetry together, where theta_i = theta_r: M = S M^T S at the same dphi
SYMMETRIC_SIGNS = np.diag(RECIPROCITY_SIGNS) @ MIRROR
_PAIRS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))


def symmetry_checks(data, tolerance_deg: float = 0.01) -> dict:
    """What the measurement says about its own symmetries, without any model (needs the Mueller matrix).

    ``mirror``: over the mirror pairs, per normalised element the RMS of m(b) - D m(a) D (what an isotropic sample
    gives: ~sqrt(2) x the element's noise) and of m(b) - m(a) (the scale of the structure that mirror symmetry
    constrains); ``noise_from_mirror`` = the first / sqrt(2), an upper bound of the noise (anisotropy adds to it).
    ``equal_angles``: at theta_i = theta_r out of the plane, reciprocity and mirror symmetry together require
    m_ji = s_i s_j m_ij (s = diag(1, 1, 1, -1) in DESIGN's basis: m31 = m13, m32 = m23, m41 = -m14, m42 = -m24,
    m43 = -m34, m21 = m12); per element pair the RMS of the part that breaks it, (m_ji - s_i s_j m_ij) / 2 (noise
    alone gives ~noise / sqrt(2)), and of the part that obeys the opposite sign. A broken relation that the opposite
    sign obeys at the noise level is structure that no reciprocal, mirror-symmetric model in this basis can fit."""
    if data.mueller is None:
        return {}
    m = _normalised(data)
    names = [f"m{i + 1}{j + 1}" for i in range(4) for j in range(4)][1:]
    out: dict = {}
    pairs = mirror_pairs(data, tolerance_deg)
    if len(pairs):
        a, b = pairs.T
        symmetric = _mirror_differences(m, pairs)
        plain = m[..., b] - m[..., a]
        elements = {}
        for name in names:
            i, j = int(name[1]) - 1, int(name[2]) - 1
            mirrored = _rms(symmetric[i, j])
            elements[name] = {"rms_mirrored": mirrored, "rms_unmirrored": _rms(plain[i, j]),
                              "noise_from_mirror": mirrored / np.sqrt(2.0)}
        out["mirror"] = {"n_pairs": int(len(pairs)), "elements": elements}
    equal = np.isclose(data.theta_i, data.theta_r, atol=tolerance_deg) & (np.abs(np.sin(np.radians(data.dphi))) > 1e-3)
    if equal.any():
        s = np.diag(SYMMETRIC_SIGNS)
        rows = {}
        for i, j in _PAIRS:
            x, y = m[i, j, equal], m[j, i, equal]
            rows[f"m{i + 1}{j + 1}/m{j + 1}{i + 1}"] = {"rms_breaking": _rms((y - s[i] * s[j] * x) / 2),
                                                      "rms_opposite_sign": _rms((y + s[i] * s[j] * x) / 2)}
        out["equal_angles"] = {"n_rows": int(equal.sum()), "pairs": rows}
    return out


@dataclass(frozen=True)
class MirrorAsymmetry:
    """Per mirror pair (``pairs``, row indices a, b) the asymmetry chi^2 = sum over the 15 normalised elements of
    (m(b) - D m(a) D)^2 / (2 sigma^2), sigma the element's measured noise (15 degrees of freedom under isotropy);
    ``flagged``: the pairs beyond the ``alpha`` quantile, Bonferroni over the pairs (what an isotropic sample at that
    noise gives by chance in fewer than ``alpha`` of measurements)."""

    pairs: np.ndarray
    chi2: np.ndarray
    flagged: np.ndarray
    alpha: float

    @property
    def rows(self) -> np.ndarray:
        """The rows of the flagged pairs, both members, sorted."""
        return np.unique(self.pairs[self.flagged].ravel())

    @property
    def excess(self) -> float:
        """Mean chi^2 per degree of freedom over all pairs: 1 for an isotropic sample at the measured noise."""
        return float(np.mean(self.chi2) / 15.0) if len(self.chi2) else float("nan")

    @property
    def text(self) -> str:
        """The finding in one sentence."""
        return (f"Mirror asymmetry against the measured noise, no model: {len(self.pairs)} pairs measured at dphi and "
                f"-dphi, chi^2 per degree of freedom {self.excess:.2f} (1 for an isotropic sample); "
                f"{int(self.flagged.sum())} pairs ({len(self.rows)} rows) differ beyond what the noise gives by chance "
                f"(p < {self.alpha:g}, Bonferroni over the pairs): the sample is anisotropic there")


def mirror_asymmetry(data, noise: dict, alpha: float = 1e-3, tolerance_deg: float = 0.01) -> MirrorAsymmetry:
    """The mirror pairs' asymmetry against ``noise`` ({group: the measured noise of the normalised elements},
    groups of ``observables.mueller.GROUPS``; a group may be given as ``sigma_m_GROUP`` too). Needs the Mueller matrix."""
    from scipy.stats import chi2 as chi2_distribution

    if data.mueller is None:
        raise ValueError("mirror_asymmetry needs the Mueller matrix")
    sigma = np.ones((4, 4))
    for group, members in GROUPS.items():
        value = noise.get(group, noise.get(f"sigma_m_{group}"))
        if value is None:
            raise ValueError(f"mirror_asymmetry: no noise for the {group} group")
        for e in members:
            sigma[index(e)] = value
    pairs = mirror_pairs(data, tolerance_deg)
    d = _mirror_differences(_normalised(data), pairs)
    chi2 = (d**2 / (2 * sigma[..., None] ** 2)).reshape(16, -1)[1:].sum(axis=0)
    limit = chi2_distribution.isf(alpha / max(len(pairs), 1), 15)
    return MirrorAsymmetry(pairs=pairs, chi2=chi2, flagged=chi2 > limit, alpha=alpha)


EXIT_EDGES_DEG = (0.0, 20.0, 40.0, 60.0, 90.0)
MIN_SCATTER_DIFFERENCES = 30  # fewer differences in a bin than this: no figure for it


@dataclass
class MirrorScatter:
    """Per element group, the spread of one measurement of a normalised element, told by the mirror pairs in bins of
    the exit angle |theta_r| (``edges_deg``): the robust SD of m(b) - D m(a) D over sqrt(2) (median absolute
    deviation, scaled to a Gaussian's SD). Noise and anisotropy both add to it, so it is an upper bound of the noise
    in each bin; unlike the reciprocal pairs, which a measurement holds at few angles, it covers every exit angle
    with a mirror pair. ``sd[group]`` and ``count[group]``: one value per bin (NaN where a bin holds fewer than
    ``MIN_SCATTER_DIFFERENCES`` differences)."""

    edges_deg: tuple
    sd: dict
    count: dict

    def bin_of(self, theta_r_deg) -> np.ndarray:
        """The bin of each exit angle (|theta_r|; -1 outside the edges)."""
        t = np.abs(np.asarray(theta_r_deg, float))
        edges = np.asarray(self.edges_deg)
        out = np.searchsorted(edges, t, side="right") - 1
        out[t == edges[-1]] = len(edges) - 2
        return np.where((t < edges[0]) | (t > edges[-1]), -1, out)

    def labels(self) -> list[str]:
        """The bins as text ("0-20 deg", ...)."""
        return [f"{lo:g}-{hi:g} deg" for lo, hi in zip(self.edges_deg[:-1], self.edges_deg[1:])]

    def noise_profile(self, data, tolerance_deg: float = 0.01) -> np.ndarray:
        """(3, N): per element group (``GROUPS``' order), the spread at each row's exit angle (linear between the bins'
        centres, the end bins' beyond them; bins without enough mirror pairs skipped) over its mean at the rows of
        ``data``'s reciprocal pairs: the likelihood's noise profile (``Mueller.noise_profile``), whose inferred level
        is then the noise where the reciprocal pairs lie, comparable with what they measure. Fine bins
        (``PROFILE_EDGES_DEG``) follow a steep rise; a robust SD of a bin whose noise varies across it falls short of
        its RMS."""
        rows = np.unique(reciprocal_pairs(data, tolerance_deg))
        if rows.size == 0:
            raise ValueError("a noise profile needs reciprocal pairs to set its level")
        edges = np.asarray(self.edges_deg, float)
        centres = 0.5 * (edges[:-1] + edges[1:])
        exit_deg = np.abs(np.asarray(data.theta_r, float))
        out = np.empty((len(GROUPS), len(data)))
        for g, group in enumerate(GROUPS):
            sd = np.asarray(self.sd[group], float)
            known = np.isfinite(sd)
            if not known.any():
                raise ValueError(f"no exit-angle bin holds enough mirror pairs for the {group} group")
            spread = np.interp(exit_deg, centres[known], sd[known])
            out[g] = spread / spread[rows].mean()
        return out


PROFILE_EDGES_DEG = tuple(float(e) for e in range(0, 91, 10))  # exit-angle bins for ``MirrorScatter.noise_profile``


def mirror_scatter(data, edges_deg=EXIT_EDGES_DEG, tolerance_deg: float = 0.01) -> MirrorScatter:
    """``MirrorScatter`` of ``data`` (one wavelength; needs the Mueller matrix): how the measurement's own spread
    changes with the exit angle, where the reciprocal pairs cannot tell."""
    if data.mueller is None:
        raise ValueError("mirror_scatter needs the Mueller matrix")
    pairs = mirror_pairs(data, tolerance_deg)
    d = _mirror_differences(_normalised(data), pairs)
    scatter = MirrorScatter(edges_deg=tuple(float(e) for e in edges_deg), sd={}, count={})
    bins = scatter.bin_of(np.asarray(data.theta_r, float)[pairs[:, 0]] if len(pairs) else np.empty(0))
    for group, members in GROUPS.items():
        values = np.stack([d[index(e)] for e in members])
        sds, counts = [], []
        for b in range(len(edges_deg) - 1):
            x = values[:, bins == b].ravel()
            x = x[np.isfinite(x)]
            counts.append(int(x.size))
            sds.append(sd_from_pair_differences(x) if x.size >= MIN_SCATTER_DIFFERENCES else float("nan"))
        scatter.sd[group], scatter.count[group] = np.array(sds), np.array(counts)
    return scatter


def symmetry_findings(symmetry: dict, measured: dict | None = None) -> list[str]:
    """In words, what ``symmetry_checks`` found: the noise the mirror pairs bound per element group (beside
    ``measured``, {group: the noise the reciprocal pairs measured}, where given), and the part of the data at
    theta_i = theta_r that no reciprocal, isotropic model in DESIGN's basis can fit."""
    measured = measured or {}
    out = []
    mirror = symmetry.get("mirror")
    if mirror:
        elements = mirror["elements"]
        groups = {g: float(np.sqrt(np.mean([elements[e]["noise_from_mirror"] ** 2 for e in members])))
                  for g, members in GROUPS.items()}
        odd = [e for e in elements if elements[e]["rms_unmirrored"] > 1.3 * elements[e]["rms_mirrored"]]
        out.append(f"Mirror symmetry, no model ({mirror['n_pairs']} pairs measured at dphi and -dphi): the "
                   f"elements odd in dphi ({', '.join(odd)}) differ by "
                   + ", ".join(f"{e} {elements[e]['rms_mirrored']:.3f}" for e in odd)
                   + " RMS once mirrored (unmirrored: " + ", ".join(f"{elements[e]['rms_unmirrored']:.3f}" for e in odd)
                   + "): the sample is isotropic to about the noise. The noise these pairs bound, per group: "
                   + ", ".join(f"{g} {v:.4f}" + (f" (reciprocal pairs: {measured[g]:.4f})" if g in measured else "")
                               for g, v in groups.items())
                   + ": an upper bound (a slight anisotropy adds to it); where it exceeds the reciprocal pairs' figure, the "
                   "misfit ratios against those are at most that much too high.")
    equal = symmetry.get("equal_angles")
    if equal:
        broken = {k: v for k, v in equal["pairs"].items() if v["rms_breaking"] > 1.5 * v["rms_opposite_sign"]}
        kept = {k: v for k, v in equal["pairs"].items() if 1.5 * v["rms_breaking"] < v["rms_opposite_sign"]}
        unclear = {k: v for k, v in equal["pairs"].items() if k not in broken and k not in kept}
        if broken:
            out.append(f"At theta_i = theta_r out of the plane ({equal['n_rows']} rows), reciprocity and mirror symmetry "
                       "together require m31 = m13, m32 = m23, m41 = -m14, m42 = -m24, m43 = -m34 and m21 = m12 in DESIGN's "
                       "basis (SCATMECH's: every reciprocal effect of the library obeys it to rounding). The data break "
                       + ", ".join(f"{k} (the breaking part {v['rms_breaking']:.4f} RMS, the opposite relation's "
                                   f"{v['rms_opposite_sign']:.4f})" for k, v in broken.items())
                       + "; they keep " + (", ".join(f"{k} ({v['rms_breaking']:.4f} vs {v['rms_opposite_sign']:.4f})"
                                                     for k, v in kept.items()) or "none")
                       + ("; within a factor 1.5 either way: " + ", ".join(
                           f"{k} ({v['rms_breaking']:.4f} vs {v['rms_opposite_sign']:.4f})" for k, v in unclear.items())
                          if unclear else "")
                       + ". No reciprocal, isotropic model in this basis can fit the breaking part: it is an anisotropy "
                       "of the sample (Germer & Patrick, Proc. SPIE 8160, 81600D (2011), saw one in sintered PTFE) or a "
                       "difference of basis on the instrument's out-of-plane rows, and it stays in the residuals of every "
                       "model here.")
    return out


def _normalised(data) -> np.ndarray:
    """The measured Mueller matrices over their M_11 (4, 4, N); a row without a positive M_11 gives zeros."""
    return data.mueller / np.where(data.mueller[0, 0] > 0, data.mueller[0, 0], np.inf)


def _mirror_differences(m: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """m(b) - D m(a) D over mirror ``pairs`` (a, b) of normalised matrices ``m``: zero for an isotropic sample."""
    a, b = (pairs.T if len(pairs) else (np.array([], int), np.array([], int)))
    return m[..., b] - np.einsum("ij,jkn,kl->iln", MIRROR, m[..., a], MIRROR)


def _rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x)))) if np.size(x) else float("nan")
