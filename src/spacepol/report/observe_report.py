"""Files of ``invert-mcmc observe``: observe.json, light_curves.png (the target's flux, DoLP and AoP with their
posterior bands, the sky's DoLP, and P_d(t) per detector), report.html."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..detect.target import bands_over_draws
from ..io.atomic import atomic_path, save_figure, write_json
from . import html as H


def light_curves_figure(observation, fig=None) -> Figure:
    """Four panels over the pass: photon flux at the aperture, DoLP (target and sky), AoP, and P_d per detector;
    medians with the 5-95 % band of the material's posterior."""
    g = observation.geometry
    minutes = np.array([(t - g.times_utc[0]).total_seconds() / 60.0 for t in g.times_utc])
    fig = fig or Figure(figsize=(8.0, 9.0), layout="constrained")
    axes = fig.subplots(4, 1, sharex=True)
    light = observation.light

    def band(ax, values, colour, label):
        lo, med, hi = bands_over_draws(values)
        ax.fill_between(minutes, lo, hi, color=colour, alpha=0.3, lw=0)
        ax.plot(minutes, med, "-", color=colour, label=label)

    band(axes[0], np.where(light.photons_m2_s > 0, light.photons_m2_s, np.nan), "C0", "target")
    axes[0].set_yscale("log")
    axes[0].set_ylabel("photons m^-2 s^-1")
    band(axes[1], light.dolp, "C0", "target DoLP")
    axes[1].plot(minutes, observation.sky_dolp, "--", color="C1", label="sky DoLP")
    axes[1].set_ylabel("DoLP")
    band(axes[2], light.aop_deg, "C0", "target AoP")
    axes[2].set_ylabel("AoP (deg from horizontal)")
    for k, (name, values) in enumerate(observation.p_detect.items()):
        band(axes[3], values, f"C{k + 2}", name)
    axes[3].axhline(observation.p_false_alarm, color="k", lw=0.8, ls=":", label="P_fa")
    # where a polarization detector's median P_d beats intensity's: the paper's case, at a glance
    if "intensity" in observation.p_detect:
        base = np.nanmedian(observation.p_detect["intensity"], axis=0)
        better = np.zeros_like(base, bool)
        for name, values in observation.p_detect.items():
            if name != "intensity":
                better |= np.nanmedian(values, axis=0) > base + 0.05
        if better.any():
            axes[3].fill_between(minutes, 0, 1, where=better, color="0.85", step="mid", lw=0,
                                 label="polarization beats intensity", transform=axes[3].get_xaxis_transform())
    axes[3].set_ylabel("P_d")
    axes[3].set_xlabel(f"minutes after {g.times_utc[0].isoformat().replace('+00:00', 'Z')}")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"{g.satellite} over ({g.site[0]:.2f}, {g.site[1]:.2f}): posterior medians and 90 % bands", fontsize=10)
    return fig


def best_times(content: dict) -> dict:
    """{detector: observe.json's row where its median P_d is highest}."""
    return {name: max(content["times"], key=lambda r: r["p_detect"][name]["median"] or 0.0) for name in content["detectors"]}


def montage_times(observation, count: int = 4) -> list[int]:
    """Up to ``count`` times for the frame montage: the one where the intensity detector does best and others spread
    over the times the satellite is above the horizon."""
    above = np.flatnonzero(observation.geometry.elevation_deg > 0)
    if not above.size:
        return []
    pd = np.nan_to_num(np.nanmedian(observation.p_detect["intensity"], axis=0)) if observation.p_detect else np.zeros(0)
    best = int(above[np.argmax(pd[above])]) if pd.size else int(above[0])
    spread = above[np.unique(np.linspace(0, above.size - 1, count).round().astype(int))]
    return sorted({best, *[int(j) for j in spread]})[:count]


def write_observe_report(observation, out: Path, assumptions: list[str], seed: int = 0) -> dict:
    """observe.json, light_curves.png, frames.png (simulated exposures at a few times) and report.html in ``out``;
    returns observe.json's content."""
    from ..detect.frames import montage_figure

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    content = observation.to_json() | {"assumptions": assumptions}
    write_json(out / "observe.json", content)
    save_figure(light_curves_figure(observation), out / "light_curves.png")
    times = montage_times(observation)
    if times:
        save_figure(montage_figure(observation, times, np.random.default_rng(seed)), out / "frames.png")
    rows = []
    for row in content["times"][:: max(1, len(content["times"]) // 30)]:
        pd = row["p_detect"]
        rows.append([row["time_utc"], f"{row['elevation_deg']:.1f}", f"{row['phase_angle_deg']:.1f}", row["sky_state"],
                     _q(row["target"]["flux"], "{:.3g}"), _q(row["target"]["dolp"], "{:.3f}"),
                     f"{row['sky']['dolp']:.2f}"] + [_q(pd[d], "{:.3f}") for d in content["detectors"]])
    over = content["over_pass"]
    summary = H.paragraph(
        f"Over the pass ({over['steps_above_horizon']} time steps above the horizon, independent frames): P(at least one "
        "detection) " + "; ".join(f"{d} {_q(over['p_detect'][d], '{:.3f}')}" for d in content["detectors"])
        + f". A target-free sky gives at least one false alarm with probability {over['p_false_alarm']:.3f}.")
    sections = [("Pass, target and camera", H.bullets(assumptions)), ("Detection over the pass", summary),
                ("Light curves and detection probability", H.image(H.png_file_to_data_uri(out / "light_curves.png"))),
                ("Simulated exposures", H.image(H.png_file_to_data_uri(out / "frames.png")) if times else
                 H.paragraph("The satellite is never above the horizon in this window.")),
                ("Per time (median [5 %, 95 %] over the material's posterior)", H.table(
                    ["time (UTC)", "elevation (deg)", "phase (deg)", "sky", "flux (photons m^-2 s^-1)", "target DoLP",
                     "sky DoLP"] + [f"P_d {d}" for d in content["detectors"]], rows))]
    with atomic_path(out / "report.html") as tmp:
        tmp.write_text(H.page(f"spacepol observe: {content['satellite']}", sections), encoding="utf-8")
    return content


def _q(q: dict, fmt: str) -> str:
    if q["median"] is None:
        return "no light"
    return f"{fmt.format(q['median'])} [{fmt.format(q['q05'])}, {fmt.format(q['q95'])}]"
