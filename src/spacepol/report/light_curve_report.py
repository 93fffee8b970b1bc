"""Files of ``invert-mcmc lightcurve``: lightcurve.json, light_curve.png (the measured flux, DoLP and AoP against
each candidate material's posterior-predictive band), attitude_corner.png (the best material's attitude offsets) and
report.html."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..io.atomic import atomic_path, save_figure, write_json
from ..io.light_curve import OBSERVABLES
from ..orbit.attitude import ANGLES
from . import html as H

_LABELS = {"flux": "photons m^-2 s^-1", "dolp": "DoLP", "aop_deg": "AoP (deg)"}


def light_curve_figure(inversion, fig=None) -> Figure:
    """Flux, DoLP and AoP against time: the measurements with their errors and, per candidate, the 5-95 %
    posterior-predictive band (the model plus the measurement's noise) and its median."""
    curve = inversion.curve
    minutes = np.array([(t - curve.times_utc[0]).total_seconds() / 60.0 for t in curve.times_utc])
    fig = fig or Figure(figsize=(8.0, 8.0), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    for ax, (name, err) in zip(axes, OBSERVABLES.items()):
        for k, f in enumerate(inversion.fits):
            low, median, high = f.bands[name]
            ax.fill_between(minutes, low, high, color=f"C{k + 1}", alpha=0.25, lw=0)
            ax.plot(minutes, median, "-", color=f"C{k + 1}", lw=1, label=f.material)
        if getattr(curve, name) is not None:
            fitted = "fitted" if name in inversion.observables else "not fitted"
            ax.errorbar(minutes, getattr(curve, name), getattr(curve, err), fmt=".", color="k", ms=3, lw=0.8,
                        label=f"measured ({fitted})")
        ax.set_ylabel(_LABELS[name])
        ax.grid(alpha=0.3)
    axes[0].set_yscale("log")
    axes[0].legend(fontsize=7)
    axes[-1].set_xlabel(f"minutes after {curve.times_utc[0].strftime('%Y-%m-%dT%H:%M:%SZ')}")
    fig.suptitle(f"{curve.source}: posterior-predictive 90 % bands per material", fontsize=10)
    return fig


def attitude_figure(fit) -> Figure | None:
    """The corner plot of ``fit``'s attitude offsets (None where the attitude was known)."""
    import corner

    columns = [fit.names.index(a) for a in ANGLES if a in fit.names]
    if not columns:
        return None
    fig = Figure(figsize=(6.0, 6.0))
    corner.corner(fit.samples[:, columns], labels=[fit.names[j] for j in columns], quantiles=[0.05, 0.5, 0.95],
                  show_titles=True, fig=fig)
    return fig


FEW_EFFECTIVE_DRAWS = 200  # below this a candidate's posterior summary is rough (the sampler's budget ran out)
LOOSE_ATTITUDE_DEG = 30.0  # an attitude offset whose 90 % interval is wider than this is reported as not determined


def verdict_text(content: dict) -> str:
    """The report's verdict in words from lightcurve.json's ``content``: the material the curve reads as and by how
    much, and every caution the fits carry (few effective draws, restarted explorations, an attitude sampled in a
    second run, explorations ended where they stood, offsets the curve does not determine)."""
    second = content["ranking"][1] if len(content["ranking"]) > 1 else None
    verdict = f"The light curve reads as {content['best']}"
    if second is not None:
        gap = -second["delta_elpd"] / max(second["delta_elpd_se"], 1e-300)
        verdict += (f", ahead of {second['material']} by {-second['delta_elpd']:.1f} +- {second['delta_elpd_se']:.1f} in "
                    f"ELPD-LOO ({gap:.1f} SE: {'decisive' if gap >= 2 else 'not decisive'}) and by "
                    f"{-second['delta_log_evidence']:.1f} in ln Z.")
        if 0 < second["points_carrying_half"] <= 2:
            verdict += (f" Half the ELPD difference sits in {second['points_carrying_half']} measured point(s), so its SE "
                        "rests on those few: read the gap from ln Z and the figure rather than in SEs.")
    rough = [f"{m} ({c['effective_draws']:.0f})" for m, c in content["candidates"].items()
             if c["effective_draws"] < FEW_EFFECTIVE_DRAWS]
    if rough:
        verdict += (f" Few effective draws (under {FEW_EFFECTIVE_DRAWS}) for {', '.join(rough)}: the sampler's budget ran "
                    "out on a posterior far narrower than its last shell, so those posteriors and ELPD-LOO are rough; "
                    "ln Z is still an estimate.")
    restarted = [f"{m} ({c['restarts']} restart{'s' if c['restarts'] > 1 else ''})" for m, c in content["candidates"].items()
                 if c.get("restarts")]
    if restarted:
        verdict += (f" Nested sampling's exploration stalled and started again from the prior with twice the live "
                    f"points for {', '.join(restarted)} (its neural bound rejected nearly every point drawn).")
    cut = [m for m, c in content["candidates"].items() if c.get("exploration_ended_early")]
    if cut:
        verdict += (f" Nested sampling's exploration of {', '.join(cut)} added no shell over a long run (a thin curved "
                    "ridge its bounds could not follow) and was ended where it stood: those ln Z, ELPD-LOO and "
                    "posteriors are rough, the more so the fewer effective draws they have.")
    added = content["candidates"][content["best"]].get("added_attitude")
    if added:
        verdict += f" For {content['best']}, {added['finding']}."
    loose = [k for k, v in content["attitude"].items() if v["q95"] - v["q05"] > LOOSE_ATTITUDE_DEG]
    if loose:
        verdict += (f" Not determined by this light curve (90 % interval wider than {LOOSE_ATTITUDE_DEG:g} deg: several "
                    f"modes or a direction the pass does not see): {', '.join(loose)}.")
    return verdict


def write_light_curve_report(inversion, out: Path) -> dict:
    """lightcurve.json, light_curve.png, attitude_corner.png (where the attitude was inferred) and report.html in
    ``out``; returns lightcurve.json's content."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    content = inversion.to_json()
    write_json(out / "lightcurve.json", content)
    save_figure(light_curve_figure(inversion), out / "light_curve.png")
    corner_fig = attitude_figure(inversion.best)
    if corner_fig is not None:
        save_figure(corner_fig, out / "attitude_corner.png")
    rows = [[r["material"], f"{r['elpd']:.1f} +- {r['elpd_se']:.1f}", f"{r['delta_elpd']:.1f} +- {r['delta_elpd_se']:.1f}",
             f"{r['delta_log_evidence']:.1f}", f"{content['candidates'][r['material']]['effective_draws']:.0f}"]
            for r in content["ranking"]]
    verdict = verdict_text(content)
    estimates = [[k, f"{v['median']:.4g}", f"[{v['q05']:.4g}, {v['q95']:.4g}]"]
                 for k, v in (content["attitude"] | content["parameters"]).items()]
    sections = [("Verdict", H.paragraph(verdict)),
                ("Materials ranked by ELPD-LOO", H.table(["material", "ELPD-LOO", "delta vs best", "ln Z - ln Z of the first",
                                                                 "effective draws"], rows)),
                (f"{content['best']}: posterior median and 90 % interval", H.table(["parameter", "median", "90 %"], estimates)),
                ("Light curve", H.image(H.png_file_to_data_uri(out / "light_curve.png")))]
    if corner_fig is not None:
        sections.append(("Attitude offsets", H.image(H.png_file_to_data_uri(out / "attitude_corner.png"))))
    sections.append(("Pass, target and fit", H.bullets(inversion.assumptions)))
    with atomic_path(out / "report.html") as tmp:
        tmp.write_text(H.page("spacepol lightcurve", sections), encoding="utf-8")
    return content
