#!/bin/sh
# The tutorial's four steps (see README.md). Run from the repository root:
#   sh examples/tutorial_user_effect/run.sh [OUT_DIR]
set -e
OUT=${1:-reports/tutorial}
# the project's environment when it is there (after the README's set-up), else whatever is on PATH
if [ -x .venv/bin/invert-mcmc ]; then PATH="$PWD/.venv/bin:$PATH"; fi
E=examples/tutorial_user_effect/sheen.py:Sheen
mkdir -p "$OUT"
# 1. the new effect is registered like a built-in one
invert-mcmc effects --effect $E | grep -A3 "^sheen"
# 2. hide it in synthetic data: the paper's model plus sheen, DOP noise 0.003, BRDF noise 2 %
invert-mcmc synth --effect $E --model paper+sheen --set n=1.5 --set k=0 --set sigma=0.2 --set ks=0.5 \
    --set rho_d=0.2 --set b_sheen=0.15 --noise-dop 0.003 --noise-brdf 0.02 --seed 7 --out "$OUT/sheen_hidden.csv"
# 3. fit the paper's model and ask what is missing (every registered effect, built-in or not)
invert-mcmc diagnose "$OUT/sheen_hidden.csv" --effect $E --model paper --json "$OUT/diagnose.json" --out "$OUT/diagnose"
# 4. add it and watch the error fall
invert-mcmc ladder "$OUT/sheen_hidden.csv" --effect $E --model paper --add sheen --json "$OUT/ladder.json" --out "$OUT/ladder"
