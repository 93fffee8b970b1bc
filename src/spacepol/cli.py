"""``invert-mcmc``: the one command-line entry point.  Parsing only; the work is in spacepol.commands."""

from __future__ import annotations

import argparse
import math
import sys


def _int_at_least(low: int):
    def parse(text: str) -> int:
        """An argparse type: a whole number >= the bound, else one line naming the value."""
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"{value}: must be >= {low}")
        return value
    parse.__name__ = f"integer >= {low}"
    return parse


def _wavelengths(text: str):
    """``0.633`` -> 0.633; ``0.532,0.633`` -> [0.532, 0.633]; ``all`` -> "all"."""
    from .api import parse_wavelengths
    from .errors import ParameterError

    try:
        return parse_wavelengths(text)
    except ParameterError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _finite(low: float | None = None, strict: bool = False):
    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"'{text}' is not a finite number")
        if low is not None and (value <= low if strict else value < low):
            raise argparse.ArgumentTypeError(f"{value:g}: must be {'>' if strict else '>='} {low:g}")
        return value
    parse.__name__ = "number"
    return parse


SEED = _int_at_least(0)  # numpy's Generator takes seeds >= 0


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit status 2 (argparse would print the usage too)
        self.exit(2, f"{self.prog}: error: {message}\n")


def _data_options(p) -> None:
    """The options every command that reads a measurement file takes."""
    p.add_argument("data", help="measurement file (spacepol CSV or NIST Mueller BRDF)")
    p.add_argument("--model", default="paper")
    p.add_argument("--prior", metavar="FILE.toml", help="prior overrides (and fixed parameters)")
    p.add_argument("--wavelength-um", type=_wavelengths, metavar="UM|LIST|all",
                   help="one wavelength of a multi-wavelength file, a comma list, or all (inverted jointly: "
                        "n, k per wavelength as n@LAMBDA, the rest shared)")
    p.add_argument("--dispersion", metavar="n=cauchy", help="a dispersion law for n over several wavelengths")
    p.add_argument("--in-plane", action="store_true", help="keep only the plane of incidence (dphi = 0, 180)")
    p.add_argument("--observables", help="comma-separated dop,brdf,q,u (default: dop and brdf where the file has them)")
    p.add_argument("--seed", type=SEED, default=0)


def _data_commands(sub) -> None:
    """demo, forward, synth, effects: the forward model and the bundled data."""
    p = sub.add_parser("demo", help="the whole chain on bundled data; report in DIR")
    p.add_argument("--out", default="reports/demo")

    p = sub.add_parser("forward", help="evaluate a model at the geometries of a CSV file")
    p.add_argument("geometry")
    p.add_argument("--model", default="paper")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("--out", required=True)

    p = sub.add_parser("synth", help="write a synthetic measurement file from any model")
    p.add_argument("--model", default="paper")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("--geometry", help="CSV with theta_i, theta_r[, dphi]; default: 4 x 21 in-plane grid")
    p.add_argument("--noise-dop", type=_finite(0.0), default=0.0, metavar="X", help="Gaussian DOP noise (absolute)")
    p.add_argument("--noise-brdf", type=_finite(0.0), default=None, metavar="REL",
                   help="also write BRDF with this relative Gaussian noise")
    p.add_argument("--wavelength-um", type=_finite(0.0, strict=True), default=None)
    p.add_argument("--seed", type=SEED, default=0)
    p.add_argument("--out", required=True)

    sub.add_parser("effects", help="list every registered effect: parameters, priors, units, physics")


def _inference_commands(sub) -> None:
    """run, optimize, compare: posteriors and the optimizers."""
    p = sub.add_parser("run", help="posterior (emcee by default) with corner, fit and residual plots and a report")
    _data_options(p)
    p.add_argument("--walkers", type=_int_at_least(2), default=None, help="even, >= 2 x parameters (default 32 or more)")
    p.add_argument("--steps", type=_int_at_least(100), default=None, help="emcee: cap on the chain length (default 20000)")
    p.add_argument("--engine", default="emcee", metavar="NAME",
                   help="the sampler: emcee (default), laplace, nuts, an entry point of group spacepol.engines, or "
                        "path/to/engine.py:Name")
    p.add_argument("--engine-option", action="append", default=[], metavar="KEY=VALUE",
                   help="an option of the engine's run (e.g. replicates=5 for nested; repeatable)")
    p.add_argument("--restart", action="store_true",
                   help="start the chain afresh; an existing chain.h5 is kept aside as chain.h5.old")
    p.add_argument("--robust", action="store_true", help="Student-t likelihood (nu = 4) instead of Gaussian")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument("--reference", action="append", default=[], metavar="NAME=VALUE",
                   help="a known value to compare the posterior with (e.g. n=1.35 for PTFE)")
    p.add_argument("--out", default="reports/run")

    p = sub.add_parser("optimize", help="one optimizer's best fit as JSON on stdout")
    _data_options(p)
    p.add_argument("--method", required=True, help="ga, de, emcee, or nlopt:ALGO")

    p = sub.add_parser("compare", help="every optimizer, several seeds, against the posterior")
    _data_options(p)
    p.add_argument("--methods", nargs="+", default=None)
    p.add_argument("--seeds", type=_int_at_least(1), default=3, help="runs per method")
    p.add_argument("--out", default="reports/compare")


def _criticism_commands(sub) -> None:
    """diagnose, ladder, design, batch: model criticism and many sets."""
    p = sub.add_parser("diagnose", help="rank the registered effects that would explain the misfit")
    _data_options(p)
    p.add_argument("--json", required=True, metavar="FILE", help="write the ranking here")
    p.add_argument("--candidates", nargs="+", default=None, help="effects to consider (default: every registered one)")
    p.add_argument("--top", type=_int_at_least(1), default=3, help="candidates confirmed by a full refit")
    p.add_argument("--rounds", type=_int_at_least(1), default=None, metavar="N",
                   help="accept the best significant change and continue from the changed model, up to N rounds")
    p.add_argument("--criterion", choices=("loo", "evidence"), default="loo",
                   help="what ranks the refitted changes: delta ELPD-LOO, or the ln Bayes factor (evidence from "
                        "Laplace-IS where trusted, else nested sampling); both are reported where known")
    p.add_argument("--workers", type=_int_at_least(1), default=1, metavar="N",
                   help="candidates searched and refitted at once, each in its own process (at most the cores; the "
                        "answer does not depend on it)")
    p.add_argument("--posterior", choices=("laplace", "emcee"), default="laplace",
                   help="each fit's posterior: a Laplace approximation corrected by importance sampling where its Pareto k "
                        "trusts it, else emcee (default), or emcee always")
    p.add_argument("--out", default="reports/diagnose")

    p = sub.add_parser("ladder", help="fit M, M + E1, M + E1 + E2, ...: the error falling rung by rung")
    _data_options(p)
    p.add_argument("--add", action="append", default=[], metavar="CHANGE",
                   help="the next rung's change: an effect to add, or 'replace A by B', or 'remove E' (repeatable)")
    p.add_argument("--replay", metavar="DIAGNOSE.json", help="replay the path of `diagnose --rounds` (its changes, in order)")
    p.add_argument("--json", metavar="FILE", help="write the rungs here (default DIR/ladder.json)")
    p.add_argument("--out", default="reports/ladder")

    p = sub.add_parser("design", help="which further measurements would break a degeneracy (Fisher information)")
    _data_options(p)
    p.add_argument("--picks", type=_int_at_least(1), default=3, help="measurements to propose (chosen greedily)")
    p.add_argument("--noise", action="append", default=[], metavar="OBS=X",
                   help="assumed noise of a new measurement of observable OBS, e.g. dop=0.005, brdf=0.03 (relative), "
                        "mueller=0.01 (default: the data's own, else each observable's design noise; the candidates are "
                        "the observables that declare one)")
    p.add_argument("--out", default="reports/design")

    p = sub.add_parser("batch", help="one inversion per row of a manifest, on a process pool or a Dask cluster")
    p.add_argument("manifest", metavar="MANIFEST.csv",
                   help="columns id, data (relative to the manifest), optional model, observables, prior, seed, wavelength_um")
    p.add_argument("--executor", default="local", choices=["local", "dask"],
                   help="local process pool (default) or Dask distributed (a LocalCluster unless --scheduler)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--workers", type=_int_at_least(1), default=None, help="local workers (default: one per core)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.add_argument("--out", default="reports/batch")


def _pass_arguments(p) -> None:
    """A satellite's pass: its elements, the site and the time window (observe, synth-pass, lightcurve)."""
    p.add_argument("--tle", required=True, metavar="FILE", help="two- or three-line element sets (e.g. data/tle/)")
    p.add_argument("--satellite", default=None, metavar="NAME", help="which satellite of the file (name or number)")
    p.add_argument("--site", required=True, metavar="LAT,LON[,HEIGHT_M]")
    p.add_argument("--start", required=True, metavar="ISO8601", help="with UTC offset, e.g. 2014-01-21T00:33Z")
    p.add_argument("--end", required=True, metavar="ISO8601")
    p.add_argument("--step", type=_finite(0.0), default=10.0, metavar="S", help="seconds between times")


def _sky_commands(sub) -> None:
    """sky, contrast, observe, frame: from a posterior to the sky and a camera."""
    p = sub.add_parser("sky", help="the sun (astropy) and the sky's polarization at a site and time; maps")
    p.add_argument("--lat", type=_finite(), required=True, metavar="DEG", help="latitude, north positive")
    p.add_argument("--lon", type=_finite(), required=True, metavar="DEG", help="longitude, east positive")
    p.add_argument("--time", required=True, metavar="ISO8601", help="with UTC offset, e.g. 2020-12-16T11:42+08:00")
    p.add_argument("--model", default="rayleigh", choices=["rayleigh", "berry-dennis-lee"])
    p.add_argument("--p-max", type=_finite(0.0), default=None, help="maximum DOP (default 1 for rayleigh, 0.8 for berry-dennis-lee)")
    p.add_argument("--delta-deg", type=_finite(0.0), default=20.0, help="berry-dennis-lee: neutral points' distance from the sun")
    p.add_argument("--direction", action="append", default=[], metavar="ZENITH,AZIMUTH",
                   help="a direction (deg) at which to report DOP and AoP (repeatable)")
    p.add_argument("--out", default="reports/sky")

    p = sub.add_parser("contrast", help="Table 3 as distributions from the posterior of a run")
    p.add_argument("run_dir", metavar="RUN_DIR", help="the --out folder of `invert-mcmc run`")
    p.add_argument("--scenario", metavar="FILE.toml", help="default: the paper's section 4 and Table 2")
    p.add_argument("--reading", default="corrected", choices=["corrected", "paper"],
                   help="micro-polarizer: superpixel mean 1/2 (corrected) or (1 + P)/2 (paper)")
    p.add_argument("--draws", type=_int_at_least(100), default=20000, help="posterior draws pushed through (>= 100)")
    p.add_argument("--extrapolate", action="store_true",
                   help="a run over several wavelengths: allow a scenario wavelength outside the measured ones (n from "
                        "the run's dispersion law, else held at the nearest measured wavelength's value)")
    p.add_argument("--seed", type=SEED, default=0)
    p.add_argument("--out", default=None, help="default: RUN_DIR/contrast")
    p = sub.add_parser("observe", help="a satellite's pass: light curves and P_d(t) per detector from a run's posterior")
    p.add_argument("run_dir", metavar="RUN_DIR", help="the --out folder of `invert-mcmc run` (the target's material)")
    _pass_arguments(p)
    p.add_argument("--target", default=None, metavar="FILE.toml", help="[[faces]] (default: a 1 m cube and a 4 m^2 panel)")
    p.add_argument("--camera", default=None, metavar="FILE.toml", help="[camera] (default: an IMX250MZR-class sensor)")
    p.add_argument("--draws", type=_int_at_least(1), default=200, help="posterior draws of the material")
    p.add_argument("--exposures", type=_int_at_least(1), default=1, metavar="N", help="exposures averaged per time step")
    p.add_argument("--sky-zenith-mag", type=float, default=5.40, metavar="MAG",
                   help="the sky's radiance at the zenith in the band, mag arcsec^-2 (default 5.40, the paper's)")
    p.add_argument("--p-max", type=float, default=0.7, help="the sky's maximum degree of polarization (Rayleigh)")
    p.add_argument("--seed", type=SEED, default=0)
    p.add_argument("--out", default=None, help="default: RUN_DIR/observe")
    p = sub.add_parser("synth-pass", help="a simulated measured light curve (flux, DoLP, AoP) of a target over a pass")
    _pass_arguments(p)
    p.add_argument("--target", required=True, metavar="FILE.toml",
                   help="[[faces]], each with its material table; an optional attitude = {yaw_deg, pitch_deg, roll_deg}")
    p.add_argument("--camera", default=None, metavar="FILE.toml", help="[camera] (default: an IMX250MZR-class sensor)")
    p.add_argument("--exposures", type=_int_at_least(1), default=None, metavar="N",
                   help="frames averaged per time step (default: as many as fill the step)")
    p.add_argument("--sky-zenith-mag", type=float, default=5.40, metavar="MAG",
                   help="the sky's radiance at the zenith in the band, mag arcsec^-2 (default 5.40, the paper's)")
    p.add_argument("--seed", type=SEED, default=0)
    p.add_argument("--out", required=True, metavar="FILE.csv", help="the light curve: time_utc,flux,flux_err,dolp,...")
    p.set_defaults(command="synth_pass")
    p = sub.add_parser("lightcurve", help="a satellite's material and attitude from its measured light curve")
    p.add_argument("curve", metavar="FILE.csv", help="time_utc and any of flux, dolp, aop_deg with their _err columns")
    _pass_arguments(p)
    p.add_argument("--target", required=True, metavar="FILE.toml",
                   help="[[faces]]: those without a material table are of the unknown material; an optional attitude "
                        "table fixes the offsets (inferred where absent)")
    p.add_argument("--materials", required=True, metavar="NAME,...",
                   help="candidate materials: aluminium, kapton, white_paint, solar_glass")
    p.add_argument("--observables", default=None, metavar="NAME,...", help="flux, dolp, aop (default: all the file holds)")
    p.add_argument("--live", type=_int_at_least(50), default=500, help="nested sampling's live points per material")
    p.add_argument("--seed", type=SEED, default=0)
    p.add_argument("--out", default=None, help="default: a folder named after the CSV, beside it")
    p = sub.add_parser("frame", help="a raw micro-polarizer frame (IMX250MZR mosaic) as Stokes, DoLP and AoP maps")
    p.add_argument("raw", metavar="RAW.png", help="an 8- or 16-bit single-channel image of the raw mosaic")
    p.add_argument("--method", choices=("superpixel", "bilinear"), default="superpixel")
    p.add_argument("--out", default=None, help="default: a folder named after the image, beside it")



def build_parser() -> argparse.ArgumentParser:
    """The `invert-mcmc` argument parser: every command, option and its help (the CLI reference is generated from it)."""
    parser = _Parser(prog="invert-mcmc", description="Probabilistic inversion of polarimetric reflectance.")
    parser.add_argument("--effect", action="append", default=[], metavar="FILE.py:NAME",
                        help="load a user-defined effect (repeatable); it is then usable by name")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    for add_commands in (_data_commands, _inference_commands, _criticism_commands, _sky_commands):
        add_commands(sub)
    for p in sub.choices.values():  # --effect also after the command name, where users put it
        p.add_argument("--effect", action="append", default=[], dest="effect_after", metavar="FILE.py:NAME",
                       help="load a user-defined effect (repeatable); it is then usable by name")
    return parser


def main(argv=None) -> int:
    """``invert-mcmc``: parse ``argv`` (default sys.argv), opt in to the process settings, run the command; a
    SpacepolError becomes one line on stderr and exit status 2. Returns the exit status."""
    args = build_parser().parse_args(argv)
    import os
    import warnings

    if not os.environ.get("SPACEPOL_SHOW_WARNINGS"):  # third-party deprecation chatter is not for users
        warnings.filterwarnings("ignore", category=FutureWarning)
        warnings.filterwarnings("ignore", category=DeprecationWarning)
        warnings.filterwarnings("ignore", module=r"jax\..*")  # e.g. an unreadable entry of the compilation cache
    from ._runtime import configure_process

    # before numpy's BLAS and JAX's backend start: the speed settings, and a command's many small calls (samplers,
    # optimizers) on the calling thread
    configure_process(small_calls=True)
    from . import commands
    from .errors import SamplerStalled, SpacepolError

    try:
        for spec in args.effect + getattr(args, "effect_after", []):
            from .physics.registry import registry

            registry.load_file(spec)
        return getattr(commands, args.command)(args) or 0
    except SpacepolError as exc:
        print(f"invert-mcmc: error: {exc}", file=sys.stderr)
        return 2
    except SamplerStalled as exc:
        print(f"invert-mcmc: {exc}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # e.g. `invert-mcmc effects | head`
        sys.stderr.close()
        return 0
    except KeyboardInterrupt:
        print("invert-mcmc: interrupted; the same command continues where it stopped", file=sys.stderr)
        return 130
    except OSError as exc:  # the file system said no (disk full, permissions changed mid-run, ...)
        where = f" {exc.filename}" if exc.filename else ""
        print(f"invert-mcmc: error:{where}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print("invert-mcmc: error: out of memory; use fewer geometries, walkers or draws", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug of ours: say so in one line; the traceback on request
        if os.environ.get("SPACEPOL_TRACEBACK"):
            raise
        print(f"invert-mcmc: internal error: {type(exc).__name__}: {exc} "
              f"(a bug in spacepol; set SPACEPOL_TRACEBACK=1 for the traceback and report it)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
