"""One OpenBLAS thread per process, as the command line asks before numpy loads, unless the user's environment says."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from softdesign.pipeline.parallel import BLAS_THREADS_VARIABLE, one_blas_thread
from tests.helpers.paths import DEMO, REPO

#: Runs ``softdesign validate DEMO`` through the console script's entry point, then prints the variable's value and
#: whether numpy was loaded before the command ran (it must not be: OpenBLAS reads the variable when it loads).
_CHILD = f"""
import os, sys
from softdesign.cli import main
loaded_before = "numpy" in sys.modules
sys.argv[:] = ["softdesign", "validate", {str(DEMO)!r}]
try:
    main()
except SystemExit:
    pass
print(os.environ.get({BLAS_THREADS_VARIABLE!r}), loaded_before)
"""


def test_one_thread_is_asked_for_unless_the_environment_says_otherwise():
    environ: dict[str, str] = {}
    one_blas_thread(environ)
    assert environ == {BLAS_THREADS_VARIABLE: "1"}
    mine = {BLAS_THREADS_VARIABLE: "4"}
    one_blas_thread(mine)
    assert mine == {BLAS_THREADS_VARIABLE: "4"}


@pytest.mark.parametrize("given, expected", [(None, "1"), ("3", "3")])
def test_the_command_line_sets_it_before_numpy_loads(given, expected):
    env = {k: v for k, v in os.environ.items() if k != BLAS_THREADS_VARIABLE}
    if given is not None:
        env[BLAS_THREADS_VARIABLE] = given
    done = subprocess.run([sys.executable, "-c", _CHILD], capture_output=True, text=True, cwd=REPO, env=env,
                          timeout=120, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split()[-2:] == [expected, "False"]
