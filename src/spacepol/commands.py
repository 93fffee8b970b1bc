"""What each ``invert-mcmc`` subcommand does.  Each takes the parsed arguments, returns an exit code."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from .errors import ParameterError, SpacepolError
from .io import Dataset, read_measurements, write_table
from .io.output import check_output_dir, check_output_file
from .physics.geometry import Geometry, default_grid
from .physics.model import Model, build_model


def parse_settings(items, model: Model) -> dict[str, float]:
    """``["n=1.5", "k=0"]`` -> {"n": 1.5, "k": 0.0}, checked against the model."""
    values = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ParameterError(f"--set '{item}': expected NAME=VALUE")
        param = model.parameter(name)
        try:
            value = float(text)
        except ValueError:
            raise ParameterError(f"--set '{item}': '{text}' is not a number") from None
        param.check(value, where="--set")
        values[name] = value
    return values


def _prediction_columns(geometry: Geometry, prediction) -> dict:
    s = prediction.stokes
    return {
        "theta_i": geometry.theta_i, "theta_r": geometry.theta_r, "dphi": geometry.dphi,
        "s0": s[0], "s1": s[1], "s2": s[2], "s3": s[3],
        "dop": prediction.dop, "aop": prediction.aop_deg, "brdf": prediction.brdf,
    }


def forward(args) -> int:
    check_output_file(args.out)
    model = build_model(args.model)
    values = parse_settings(args.set, model)
    data = read_measurements(args.geometry, require_observable=False)
    prediction = model.check_plugins({**model.defaults(), **values}, data.geometry).require_finite(values, model.name)
    columns = _prediction_columns(data.geometry, prediction)
    if data.wavelength_um is not None:
        columns["wavelength_um"] = data.wavelength_um
    meta = {"model": model.name, **{f"param_{k}": v for k, v in {**model.defaults(), **values}.items()}}
    write_table(args.out, columns, meta)
    print(f"wrote {args.out}: {len(data)} geometries, model {model.name}")
    return 0


def synth(args) -> int:
    check_output_file(args.out)
    model = build_model(args.model)
    settings = parse_settings(args.set, model)
    values = {**model.defaults(), **settings}
    if args.noise_dop < 0 or (args.noise_brdf is not None and args.noise_brdf < 0):
        raise ParameterError("noise levels must be >= 0")
    if args.geometry:
        geo_data = read_measurements(args.geometry, require_observable=False)
        geometry = geo_data.geometry
        wavelength = geo_data.wavelength_um
    else:
        geometry = default_grid()
        wavelength = None
    if args.wavelength_um is not None:
        wavelength = np.full(geometry.size, args.wavelength_um)
    if wavelength is not None:
        geometry = Geometry(geometry.theta_i, geometry.theta_r, geometry.dphi, wavelength)
    rng = np.random.default_rng(args.seed)
    prediction = model.check_plugins(values, geometry).require_finite(settings, model.name)
    dop = np.clip(prediction.dop + rng.normal(0.0, args.noise_dop, geometry.size), 0.0, 1.0)
    columns = {"theta_i": geometry.theta_i, "theta_r": geometry.theta_r, "dphi": geometry.dphi, "dop": dop}
    if args.noise_dop > 0:
        columns["dop_err"] = np.full(geometry.size, args.noise_dop)
    if args.noise_brdf is not None:
        brdf = prediction.brdf * (1.0 + rng.normal(0.0, args.noise_brdf, geometry.size))
        columns["brdf"] = np.maximum(brdf, 0.0)
        if args.noise_brdf > 0:
            columns["brdf_err"] = args.noise_brdf * prediction.brdf
    if wavelength is not None:
        columns["wavelength_um"] = wavelength
    meta = {
        "source": "spacepol synth",
        "model": model.name,
        "seed": args.seed,
        "noise_dop": args.noise_dop,
        **{f"truth_{k}": v for k, v in values.items()},
    }
    write_table(args.out, columns, meta)
    print(f"wrote {args.out}: {geometry.size} points from {model.name} (seed {args.seed})")
    return 0


def effects(args) -> int:
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
    from .report.demo import run_demo

    check_output_dir(args.out)
    run_demo(Path(args.out))
    return 0


def load_dataset(args) -> Dataset:
    data = read_measurements(args.data)
    chosen = args.wavelength_um
    if data.wavelength_um is not None and len(np.unique(data.wavelength_um)) > 1:
        if chosen is None:
            have = ", ".join(f"{w:g}" for w in np.unique(data.wavelength_um))
            raise SpacepolError(f"{args.data}: holds several wavelengths ({have} um); choose one with --wavelength-um, "
                                f"a comma list, or all")
    if isinstance(chosen, list):
        data = data.at_wavelengths(chosen)
    elif chosen == "all":
        if data.wavelength_um is None:
            raise SpacepolError(f"{args.data}: --wavelength-um all, but the file gives no wavelength")
    elif chosen is not None:
        data = data.at_wavelength(chosen)
    if args.in_plane:
        data = data.in_plane()
    return data


def parse_observables(text: str | None) -> list[str] | None:
    """``--observables dop,brdf`` -> ["dop", "brdf"]; empty, unknown or repeated names are errors."""
    if text is None:
        return None
    from .observables import ALIASES, OBSERVABLES

    names = [o.strip() for o in text.split(",")]
    for name in names:
        if not name:
            raise ParameterError(f"--observables '{text}': an empty name (use e.g. dop,brdf)")
        if name not in OBSERVABLES and name not in ALIASES:
            raise ParameterError(f"--observables '{text}': unknown observable '{name}' (use {', '.join(OBSERVABLES)}; "
                                 f"q, u name the Stokes pair)")
        if names.count(name) > 1:
            raise ParameterError(f"--observables '{text}': '{name}' named twice (each observable counts once)")
    return names


def model_for(args, data):
    """The model named by --model; over several wavelengths a SpectralModel (n, k per wavelength, or
    the --dispersion law)."""
    model = build_model(args.model)
    wavelengths = np.unique(data.wavelength_um) if data.wavelength_um is not None else []
    dispersion = parse_dispersion(getattr(args, "dispersion", None))
    if len(wavelengths) > 1:
        from .physics.spectral import SpectralModel

        return SpectralModel(model, wavelengths, dispersion)
    if dispersion:
        raise ParameterError(f"--dispersion {args.dispersion}: needs several wavelengths (--wavelength-um all or a list)")
    return model


def parse_dispersion(text: str | None) -> dict:
    if not text:
        return {}
    name, sep, law = text.partition("=")
    if not sep or not law:
        raise ParameterError(f"--dispersion '{text}': write NAME=LAW, e.g. n=cauchy")
    return {name.strip(): law.strip()}


def build_posterior(args, data, robust=False):
    from .infer.posterior import Posterior
    from .infer.prior_set import read_prior_file

    model = model_for(args, data)
    overrides = read_prior_file(args.prior) if args.prior else None
    observables = parse_observables(args.observables)
    return Posterior.build(data, model, overrides, observables=observables, robust=robust,
                           where=args.prior or "priors")


def parse_references(items, posterior) -> dict[str, float]:
    refs = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep:
            raise ParameterError(f"--reference '{item}': expected NAME=VALUE")
        if name not in posterior.names:
            raise ParameterError(f"--reference '{item}': '{name}' is not a free parameter ({', '.join(posterior.names)})")
        try:
            refs[name] = float(text)
        except ValueError:
            raise ParameterError(f"--reference '{item}': '{text}' is not a number") from None
    return refs


def run(args) -> int:
    from .infer.chain_file import set_aside
    from .infer.inversion import check_resumable, check_walkers, invert
    from .io.output import folder_lock
    from .report.run_report import write_run_report

    out = check_output_dir(args.out)
    data = load_dataset(args)
    posterior = build_posterior(args, data, robust=args.robust)
    references = parse_references(args.reference, posterior)
    check_walkers(args.walkers, posterior.ndim)
    made_folder = not out.exists()
    chain = out / "chain.h5"
    fresh = not chain.exists()
    with folder_lock(out):  # first: a second run on this folder stops here, before it reads the chain
        try:
            if not args.restart:
                check_resumable(chain, posterior, args.walkers, args.seed)
            if not args.quiet:
                print(f"sampling {', '.join(posterior.names)} from {len(data)} geometries "
                      f"({', '.join(posterior.likelihood.observables)}), model {posterior.likelihood.model.name}",
                      file=sys.stderr)
                if left_out := posterior.likelihood.left_out:
                    print(f"  not fitted: {', '.join(left_out)} ({' and '.join(sorted(set(left_out.values())))} holds "
                          f"their numbers; --observables chooses)", file=sys.stderr)
            if args.restart and (old := set_aside(chain)) is not None and not args.quiet:
                print(f"  --restart: the previous chain is kept as {old}", file=sys.stderr)
            inv = invert(posterior, seed=args.seed, walkers=args.walkers, max_steps=args.steps,
                         backend_path=chain, progress=not args.quiet)
        except KeyboardInterrupt:
            raise  # the chain so far is kept: the same command continues it
        except BaseException:
            _discard_unstarted(chain, out, fresh or args.restart, made_folder)
            raise
        if not args.quiet:
            print("  writing the report (figures, posterior.nc, summary.json, report.html)", file=sys.stderr)
        summary = write_run_report(inv, out, args.data, references=references)
    for flag in summary["identifiability"].get("at_bound", []):
        from .infer.identifiability import bound_finding

        print(f"warning: {bound_finding(flag)}")
    from .infer.inversion import noise_findings

    for line in noise_findings(summary.get("noise", {})):
        print(f"noise: {line}")
    d = summary["diagnostics"]
    print(f"wrote {out}/summary.json, posterior.nc, corner.png, fit.png, residuals.png, residual_trends.png, report.html "
          f"(R-hat max {d['rhat_max']:.4f}, ESS min {d['ess_min']:.0f}, {summary['seconds']:.1f} s)")
    return 0


def _discard_unstarted(chain: Path, out: Path, fresh: bool, made_folder: bool) -> None:
    """A run that failed before its first stored step leaves nothing behind that would block the
    corrected command (a chain stamped with the failed run's settings would)."""
    from .infer.chain_file import ChainFileError, chain_iterations

    try:
        empty = fresh and chain.exists() and chain_iterations(chain) == 0
    except ChainFileError:
        empty = fresh
    if empty:
        chain.unlink(missing_ok=True)
    if made_folder and out.is_dir() and not any(p.name != ".spacepol.lock" for p in out.iterdir()):
        import shutil

        shutil.rmtree(out, ignore_errors=True)


def optimize(args) -> int:
    import json

    from .infer.engines import optimize as run_optimizer
    from .infer.objective import PaperObjective
    from .infer.prior_set import PriorSet
    from .io.atomic import _jsonable

    from .infer.engines import check_method

    check_method(args.method)
    data = load_dataset(args)
    if args.method == "emcee":
        from .infer.inversion import invert

        inv = invert(build_posterior(args, data), seed=args.seed, progress=False)
        result = inv.result
    else:
        posterior = build_posterior(args, data)
        model = posterior.likelihood.model
        model_priors = PriorSet(model.parameters, {n: posterior.priors.priors[n] for n in posterior.priors.priors
                                                   if n in {p.name for p in model.parameters}})
        result = run_optimizer(args.method, PaperObjective(data, model, model_priors),
                               np.random.default_rng(args.seed), model.name, seed=args.seed)
    print(json.dumps(_jsonable(result.to_json()), indent=2))
    return 0


def compare(args) -> int:
    from .report.compare import run_comparison

    from .infer.engines import check_method

    check_output_dir(args.out)
    for method in args.methods or []:
        check_method(method)
    data = load_dataset(args)
    posterior = build_posterior(args, data)
    run_comparison(posterior, data, Path(args.out), methods=args.methods, seeds=args.seeds, base_seed=args.seed)
    return 0


def diagnose(args) -> int:
    from .criticism.diagnose import diagnose as run_diagnose
    from .io.atomic import write_json
    from .physics.registry import registry
    from .report.diagnose_report import significance_statement, write_diagnose_report

    from .infer.prior_set import read_prior_file

    check_output_file(args.json, "--json")
    check_output_dir(args.out)
    build_model(args.model)  # a wrong name fails before the data are read
    priors = read_prior_file(args.prior) if args.prior else None
    for name in args.candidates or []:
        registry.get(name)
    if args.top < 1:
        raise ParameterError(f"--top {args.top}: need at least 1")
    data = load_dataset(args)
    model = model_for(args, data)  # over several wavelengths: n, k per wavelength
    observables = parse_observables(args.observables)
    rng = np.random.default_rng(args.seed)
    if args.rounds:
        from .criticism.rounds import as_rungs, diagnose_rounds

        result = diagnose_rounds(data, model, rng, args.rounds, seed=args.seed, observables=observables,
                                 candidates=args.candidates, top=args.top, priors=priors, posterior_method=args.posterior)
        rungs = as_rungs(result)
        first = result.pop("_reports")[0]
        report = result
        base, confirmed = first["_base"], first["_confirmed"]
    else:
        report = run_diagnose(data, model, rng, seed=args.seed, observables=observables,
                              candidates=args.candidates, top=args.top, priors=priors, posterior_method=args.posterior)
        base, confirmed = report.pop("_base"), report.pop("_confirmed")
        rungs = None
    write_diagnose_report(report, base, confirmed, Path(args.out), str(args.data), path_rungs=rungs)
    write_json(args.json, report)
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
    from .criticism.changes import parse
    from .criticism.ladder import climb
    from .report.ladder_report import write_ladder_report

    check_output_dir(args.out)
    if args.json:
        check_output_file(args.json, "--json")
    model = build_model(args.model)
    steps = list(args.add)
    if args.replay:
        steps = replay_steps(args.replay, model) + steps
    if not steps:
        raise ParameterError("ladder: give at least one --add CHANGE or --replay DIAGNOSE.json")
    current = model
    for step in steps:  # check the whole ladder composes before fitting anything
        current = parse(current, step).model
    data = load_dataset(args)
    model = model_for(args, data)
    observables = parse_observables(args.observables)
    rungs = climb(data, model, steps, seed=args.seed, observables=observables)
    out = Path(args.out)
    print("\n".join(write_ladder_report(rungs, out, args.json)))
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
    from .criticism.design import design as rank_measurements
    from .infer.optimum import find_optimum
    from .report.design_report import write_design_report

    out = check_output_dir(args.out)
    data = load_dataset(args)
    posterior = build_posterior(args, data)
    print(f"design: the optimum of {posterior.likelihood.model.name} on {len(data)} geometries "
          f"({', '.join(posterior.likelihood.observables)}), then the Fisher information of every candidate", file=sys.stderr)
    _, theta = find_optimum(posterior, np.random.default_rng(args.seed))
    point = {k: float(np.ravel(v)[0]) for k, v in posterior.priors.to_params(theta[None, :]).items()}
    noise = {}
    for item in args.noise:
        name, sep, text = item.partition("=")
        try:
            noise[name.strip()] = float(text)
        except ValueError:
            raise ParameterError(f"--noise '{item}': expected dop=X, brdf=REL or mueller=X") from None
        if not sep or name.strip() not in ("dop", "brdf", "mueller") or not noise[name.strip()] > 0:
            raise ParameterError(f"--noise '{item}': expected dop=X, brdf=REL or mueller=X with X > 0")
    report = rank_measurements(posterior, point, picks=args.picks, noise=noise)
    lines = write_design_report(report, out, args.data)
    print("\n".join(lines[2:3]))
    print(f"wrote {out}/design.md, design.json, design.png")
    return 0


def batch(args) -> int:
    from .batch import run_batch

    rows = run_batch(args.manifest, args.out, executor=args.executor, scheduler=args.scheduler, workers=args.workers,
                     progress=not args.quiet)
    counts = {s: sum(r["status"] == s for r in rows) for s in ("ok", "skipped", "failed")}
    print(f"wrote {args.out}/results.csv: {counts['ok']} ok, {counts['skipped']} skipped (finished before), "
          f"{counts['failed']} failed" + ("".join(f"\n  failed {r['id']}: {r['error']}" for r in rows if r["status"] == "failed")))
    return 1 if counts["failed"] else 0


def _parse_direction(text: str) -> tuple[float, float]:
    try:
        zen, az = (float(v) for v in text.split(","))
    except ValueError:
        raise ParameterError(f"--direction '{text}': expected ZENITH,AZIMUTH in degrees, e.g. 60,101.5") from None
    if not 0 <= zen <= 90:
        raise ParameterError(f"--direction '{text}': zenith angle must lie in [0, 90] deg")
    if not np.isfinite(az):
        raise ParameterError(f"--direction '{text}': azimuth {az:g} deg is not a finite number")
    return zen, az


def sky(args) -> int:
    from .io.atomic import save_figure, write_json
    from .report.sky_figures import projection_distortion_figure, sky_maps_figure
    from .sky.neutral_points import BerryDennisLeeSky
    from .sky.projections import PROJECTIONS, cap_fraction
    from .sky.rayleigh import RayleighSky
    from .sky.sun import sun_position

    check_output_dir(args.out)
    directions = [_parse_direction(d) for d in args.direction]
    if args.model == "rayleigh":
        model = RayleighSky(1.0 if args.p_max is None else args.p_max)
    else:
        model = BerryDennisLeeSky(0.8 if args.p_max is None else args.p_max, args.delta_deg)
    sun = sun_position(args.lat, args.lon, args.time)
    s = (sun.zenith_deg, sun.azimuth_deg)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {
        "sun": {"zenith_deg": sun.zenith_deg, "azimuth_deg": sun.azimuth_deg, "altitude_deg": sun.altitude_deg,
                "time_utc": sun.time_utc, "azimuth_convention": "degrees east of north", "refraction": "none"},
        "site": {"lat_deg": args.lat, "lon_deg": args.lon, "time": args.time},
        "model": {"name": model.name, "p_max": model.p_max} | ({"delta_deg": model.delta_deg} if args.model != "rayleigh" else {}),
        "aop_frame": "angle of the E-vector from the local meridian (towards the zenith), positive towards increasing azimuth",
        "sun_below_horizon": bool(sun.zenith_deg > 90),
        "directions": [{"zenith_deg": z, "azimuth_deg": a, "dop": float(model.dop(z, a, s)), "aop_deg": float(model.aop(z, a, s))}
                       for z, a in directions],
        "projections": {name: {"zenith_30_cap_share_of_map": cap_fraction(p, 30.0),
                               "max_angular_distortion_deg": float(p.tissot(89.999)["angular_distortion_deg"]),
                               "areal_scale_at_horizon": float(p.tissot(89.999)["areal_scale"])}
                        for name, p in PROJECTIONS.items()},
    }
    points = {f"target {i + 1}": d for i, d in enumerate(directions)}
    if args.model != "rayleigh":
        report["neutral_points"] = {k: {"zenith_deg": z, "azimuth_deg": a} for k, (z, a) in model.neutral_points(s).items()}
        points.update(model.neutral_points(s))
    save_figure(sky_maps_figure(model, s, points), out / "sky_maps.png")
    save_figure(projection_distortion_figure(), out / "projections.png")
    write_json(out / "sky.json", report)
    print(f"sun: zenith {sun.zenith_deg:.2f} deg, azimuth {sun.azimuth_deg:.2f} deg east of north ({sun.time_utc})")
    if sun.zenith_deg > 90:
        print(f"note: the sun is {sun.zenith_deg - 90:.1f} deg below the horizon: there is no daylight sky then; the maps "
              f"show the single-scattering pattern for reference only")
    for d in report["directions"]:
        print(f"  zenith {d['zenith_deg']:g}, azimuth {d['azimuth_deg']:g}: DOP {d['dop']:.3f}, AoP {d['aop_deg']:.1f} deg")
    print(f"wrote {out}/sky.json, sky_maps.png, projections.png")
    return 0


def contrast(args) -> int:
    from .detect.scenario import default_scenario, read_scenario
    from .report.contrast_report import make_contrast_report, table3_lines

    scenario = read_scenario(args.scenario) if args.scenario else default_scenario()
    out = check_output_dir(Path(args.out) if args.out else Path(args.run_dir) / "contrast")
    report = make_contrast_report(args.run_dir, scenario, out, args.reading, args.draws, args.seed, args.extrapolate)
    print("\n".join(table3_lines(report)))
    print(report["dominance"])
    print(f"wrote {out}/contrast.json, table3.md, contrast_histograms.png, report.html")
    return 0
