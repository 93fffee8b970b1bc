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
# 2. hide it in synthetic data: a surface with physical (Smith) shadowing and the sheen; DOP noise 0.003, BRDF 2 %
invert-mcmc synth --effect $E --model specular+smith+body+sheen --set n=1.5 --set k=0 --set sigma=0.2 --set ks=0.5 \
    --set rho_d=0.2 --set b_sheen=0.15 --noise-dop 0.003 --noise-brdf 0.02 --seed 7 --out "$OUT/sheen_hidden.csv"
# 3. start from the paper's model and let diagnose change it, round by round, until nothing significant is left
#    (every registered effect, built-in or not: additions, replacements of a slot's member, removals)
invert-mcmc diagnose "$OUT/sheen_hidden.csv" --effect $E --model paper --rounds 3 --json "$OUT/diagnose.json" --out "$OUT/diagnose"
# 4. replay the path as a ladder and watch the error fall at each round
invert-mcmc ladder "$OUT/sheen_hidden.csv" --effect $E --model paper --replay "$OUT/diagnose.json" --json "$OUT/ladder.json" --out "$OUT/ladder"
