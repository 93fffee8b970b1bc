"""Process settings (``spacepol._runtime``): none at import; ``configure_process`` makes them for the processes that opt
in (the command line, benchmarks), and a user's own settings are kept."""

import os
import subprocess
import sys

from spacepol._runtime import has_avx512

PRINT_FLAGS = "import os, spacepol; spacepol.configure_process(); print(os.environ.get('XLA_FLAGS', ''))"


def _flags_after_import(xla_flags):
    env = {k: v for k, v in os.environ.items() if k != "XLA_FLAGS"}
    if xla_flags is not None:
        env["XLA_FLAGS"] = xla_flags
    out = subprocess.run([sys.executable, "-c", PRINT_FLAGS], env=env, capture_output=True, text=True, check=True)
    return out.stdout.strip()


def test_wide_vectors_only_on_avx512_and_never_over_the_users_choice():
    wide = "--xla_cpu_prefer_vector_width=512"
    assert _flags_after_import(None) == (wide if has_avx512() else "")
    # another flag of the user's is kept, ours appended after it
    assert _flags_after_import("--xla_dump_to=/nonexistent") == ("--xla_dump_to=/nonexistent" + (f" {wide}" if has_avx512() else ""))
    # the user's own vector width wins
    assert _flags_after_import("--xla_cpu_prefer_vector_width=256") == "--xla_cpu_prefer_vector_width=256"


def test_commands_run_programs_on_the_calling_thread_unless_the_user_says_otherwise():
    """``import spacepol`` keeps JAX's default (large evaluations gain from its worker threads); the command
    line switches before its first computation; an explicit JAX_CPU_ENABLE_ASYNC_DISPATCH wins."""
    code = ("import sys, jax, spacepol\nfrom spacepol._runtime import inline_small_calls\nspacepol.configure_process()\n"
            "print(jax.config.values['jax_cpu_enable_async_dispatch'])\n"
            "if sys.argv[1] == 'cli': inline_small_calls()\n"
            "print(jax.config.values['jax_cpu_enable_async_dispatch'])")
    env = {k: v for k, v in os.environ.items() if k != "JAX_CPU_ENABLE_ASYNC_DISPATCH"}

    def run(env, how):
        return subprocess.run([sys.executable, "-c", code, how], env=env, capture_output=True, text=True, check=True).stdout.split()

    assert run(env, "library") == ["True", "True"]
    assert run(env, "cli") == ["True", "False"]
    assert run({**env, "JAX_CPU_ENABLE_ASYNC_DISPATCH": "1"}, "cli") == ["True", "True"]


SETTINGS = """
import json, os, sys
from threadpoolctl import threadpool_info
import jax
def settings():
    blas = sorted((i["internal_api"], i["num_threads"]) for i in threadpool_info() if i["user_api"] == "blas")
    env = {k: os.environ.get(k) for k in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "XLA_FLAGS", "MALLOC_ARENA_MAX")}
    flags = {k: str(jax.config.values[k]) for k in ("jax_enable_x64", "jax_cpu_enable_async_dispatch",
                                                    "jax_compilation_cache_dir")}
    return {"blas": blas, "env": env, "jax": flags}
import numpy, scipy.linalg  # BLAS loaded, as in any user's process
before = settings()
import spacepol
from spacepol.io import read_measurements
import spacepol.infer.inversion, spacepol.criticism.diagnose
after_import = settings()
getattr(spacepol, sys.argv[1])() if sys.argv[1] != "none" else None
print(json.dumps({"before": before, "after_import": after_import, "after_call": settings()}))
"""


def _settings(*calls: str) -> list[dict]:
    """Per call (``spacepol``'s function, or "none"), the settings before and after the import and after the call,
    each in a fresh process; the processes run at once."""
    import json

    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS",
                                                          "XLA_FLAGS", "JAX_ENABLE_X64", "SPACEPOL_CACHE_DIR")}
    procs = [subprocess.Popen([sys.executable, "-c", SETTINGS, call], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for call in calls]
    found = []
    for proc in procs:
        out, err = proc.communicate()
        assert proc.returncode == 0, err
        found.append(json.loads(out.strip().splitlines()[-1]))
    return found


def test_importing_spacepol_changes_no_process_wide_setting():
    """Neither ``import spacepol`` nor importing its inference and criticism layers changes BLAS threads, the
    environment (BLAS, XLA and malloc variables) or a JAX flag. Control: ``configure_process()`` does change them, so
    the check can see a change."""
    quiet, opted = _settings("none", "configure_process")  # two processes at once
    assert quiet["after_import"] == quiet["before"], (quiet["before"], quiet["after_import"])
    assert opted["after_import"] == opted["before"]
    changed = {k for k in opted["before"] if opted["after_call"][k] != opted["before"][k]}
    assert {"jax", "env"} <= changed, changed
    assert opted["after_call"]["jax"]["jax_enable_x64"] == "True"
    assert opted["after_call"]["env"]["OPENBLAS_NUM_THREADS"] == "1"


def test_a_model_computes_in_double_precision_without_configure_process():
    """JAX's float32 default would lose the polarization of a nearly index-matched interface: building a model turns
    double precision on, and the DOP equals the one computed in a configured process (this one) to 1e-12."""
    import numpy as np

    from spacepol.physics import Model
    from spacepol.physics.geometry import default_grid

    code = ("import json, numpy as np, jax\nfrom spacepol.physics import Model\nfrom spacepol.physics.geometry import default_grid\n"
            "x64 = bool(jax.config.values['jax_enable_x64'])\n"
            "g = default_grid()\nd = Model.from_string('paper').evaluate({'n': 1.0001, 'k': 0.0}, g).dop\n"
            "print(json.dumps([x64, str(np.asarray(d).dtype), np.asarray(d).tolist()]))")
    env = {k: v for k, v in os.environ.items() if k not in ("JAX_ENABLE_X64",)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    import json

    x64_at_import, dtype, dop = json.loads(out.stdout.strip().splitlines()[-1])
    assert not x64_at_import and dtype == "float64"
    here = Model.from_string("paper").evaluate({"n": 1.0001, "k": 0.0}, default_grid()).dop
    np.testing.assert_allclose(dop, np.asarray(here), rtol=1e-12, atol=1e-15)
