"""The command line run in the test's own process: ``cli.main``, which the ``invert-mcmc`` entry point calls, with
its exit status and output captured as ``subprocess.run`` would give them. A subprocess pays the imports again for every
command; the tests that need a real process (signals, locks, a fresh interpreter) keep one."""

import contextlib
import io
import os
import subprocess


def run_cli(*args, cwd=None) -> subprocess.CompletedProcess:
    """Exit status, stdout and stderr of ``invert-mcmc ARGS`` run in this process (in ``cwd`` if given)."""
    from spacepol import cli

    out, err = io.StringIO(), io.StringIO()
    here = os.getcwd()
    try:
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = cli.main([str(a) for a in args])
            except SystemExit as exc:  # argparse
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    finally:
        os.chdir(here)
    return subprocess.CompletedProcess(list(args), code, out.getvalue(), err.getvalue())
