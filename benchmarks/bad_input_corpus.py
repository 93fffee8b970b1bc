"""A corpus of bad and odd inputs run against the CLI, in separate processes as a user would:
every invalid input must give exit status 2, one line on stderr, no traceback and nothing left
behind; every valid (if unusual) input must succeed.  Prints one line per case and a tally.

    python benchmarks/bad_input_corpus.py [--jobs 2] [--only SUBSTRING]

The fast in-process version of the same categories is tests/test_bad_input.py.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

GOOD = "theta_i,theta_r,dop\n" + "".join(f"{ti},{tr},0.{(ti + tr) % 9 + 1}\n" for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65))
GOOD_BRDF = "theta_i,theta_r,dop,brdf\n" + "".join(f"{ti},{tr},0.{(ti + tr) % 9 + 1},{0.1 + tr / 100}\n"
                                                   for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65))
NIST_HEAD = "lambda,thetai,phi,thetar,phir,f_r11," + ",".join(f"f_r{i}{j}/f_r11" for i in range(1, 5) for j in range(1, 5) if (i, j) != (1, 1))


def nist_row(lam=0.633, ti=-30.0, tr=20.0, phir=0.0, fr11=0.3, m=None):
    m = m or {}
    values = [m.get(f"{i}{j}", 0.0) for i in range(1, 5) for j in range(1, 5) if (i, j) != (1, 1)]
    return ",".join(map(str, [lam, ti, 0, tr, phir, fr11] + values))


PLUGIN = "import sys\nimport numpy as np\nfrom spacepol.physics.effect import Effect\n\nclass P(Effect):\n    name = 'p_eff'\n    def lobe(self, ctx):\n        {body}\n"
SKY = ["sky", "--lat", "43", "--lon", "125"]

# (name, files {name: text | bytes}, argv, "error" | "ok")
CASES = [
    # output locations
    ("out is a file", {"d.csv": GOOD, "f": "x"}, ["forward", "d.csv", "--out", "f/x.csv"], "error"),
    ("run out is a file", {"d.csv": GOOD, "f": "x"}, ["run", "d.csv", "--out", "f"], "error"),
    ("run out under a file", {"d.csv": GOOD, "f": "x"}, ["run", "d.csv", "--out", "f/deeper/run"], "error"),
    ("run out under /proc", {"d.csv": GOOD}, ["run", "d.csv", "--out", "/proc/spacepol"], "error"),
    ("run out under /sys", {"d.csv": GOOD}, ["run", "d.csv", "--out", "/sys/spacepol"], "error"),
    ("forward out is a folder", {"d.csv": GOOD}, ["forward", "d.csv", "--out", "."], "error"),
    ("forward out ends in /", {"d.csv": GOOD}, ["forward", "d.csv", "--out", "new/"], "error"),
    ("synth out /proc", {}, ["synth", "--out", "/proc/s.csv"], "error"),
    ("diagnose json folder", {"d.csv": GOOD}, ["diagnose", "d.csv", "--json", ".", "--out", "dg"], "error"),
    ("diagnose json under file", {"d.csv": GOOD, "f": "x"}, ["diagnose", "d.csv", "--json", "f/r.json"], "error"),
    ("ladder json folder", {"d.csv": GOOD}, ["ladder", "d.csv", "--add", "dop_bias", "--json", "."], "error"),
    ("compare out file", {"d.csv": GOOD, "f": "x"}, ["compare", "d.csv", "--out", "f"], "error"),
    ("sky out file", {"f": "x"}, SKY + ["--time", "2026-11-22T12:00Z", "--out", "f"], "error"),
    ("contrast out file", {"f": "x"}, ["contrast", ".", "--out", "f"], "error"),
    ("demo out file", {"f": "x"}, ["demo", "--out", "f"], "error"),
    # seeds and counts
    ("seed -1", {"d.csv": GOOD}, ["run", "d.csv", "--seed", "-1"], "error"),
    ("seed 1.5", {"d.csv": GOOD}, ["run", "d.csv", "--seed", "1.5"], "error"),
    ("synth seed -3", {}, ["synth", "--seed", "-3", "--out", "s.csv"], "error"),
    ("walkers 0", {"d.csv": GOOD}, ["run", "d.csv", "--walkers", "0"], "error"),
    ("walkers odd", {"d.csv": GOOD}, ["run", "d.csv", "--walkers", "13"], "error"),
    ("walkers too few", {"d.csv": GOOD}, ["run", "d.csv", "--walkers", "4"], "error"),
    ("steps 0", {"d.csv": GOOD}, ["run", "d.csv", "--steps", "0"], "error"),
    ("steps text", {"d.csv": GOOD}, ["run", "d.csv", "--steps", "lots"], "error"),
    ("compare seeds 0", {"d.csv": GOOD}, ["compare", "d.csv", "--seeds", "0"], "error"),
    ("compare seeds -2", {"d.csv": GOOD}, ["compare", "d.csv", "--seeds", "-2"], "error"),
    ("compare bad method", {"d.csv": GOOD}, ["compare", "d.csv", "--methods", "ga", "nlopt:LN_BOBYQA"], "error"),
    ("compare method twice", {"d.csv": GOOD}, ["compare", "d.csv", "--methods", "ga", "ga"], "error"),
    ("optimize unknown", {"d.csv": GOOD}, ["optimize", "d.csv", "--method", "lbfgs"], "error"),
    ("diagnose top 0", {"d.csv": GOOD}, ["diagnose", "d.csv", "--json", "r.json", "--top", "0"], "error"),
    ("diagnose unknown candidate", {"d.csv": GOOD}, ["diagnose", "d.csv", "--json", "r.json", "--candidates", "glitter"], "error"),
    ("ladder unknown add", {"d.csv": GOOD}, ["ladder", "d.csv", "--add", "glitter"], "error"),
    ("ladder add present", {"d.csv": GOOD}, ["ladder", "d.csv", "--add", "body"], "error"),
    ("contrast draws 10", {}, ["contrast", ".", "--draws", "10"], "error"),
    # observables
    ("observables twice", {"d.csv": GOOD}, ["run", "d.csv", "--observables", "dop,dop"], "error"),
    ("observables unknown", {"d.csv": GOOD}, ["run", "d.csv", "--observables", "dolp"], "error"),
    ("observables empty", {"d.csv": GOOD}, ["run", "d.csv", "--observables", ","], "error"),
    ("observables absent", {"d.csv": GOOD}, ["run", "d.csv", "--observables", "brdf"], "error"),
    ("diagnose observables twice", {"d.csv": GOOD}, ["diagnose", "d.csv", "--json", "r.json", "--observables", "dop,dop"], "error"),
    # numbers
    ("noise nan", {}, ["synth", "--noise-dop", "nan", "--out", "s.csv"], "error"),
    ("noise inf", {}, ["synth", "--noise-dop", "inf", "--out", "s.csv"], "error"),
    ("noise negative", {}, ["synth", "--noise-brdf", "-0.1", "--out", "s.csv"], "error"),
    ("set nan", {}, ["synth", "--set", "n=nan", "--out", "s.csv"], "error"),
    ("set inf", {}, ["synth", "--set", "sigma=inf", "--out", "s.csv"], "error"),
    ("set unknown", {}, ["synth", "--set", "zeta=1", "--out", "s.csv"], "error"),
    ("set no value", {}, ["synth", "--set", "n=", "--out", "s.csv"], "error"),
    ("wavelength 0", {}, ["synth", "--wavelength-um", "0", "--out", "s.csv"], "error"),
    ("wavelength -1 run", {"d.csv": GOOD}, ["run", "d.csv", "--wavelength-um", "-1"], "error"),
    ("wavelength nan", {"d.csv": GOOD}, ["run", "d.csv", "--wavelength-um", "nan"], "error"),
    ("lat nan", {}, SKY[:1] + ["--lat", "nan", "--lon", "1", "--time", "2026-11-22T12:00Z"], "error"),
    ("lat 91", {}, SKY[:1] + ["--lat", "91", "--lon", "1", "--time", "2026-11-22T12:00Z"], "error"),
    ("lon inf", {}, SKY[:1] + ["--lat", "1", "--lon", "inf", "--time", "2026-11-22T12:00Z"], "error"),
    ("p-max -1", {}, SKY + ["--time", "2026-11-22T12:00Z", "--p-max", "-1"], "error"),
    ("direction text", {}, SKY + ["--time", "2026-11-22T12:00Z", "--direction", "up"], "error"),
    ("direction zenith 120", {}, SKY + ["--time", "2026-11-22T12:00Z", "--direction", "120,0"], "error"),
    # dates
    ("time naive", {}, SKY + ["--time", "2026-11-22T12:00"], "error"),
    ("time year 1", {}, SKY + ["--time", "0001-01-01T00:00Z"], "error"),
    ("time year 9999", {}, SKY + ["--time", "9999-12-31T23:59:59+14:00"], "error"),
    ("time feb 30", {}, SKY + ["--time", "2021-02-30T00:00Z"], "error"),
    ("time words", {}, SKY + ["--time", "tomorrow noon"], "error"),
    ("time empty", {}, SKY + ["--time", ""], "error"),
    # measurement files
    ("missing file", {}, ["run", "nope.csv"], "error"),
    ("folder as data", {"dir/x": "x"}, ["run", "dir"], "error"),
    ("empty file", {"d.csv": ""}, ["run", "d.csv"], "error"),
    ("header only", {"d.csv": "theta_i,theta_r,dop\n"}, ["run", "d.csv"], "error"),
    ("unknown column", {"d.csv": "theta_i,theta_r,dop,colour\n1,2,0.1,red\n"}, ["run", "d.csv"], "error"),
    ("duplicate column", {"d.csv": "theta_i,theta_r,dop,dop\n1,2,0.1,0.1\n"}, ["run", "d.csv"], "error"),
    ("missing theta_r", {"d.csv": "theta_i,dop\n1,0.1\n"}, ["run", "d.csv"], "error"),
    ("no observable", {"d.csv": "theta_i,theta_r\n1,2\n"}, ["run", "d.csv"], "error"),
    ("text in number", {"d.csv": "theta_i,theta_r,dop\n10,x,0.1\n"}, ["run", "d.csv"], "error"),
    ("nan in cell", {"d.csv": "theta_i,theta_r,dop\n10,20,nan\n"}, ["run", "d.csv"], "error"),
    ("inf in cell", {"d.csv": "theta_i,theta_r,dop\n10,20,inf\n"}, ["run", "d.csv"], "error"),
    ("dop 1.2", {"d.csv": "theta_i,theta_r,dop\n10,20,1.2\n"}, ["run", "d.csv"], "error"),
    ("dop -0.1", {"d.csv": "theta_i,theta_r,dop\n10,20,-0.1\n"}, ["run", "d.csv"], "error"),
    ("angle 90", {"d.csv": "theta_i,theta_r,dop\n90,20,0.1\n"}, ["run", "d.csv"], "error"),
    ("angle -95", {"d.csv": "theta_i,theta_r,dop\n10,-95,0.1\n"}, ["run", "d.csv"], "error"),
    ("negative error", {"d.csv": "theta_i,theta_r,dop,dop_err\n10,20,0.1,-1\n"}, ["run", "d.csv"], "error"),
    ("zero error", {"d.csv": GOOD.replace("dop\n", "dop,dop_err\n").replace("\n", ",0\n").replace("dop_err,0", "dop_err", 1)},
     ["run", "d.csv"], "error"),
    ("error without value", {"d.csv": "theta_i,theta_r,brdf_err\n10,20,0.1\n"}, ["run", "d.csv"], "error"),
    ("short row", {"d.csv": "theta_i,theta_r,dop\n10,20\n"}, ["run", "d.csv"], "error"),
    ("long row", {"d.csv": "theta_i,theta_r,dop\n10,20,0.1,4\n"}, ["run", "d.csv"], "error"),
    ("negative brdf", {"d.csv": "theta_i,theta_r,brdf\n10,20,-1\n"}, ["run", "d.csv"], "error"),
    ("bad metadata", {"d.csv": "# just a comment without colon\n" + GOOD}, ["run", "d.csv"], "error"),
    ("metadata wavelength 0", {"d.csv": "# wavelength_um: 0\n" + GOOD}, ["run", "d.csv"], "error"),
    ("metadata wavelength text", {"d.csv": "# wavelength_um: red\n" + GOOD}, ["run", "d.csv"], "error"),
    ("wavelength column 0", {"d.csv": "theta_i,theta_r,dop,wavelength_um\n10,20,0.1,0\n"}, ["run", "d.csv"], "error"),
    ("latin-1 file", {"d.csv": "# material: caf\xe9\n".encode("latin-1") + GOOD.encode()}, ["run", "d.csv"], "error"),
    ("binary file", {"d.csv": bytes(range(256))}, ["run", "d.csv"], "error"),
    ("too few points", {"d.csv": "theta_i,theta_r,dop\n10,20,0.1\n30,40,0.2\n"}, ["run", "d.csv"], "error"),
    ("multi wavelength unpicked", {"d.csv": "theta_i,theta_r,dop,wavelength_um\n10,20,0.1,0.5\n10,20,0.1,0.6\n"}, ["run", "d.csv"], "error"),
    ("wavelength absent", {"d.csv": "theta_i,theta_r,dop,wavelength_um\n10,20,0.1,0.5\n"}, ["run", "d.csv", "--wavelength-um", "0.9"], "error"),
    # NIST layout
    ("nist dop > 1", {"n.csv": NIST_HEAD + "\n" + nist_row(m={"21": 0.8, "31": 0.8}) + "\n"}, ["run", "n.csv"], "error"),
    ("nist element > 1", {"n.csv": NIST_HEAD + "\n" + nist_row(m={"33": -1.4}) + "\n"}, ["run", "n.csv"], "error"),
    ("nist lambda 0", {"n.csv": NIST_HEAD + "\n" + nist_row(lam=0) + "\n"}, ["run", "n.csv"], "error"),
    ("nist lambda negative", {"n.csv": NIST_HEAD + "\n" + nist_row(lam=-0.6) + "\n"}, ["run", "n.csv"], "error"),
    ("nist angle 90", {"n.csv": NIST_HEAD + "\n" + nist_row(tr=90) + "\n"}, ["run", "n.csv"], "error"),
    ("nist short row", {"n.csv": NIST_HEAD + "\n0.6,-30,0,20\n"}, ["run", "n.csv"], "error"),
    ("nist negative brdf", {"n.csv": NIST_HEAD + "\n" + nist_row(fr11=-0.1) + "\n"}, ["run", "n.csv"], "error"),
    # priors
    ("prior no mass", {"d.csv": GOOD, "p.toml": "[n]\ndistribution='normal'\nmu=100.0\nsigma=0.01\nlower=1.0\nupper=2.0\n"},
     ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior fixed nan", {"d.csv": GOOD, "p.toml": "[k]\nfixed = nan\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior fixed inf", {"d.csv": GOOD, "p.toml": "[k]\nfixed = inf\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior fixed text", {"d.csv": GOOD, "p.toml": "[k]\nfixed = 'zero'\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior reversed", {"d.csv": GOOD, "p.toml": "[n]\nlower=2.0\nupper=1.0\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior equal bounds", {"d.csv": GOOD, "p.toml": "[n]\nlower=1.5\nupper=1.5\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior sigma 0", {"d.csv": GOOD, "p.toml": "[n]\ndistribution='normal'\nmu=1.5\nsigma=0.0\nlower=1.0\nupper=2.0\n"},
     ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior loguniform 0", {"d.csv": GOOD, "p.toml": "[sigma]\ndistribution='loguniform'\nlower=0.0\nupper=0.5\n"},
     ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior unknown dist", {"d.csv": GOOD, "p.toml": "[n]\ndistribution='cauchy'\nlower=1.0\nupper=2.0\n"},
     ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior unphysical", {"d.csv": GOOD, "p.toml": "[sigma]\nlower=-1.0\nupper=0.5\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior unknown param", {"d.csv": GOOD, "p.toml": "[zeta]\nfixed=1.0\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior unknown key", {"d.csv": GOOD, "p.toml": "[n]\nlow=1.0\nupper=2.0\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior not a table", {"d.csv": GOOD, "p.toml": "n = 1.5\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior bad toml", {"d.csv": GOOD, "p.toml": "[n\n"}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    ("prior missing file", {"d.csv": GOOD}, ["run", "d.csv", "--prior", "nope.toml"], "error"),
    ("prior all fixed", {"d.csv": GOOD, "p.toml": "".join(f"[{p}]\nfixed={v}\n" for p, v in
                                                         [("n", 1.5), ("k", 0.1), ("sigma", 0.2), ("ks", 0.5), ("rho_d", 0.1),
                                                          ("sigma_dop", 0.01)])}, ["run", "d.csv", "--prior", "p.toml"], "error"),
    # plug-in effects
    ("plugin raises", {"d.csv": GOOD, "p.py": PLUGIN.format(body="raise ValueError('x')")},
     ["--effect", "p.py:P", "run", "d.csv", "--model", "paper+p_eff"], "error"),
    ("plugin nan", {"d.csv": GOOD, "p.py": PLUGIN.format(body="return ctx.depolarized(np.full(ctx.shape, np.nan))")},
     ["--effect", "p.py:P", "run", "d.csv", "--model", "paper+p_eff"], "error"),
    ("plugin inf", {"d.csv": GOOD, "p.py": PLUGIN.format(body="return ctx.depolarized(np.full(ctx.shape, np.inf))")},
     ["forward", "d.csv", "--effect", "p.py:P", "--model", "paper+p_eff", "--out", "f.csv"], "error"),
    ("plugin exits", {"d.csv": GOOD, "p.py": PLUGIN.format(body="sys.exit(0)")},
     ["--effect", "p.py:P", "run", "d.csv", "--model", "paper+p_eff"], "error"),
    ("plugin exits synth", {"p.py": PLUGIN.format(body="sys.exit('bye')")},
     ["--effect", "p.py:P", "synth", "--model", "paper+p_eff", "--out", "s.csv"], "error"),
    ("plugin import error", {"p.py": "import not_a_module\n"}, ["--effect", "p.py:P", "effects"], "error"),
    ("plugin import exit", {"p.py": "raise SystemExit(4)\n"}, ["--effect", "p.py:P", "effects"], "error"),
    ("plugin syntax error", {"p.py": "class P(:\n"}, ["--effect", "p.py:P", "effects"], "error"),
    ("plugin missing class", {"p.py": "x = 1\n"}, ["--effect", "p.py:P", "effects"], "error"),
    ("plugin not an effect", {"p.py": "class P:\n    pass\n"}, ["--effect", "p.py:P", "effects"], "error"),
    ("plugin no colon", {"p.py": "x = 1\n"}, ["--effect", "p.py", "effects"], "error"),
    ("plugin missing file", {}, ["--effect", "nope.py:P", "effects"], "error"),
    ("plugin name clash", {"p.py": "from spacepol.physics.effect import Effect\nclass P(Effect):\n    name = 'body'\n"},
     ["--effect", "p.py:P", "effects"], "error"),
    # models
    ("unknown effect", {"d.csv": GOOD}, ["run", "d.csv", "--model", "paper+glitter"], "error"),
    ("empty model term", {"d.csv": GOOD}, ["run", "d.csv", "--model", "paper++body"], "error"),
    ("effect twice", {"d.csv": GOOD}, ["run", "d.csv", "--model", "paper+body"], "error"),
    ("smith with shadowing", {"d.csv": GOOD}, ["run", "d.csv", "--model", "paper+smith"], "error"),
    ("effect needs specular", {"d.csv": GOOD}, ["run", "d.csv", "--model", "body+ggx"], "error"),
    ("reference unknown", {"d.csv": GOOD}, ["run", "d.csv", "--reference", "zeta=1"], "error"),
    ("reference text", {"d.csv": GOOD}, ["run", "d.csv", "--reference", "n=high"], "error"),
    # scenarios and contrast
    ("scenario nan", {"s.toml": "[instrument]\npupil_area_m2 = nan\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario inf", {"s.toml": "[sky]\np_max_low = inf\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario no flux", {"s.toml": "[instrument]\nband_low_um = 0.0001\nband_high_um = 0.0002\n"},
     ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario band reversed", {"s.toml": "[instrument]\nband_low_um = 2.0\nband_high_um = 1.0\n"},
     ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario bad time", {"s.toml": "[site]\ntime = 'noon'\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario time year 5", {"s.toml": "[site]\ntime = '0005-01-01T00:00Z'\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario wrong unit", {"s.toml": "[instrument]\nintegration_time_s = '3 m'\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario unknown key", {"s.toml": "[instrument]\naperture = 1\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario case nan", {"s.toml": "[[cases]]\nzenith_deg = nan\nazimuth_deg = 0\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("scenario lat 100", {"s.toml": "[site]\nlat_deg = 100\n"}, ["contrast", ".", "--scenario", "s.toml"], "error"),
    ("contrast not a run", {}, ["contrast", "."], "error"),
    ("contrast missing dir", {}, ["contrast", "nope"], "error"),
    ("contrast bad summary", {"r/summary.json": "{", "r/posterior.nc": "x"}, ["contrast", "r"], "error"),
    ("contrast bad posterior", {"r/summary.json": '{"model": "paper"}', "r/posterior.nc": "not netcdf"}, ["contrast", "r"], "error"),
    # odd but valid: must succeed
    ("BOM csv", {"d.csv": b"\xef\xbb\xbf" + GOOD.encode()}, ["forward", "d.csv", "--out", "f.csv"], "ok"),
    ("CRLF csv", {"d.csv": GOOD.replace("\n", "\r\n")}, ["forward", "d.csv", "--out", "f.csv"], "ok"),
    ("blank lines and spaces", {"d.csv": "\n# material: paint \n\n theta_i , theta_r ,dop\n 10 , 20 , 0.1\n\n30,40,0.2\n\n"},
     ["forward", "d.csv", "--out", "f.csv"], "ok"),
    ("scientific notation", {"d.csv": "theta_i,theta_r,dop\n1e1,2.0E1,1e-1\n"}, ["forward", "d.csv", "--out", "f.csv"], "ok"),
    ("columns reordered, negative dphi", {"d.csv": "dop,dphi,theta_r,theta_i\n0.1,-170,20,10\n"},
     ["forward", "d.csv", "--out", "f.csv"], "ok"),
    ("out in a new nested folder", {"d.csv": GOOD}, ["forward", "d.csv", "--out", "a/b/c/f.csv"], "ok"),
    ("out with spaces and unicode", {"d.csv": GOOD}, ["forward", "d.csv", "--out", "my results/\u00e9t\u00e9.csv"], "ok"),
    ("synth seed 0 defaults", {}, ["synth", "--out", "s.csv"], "ok"),
    ("synth big seed", {}, ["synth", "--seed", str(2**40), "--out", "s.csv"], "ok"),
    ("sky today", {}, SKY + ["--time", "2026-11-22T12:00:00+08:00", "--out", "sky"], "ok"),
    ("sky in five years", {}, SKY + ["--time", "2031-11-22T12:00:00Z", "--out", "sky"], "ok"),
    ("sky 1950", {}, SKY + ["--time", "1950-06-21T12:00Z", "--out", "sky"], "ok"),
    ("sky fractional seconds", {}, SKY + ["--time", "2026-11-22T12:00:30.25-03:30", "--out", "sky"], "ok"),
    ("sky pole", {}, ["sky", "--lat", "-90", "--lon", "359", "--time", "2026-06-21T00:00Z", "--out", "sky"], "ok"),
    ("effects list", {}, ["effects"], "ok"),
    ("plugin good", {"p.py": "import numpy as np\nfrom spacepol.physics.effect import Effect\nclass P(Effect):\n    name = 'p_ok'\n"
                     "    def lobe(self, ctx):\n        return ctx.depolarized(0.01 + 0 * ctx.geometry.cos_tr)\n", "d.csv": GOOD},
     ["--effect", "p.py:P", "forward", "d.csv", "--model", "paper+p_ok", "--out", "f.csv"], "ok"),
    ("run short capped", {"d.csv": GOOD_BRDF}, ["run", "d.csv", "--steps", "500", "--quiet", "--out", "r"], "ok"),
    # inputs once accepted (issue 25, item 8)
    ("a row of only commas", {"d.csv": GOOD + ",,\n"}, ["run", "d.csv", "--out", "r"], "error"),
    ("stokes |S| > S0 fitted as q", {"d.csv": "theta_i,theta_r,s0,s1,s2\n" + "".join(
        f"{ti},{tr},1.0,{1.5 if tr == 35 else 0.3},0.1\n" for ti in (10, 30, 50) for tr in (5, 20, 35, 50, 65))},
     ["run", "d.csv", "--observables", "q", "--out", "r"], "error"),
    ("forward ks near 1e300", {"d.csv": GOOD}, ["forward", "d.csv", "--set", "ks=1e300", "--out", "f.csv"], "error"),
    ("synth rho_d near 1e300", {}, ["synth", "--set", "rho_d=1e300", "--out", "s.csv"], "error"),
    ("forward n near 1e300 (no finite output)", {"d.csv": GOOD}, ["forward", "d.csv", "--set", "n=1e300", "--out", "f.csv"], "error"),
    ("sky direction 30,nan", {}, SKY + ["--time", "2026-11-22T12:00:00Z", "--direction", "30,nan", "--out", "sky"], "error"),
    ("a blank line in the data", {"d.csv": GOOD + "\n\n"}, ["forward", "d.csv", "--out", "f.csv"], "ok"),
]


def run_case(case, timeout=300):
    name, files, argv, expect = case
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for rel, content in files.items():
            path = tmp / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
        before = sorted(str(p.relative_to(tmp)) for p in tmp.rglob("*"))
        start = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "spacepol.cli", *argv], cwd=tmp, capture_output=True, text=True,
                              timeout=timeout, stdin=subprocess.DEVNULL)
        seconds = time.perf_counter() - start
        after = sorted(str(p.relative_to(tmp)) for p in tmp.rglob("*"))
    err_lines = [line for line in proc.stderr.splitlines() if line.strip()]
    problems = []
    if "Traceback" in proc.stderr or "Traceback" in proc.stdout:
        problems.append("traceback")
    if expect == "error":
        if proc.returncode != 2:
            problems.append(f"exit {proc.returncode}")
        if len(err_lines) != 1:
            problems.append(f"{len(err_lines)} stderr lines")
        if after != before:
            problems.append("left " + ", ".join(sorted(set(after) - set(before)))[:80])
    elif proc.returncode != 0:
        problems.append(f"exit {proc.returncode}")
    message = err_lines[-1] if err_lines else ""
    return name, expect, proc.returncode, seconds, problems, message


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--only", default="")
    args = parser.parse_args(argv)
    cases = [c for c in CASES if args.only in c[0]]
    start = time.perf_counter()
    with ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(run_case, cases))
    bad = 0
    for name, expect, rc, seconds, problems, message in results:
        bad += bool(problems)
        status = "ok  " if not problems else "FAIL"
        print(f"{status} {expect:5s} rc {rc} {seconds:5.1f} s  {name:32s} {'; '.join(problems) or message[:110]}")
    errors = sum(1 for r in results if r[1] == "error")
    print(f"{len(results) - bad} of {len(results)} cases as required ({errors} invalid inputs: exit 2, one line, "
          f"no traceback, nothing left behind; {len(results) - errors} odd but valid inputs: exit 0) "
          f"in {time.perf_counter() - start:.0f} s")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
