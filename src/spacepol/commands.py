"""What each ``invert-mcmc`` subcommand does.  Each takes the parsed arguments, returns an exit code."""

from __future__ import annotations

from pathlib import Path

from .errors import ParameterError
from .io import Dataset, read_measurements, write_table
from .io.output import check_output_dir, check_output_file
from .physics.geometry import Geometry
from .api.inputs import build_model, parse_engine_options, parse_references, parse_settings
from .physics.model import Model


def _prediction_columns(geometry: Geometry, prediction) -> dict:
    s = prediction.stokes
    return {
        "theta_i": geometry.theta_i, "theta_r": geometry.theta_r, "dphi": geometry.dphi,
        "s0": s[0], "s1": s[1], "s2": s[2], "s3": s[3],
        "dop": prediction.dop, "aop": prediction.aop_deg, "brdf": prediction.brdf,
    }


def forward(args) -> int:
    """``invert-mcmc forward``: the model's Stokes vector, DOP, AoP and BRDF at a file's geometries, as a CSV."""
    from .api import forward as predict

    check_output_file(args.out)
    model = build_model(args.model)
    values = parse_settings(args.set, model)
    data = read_measurements(args.geometry, require_observable=False)
    prediction = predict(model, data, values)
    columns = _prediction_columns(data.geometry, prediction)
    if data.wavelength_um is not None:
        columns["wavelength_um"] = data.wavelength_um
    meta = {"model": model.name, **{f"param_{k}": v for k, v in {**model.defaults(), **values}.items()}}
    write_table(args.out, columns, meta)
    print(f"wrote {args.out}: {len(data)} geometries, model {model.name}")
    return 0


def synth(args) -> int:
    """``invert-mcmc synth``: a synthetic data set from a model with Gaussian noise, as a CSV with its truth in the
    metadata."""
    from .api import synth as synthesise

    check_output_file(args.out)
    model = build_model(args.model)
    settings = parse_settings(args.set, model)
    data = synthesise(model, settings, args.geometry, noise_dop=args.noise_dop, noise_brdf=args.noise_brdf,
                      wavelength_um=args.wavelength_um, seed=args.seed, out=args.out)
    print(f"wrote {args.out}: {len(data)} points from {model.name} (seed {args.seed})")
    return 0


def effects(args) -> int:
    """``invert-mcmc effects``: every registered effect with its parameters, priors, slot, twins and reciprocity."""
    from .physics.effects import PRESETS, registry
    import textwrap

    for name in registry.names():
        cls = registry.get(name)
        print(f"{name}")
        print(textwrap.fill(cls.description, width=96, initial_indent="    ", subsequent_indent="    "))
        for p in cls.parameters:
            print(f"    - {p.describe()}")
        extras = []
        if cls.requires:
            extras.append("needs " + ", ".join(cls.requires))
        if cls.excludes:
            extras.append("replaces " + ", ".join(cls.excludes))
        if cls.removes:
            extras.append("replaces parameter " + ", ".join(cls.removes))
        if cls.slot:
            extras.append(f"slot {cls.slot}" + (" (removable)" if cls.removable else ""))
        for twin, separation in cls.twins.items():
            extras.append(f"twin of {twin} (separated by {separation})")
        extras.append("reciprocal" if cls.reciprocal else "NOT reciprocal")
        print(f"    ({'; '.join(extras)})")
        print()
    print("presets: " + "; ".join(f"{k} = {v}" for k, v in PRESETS.items()))
    return 0


def demo(args) -> int:
    """``invert-mcmc demo``: the whole chain on bundled data, report in ``--out``."""
    from .report.demo import run_demo

    check_output_dir(args.out)
    run_demo(Path(args.out))
    return 0


def load_dataset(args) -> Dataset:
    """The data set of --data, --wavelength-um and --in-plane (``api.load``); a user's observable named in
    --observables (``path.py:Name``) is registered first, so that the file's columns for it are read."""
    from .api import load, parse_observables

    parse_observables(getattr(args, "observables", None))
    return load(args.data, args.wavelength_um, args.in_plane)


def build_posterior(args, data, robust=False):
    """The Posterior of --model, --prior, --observables and --dispersion on ``data`` (``api.build_posterior``)."""
    from .api import build_posterior as posterior_of

    return posterior_of(data, args.model, args.prior, args.observables, getattr(args, "dispersion", None), robust)


def run(args) -> int:
    """``invert-mcmc run``: ``api.invert`` with the run's report; prints the findings and the convergence figures."""
    from .api import invert

    check_output_dir(args.out)  # before the data are read
    from .infer.engine_registry import SAMPLER, engines

    engines.get(args.engine, SAMPLER)  # a wrong name fails before the data are read
    summary = invert(load_dataset(args), args.model, args.prior, args.engine, args.seed, args.out,
                     observables=args.observables, dispersion=args.dispersion, walkers=args.walkers, steps=args.steps,
                     robust=args.robust, restart=args.restart, progress=not args.quiet,
                     references=parse_references(args.reference),
                     engine_options=parse_engine_options(args.engine_option)).summary
    for flag in summary.at_bound:
        from .infer.identifiability import bound_finding

        print(f"warning: {bound_finding(flag)}")
    from .infer.draws_result import noise_findings

    for line in noise_findings(summary.noise):
        print(f"noise: {line}")
    d = summary.diagnostics
    quality = (f"R-hat max {d['rhat_max']:.4f}, ESS min {d['ess_min']:.0f}" if d.get("rhat_max") is not None
               else f"Pareto k {d.get('pareto_k', float('nan')):.2f}, {d['ess_min']:.0f} effective draws")
    evidence = summary.log_evidence
    if evidence:
        quality += f", ln Z {evidence['value']:.2f} +- {evidence['error']:.2f}"
    print(f"wrote {args.out}/summary.json, posterior.nc, corner.png, fit.png, residuals.png, residual_trends.png, "
          f"report.html ({quality}, {summary.seconds:.1f} s)")
    return 0


def optimize(args) -> int:
    """``invert-mcmc optimize``: ``api.optimize``; prints its EngineResult as JSON."""
    import json

    from .api import optimize as run_optimize
    from .infer.engine_registry import check_method
    from .io.atomic import jsonable

    check_method(args.method)  # before the data are read
    result = run_optimize(load_dataset(args), args.model, args.method, args.prior, observables=args.observables,
                          dispersion=getattr(args, "dispersion", None), seed=args.seed)
    print(json.dumps(jsonable(result.to_json()), indent=2))
    return 0


def compare(args) -> int:
    """``invert-mcmc compare``: ``api.compare``, several engines and seeds on the same posterior; figures and table in
    ``--out``."""
    from .api import compare as run_compare
    from .infer.engine_registry import check_method

    check_output_dir(args.out)
    for method in args.methods or []:
        check_method(method)
    run_compare(load_dataset(args), args.model, args.methods, args.seeds, args.out, args.prior,
                observables=args.observables, dispersion=getattr(args, "dispersion", None), seed=args.seed)
    return 0


def diagnose(args) -> int:
    """``invert-mcmc diagnose``: ``api.diagnose`` and its verdict, conclusion and significance in words."""
    from .api import diagnose as diagnose_data
    from .report.diagnose_report import significance_statement

    result = diagnose_data(args.data, args.model, rounds=args.rounds, candidates=args.candidates,
                           top=args.top, prior=args.prior, observables=args.observables,
                           dispersion=getattr(args, "dispersion", None), posterior=args.posterior, seed=args.seed,
                           out=args.out, json_path=args.json, wavelength_um=args.wavelength_um, in_plane=args.in_plane,
                           workers=args.workers, criterion=args.criterion)
    report = result.content
    lead = report["ranking"][0] if report["ranking"] else None
    print(f"verdict: {report['verdict']}" + (f" ({lead['change']}: delta ELPD {lead['delta_elpd']:+.1f} +- "
                                             f"{lead['delta_elpd_se']:.1f})" if lead and lead["delta_elpd"] is not None else ""))
    print(report["conclusion"])
    print(significance_statement(report))
    if args.rounds:
        print(report["conclusion_rounds"])
    print(f"wrote {args.json}; figures and report.html in {args.out}")
    return 0


def ladder(args) -> int:
    """``invert-mcmc ladder``: ``api.ladder`` over ``--add`` changes (after a ``--replay`` path) and its table."""
    from .api import ladder as climb_ladder
    from .report.ladder_report import ladder_table

    check_output_dir(args.out)
    if args.json:
        check_output_file(args.json, "--json")
    steps = list(args.add)
    if args.replay:
        steps = replay_steps(args.replay, build_model(args.model)) + steps
    result = climb_ladder(args.data, args.model, steps, observables=args.observables,
                          dispersion=getattr(args, "dispersion", None), seed=args.seed, out=args.out, json_path=args.json,
                          wavelength_um=args.wavelength_um, in_plane=args.in_plane)
    out = Path(args.out)
    print("\n".join(ladder_table(result.to_json())))
    print(f"wrote {args.json or out / 'ladder.json'}, {out / 'ladder.png'}, {out / 'ladder.md'}")
    return 0


def replay_steps(path, model: Model) -> list[str]:
    """The changes of a `diagnose --rounds` JSON, checked to start from ``model``."""
    import json

    try:
        report = json.loads(Path(path).read_text(encoding="utf-8"))
        rounds = report["rounds"]
        start, steps = rounds[0]["model"], [r["change"] for r in rounds[1:]]
    except FileNotFoundError:
        raise ParameterError(f"--replay {path}: file not found") from None
    except (ValueError, KeyError, IndexError, TypeError, UnicodeDecodeError):
        raise ParameterError(f"--replay {path}: not the JSON of `diagnose --rounds` (no 'rounds' path)") from None
    if start != model.name:
        raise ParameterError(f"--replay {path}: its path starts from {start}, not from --model {model.name}")
    return [s for s in steps if isinstance(s, str)]


def design(args) -> int:
    """``invert-mcmc design``: ``api.design`` with ``--noise`` levels; prints the first finding."""
    from .api import design as propose

    out = check_output_dir(args.out)
    noise = {}
    for item in args.noise:  # the text to numbers here; which names and values are allowed, api.design says
        name, sep, text = item.partition("=")
        try:
            noise[name.strip()] = float(text)
        except ValueError:
            raise ParameterError(f"--noise '{item}': expected dop=X, brdf=REL or mueller=X") from None
        if not sep:
            raise ParameterError(f"--noise '{item}': expected dop=X, brdf=REL or mueller=X")
    data = load_dataset(args)
    result = propose(data, args.model, picks=args.picks, noise=noise, prior=args.prior, observables=args.observables,
                     seed=args.seed, out=out, progress=True)
    from .report.design_report import design_lines

    print("\n".join(design_lines(result.content, args.data)[2:3]))
    print(f"wrote {out}/design.md, design.json, design.png")
    return 0


def batch(args) -> int:
    """``invert-mcmc batch``: every set of a manifest; exit status 1 when any set failed."""
    from .batch import run_batch

    rows = run_batch(args.manifest, args.out, executor=args.executor, scheduler=args.scheduler, workers=args.workers,
                     progress=not args.quiet)
    counts = {s: sum(r["status"] == s for r in rows) for s in ("ok", "skipped", "failed")}
    print(f"wrote {args.out}/results.csv: {counts['ok']} ok, {counts['skipped']} skipped (finished before), "
          f"{counts['failed']} failed" + ("".join(f"\n  failed {r['id']}: {r['error']}" for r in rows if r["status"] == "failed")))
    return 1 if counts["failed"] else 0


def sky(args) -> int:
    """``invert-mcmc sky``: ``api.sky`` and its figures; prints the sun and the sky's DOP and AoP at each direction."""
    from .api import sky as sky_of

    check_output_dir(args.out)
    result = sky_of(args.lat, args.lon, args.time, args.direction, model=args.model, p_max=args.p_max,
                    delta_deg=args.delta_deg, out=args.out)
    sun = result.content["sun"]
    print(f"sun: zenith {sun['zenith_deg']:.2f} deg, azimuth {sun['azimuth_deg']:.2f} deg east of north ({sun['time_utc']})")
    if sun["zenith_deg"] > 90:
        print(f"note: the sun is {sun['zenith_deg'] - 90:.1f} deg below the horizon: there is no daylight sky then; the maps "
              f"show the single-scattering pattern for reference only")
    for d in result.content["directions"]:
        print(f"  zenith {d['zenith_deg']:g}, azimuth {d['azimuth_deg']:g}: DOP {d['dop']:.3f}, AoP {d['aop_deg']:.1f} deg")
    print(f"wrote {args.out}/sky.json, sky_maps.png, projections.png")
    return 0


def contrast(args) -> int:
    """``invert-mcmc contrast``: ``api.contrast`` on a run folder; prints Table 3 as distributions."""
    from .api import contrast as contrast_of_run
    from .report.contrast_report import table3_lines

    out = check_output_dir(Path(args.out) if args.out else Path(args.run_dir) / "contrast")
    report = contrast_of_run(args.run_dir, args.scenario, out, reading=args.reading, draws=args.draws, seed=args.seed,
                             extrapolate=args.extrapolate).content
    print("\n".join(table3_lines(report)))
    print(report["dominance"])
    print(f"wrote {out}/contrast.json, table3.md, contrast_histograms.png, report.html")
    return 0


def observe(args) -> int:
    """``invert-mcmc observe``: a run folder's Result over a satellite's pass (``api.observe``); prints where the
    target is detectable."""
    from .api import observe as observe_pass
    from .report.observe_report import best_times

    out = check_output_dir(Path(args.out) if args.out else Path(args.run_dir) / "observe")
    observation = observe_pass(args.run_dir, args.tle, args.site, args.start, args.end, step_s=args.step,
                               satellite=args.satellite, target=args.target, camera=args.camera, draws=args.draws,
                               seed=args.seed, out=out, progress=True, exposures_per_step=args.exposures,
                               sky_magnitude_zenith=args.sky_zenith_mag, p_max=args.p_max)
    content = observation.to_json()
    for name, best in best_times(content).items():
        print(f"{name}: best P_d {best['p_detect'][name]['median']:.3f} at {best['time_utc']} "
              f"(elevation {best['elevation_deg']:.1f} deg, phase {best['phase_angle_deg']:.1f} deg); over the pass "
              f"{content['over_pass']['p_detect'][name]['median']:.3f}")
    print(f"over the pass a target-free sky gives a false alarm with probability {content['over_pass']['p_false_alarm']:.3f}")
    print(f"wrote {out}/observe.json, light_curves.png, report.html")
    return 0


def synth_pass(args) -> int:
    """``invert-mcmc synth-pass``: a simulated light curve of a target over a pass (``api.synth_pass``)."""
    from .api import synth_pass as render

    curve = render(args.tle, args.site, args.start, args.end, target=args.target, step_s=args.step,
                   satellite=args.satellite, camera=args.camera, seed=args.seed, exposures_per_step=args.exposures,
                   sky_magnitude_zenith=args.sky_zenith_mag, out=args.out)
    print(f"{len(curve)} times with the target above the horizon, sunlit and turning a lit face to the site "
          f"({curve.times_utc[0]:%H:%M:%S} to {curve.times_utc[-1]:%H:%M:%S} UTC); wrote {args.out}")
    return 0


def lightcurve(args) -> int:
    """``invert-mcmc lightcurve``: materials ranked and the attitude from a light curve (``api.invert_lightcurve``)."""
    from .api import invert_lightcurve

    out = check_output_dir(Path(args.out) if args.out else Path(args.curve).with_suffix(""))
    inversion = invert_lightcurve(args.curve, args.tle, args.site, args.start, args.end, target=args.target,
                                  materials=args.materials, step_s=args.step, satellite=args.satellite,
                                  observables=args.observables.split(",") if args.observables else None,
                                  seed=args.seed, live=args.live, out=out, progress=True)
    for row in inversion.ranking:
        print(f"{row['material']:<12s} ELPD-LOO {row['elpd']:12.1f} +- {row['elpd_se']:.1f}   "
              f"delta {row['delta_elpd']:12.1f} +- {row['delta_elpd_se']:.1f}")
    for name, q in inversion.to_json()["attitude"].items():
        print(f"{name} {q['median']:.2f} [90 %: {q['q05']:.2f}, {q['q95']:.2f}]")
    print(f"wrote {out}/lightcurve.json, light_curve.png, report.html")
    return 0


def frame(args) -> int:
    """``invert-mcmc frame``: a raw frame's maps (``api.frame``); prints their DoLP."""
    from .api import frame as read_frame

    raw = Path(args.raw)
    out = check_output_dir(Path(args.out) if args.out else raw.with_suffix(""))
    content = read_frame(raw, args.method, out=out).to_json()
    d = content["dolp"]
    unit = "superpixels" if args.method == "superpixel" else "pixels (bilinear)"
    print(f"{raw.name}: {content['shape'][0]} x {content['shape'][1]} {unit}, DoLP median {d['median']:.3f} "
          f"[5 %, 95 %: {d['q05']:.3f}, {d['q95']:.3f}]")
    print(f"wrote {out}/frame.png, stokes.npz, frame.json")
    return 0
