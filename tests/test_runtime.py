"""Process settings made at import (``spacepol._runtime``): a user's own settings are kept."""

import os
import subprocess
import sys

from spacepol._runtime import has_avx512

PRINT_FLAGS = "import os, spacepol; print(os.environ.get('XLA_FLAGS', ''))"


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
    code = ("import sys, jax, spacepol\nfrom spacepol._runtime import inline_small_calls\n"
            "print(jax.config.values['jax_cpu_enable_async_dispatch'])\n"
            "if sys.argv[1] == 'cli': inline_small_calls()\n"
            "print(jax.config.values['jax_cpu_enable_async_dispatch'])")
    env = {k: v for k, v in os.environ.items() if k != "JAX_CPU_ENABLE_ASYNC_DISPATCH"}

    def run(env, how):
        return subprocess.run([sys.executable, "-c", code, how], env=env, capture_output=True, text=True, check=True).stdout.split()

    assert run(env, "library") == ["True", "True"]
    assert run(env, "cli") == ["True", "False"]
    assert run({**env, "JAX_CPU_ENABLE_ASYNC_DISPATCH": "1"}, "cli") == ["True", "True"]
