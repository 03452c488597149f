"""Shared paths and helpers of the mlcp package's tests (run by ctest as python_pytest, which sets
PYTHONPATH to the build's python folder and MLCP_SOURCE_DIR / MLCP_BUILD_DIR; or as
`python -m pytest python/tests` with the package pip-installed, the mlcp program among the
interpreter's scripts)."""

import os
import pathlib
import subprocess
import sys
import sysconfig

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("MLCP_SOURCE_DIR", pathlib.Path(__file__).parents[2]))
BUILD = pathlib.Path(os.environ["MLCP_BUILD_DIR"]) if "MLCP_BUILD_DIR" in os.environ else None
SCENES = SOURCE / "scenes"
DATA = SOURCE / "tests" / "data"

# The worked Lemke example (a 3-row LCP solved by hand in the Lemke literature): z = (20/19, 21/19, 0), w = (0, 0, 12/19).
SEED_M = np.array([[2.0, -1.0, 3.0], [-1.0, 10.0, 2.0], [-3.0, -2.0, 0.0]])
SEED_Q = np.array([-1.0, -10.0, 6.0])


def natural_map_residual(A, b, lo, hi, x, findex=None):
    """The scaled natural-map residual computed here, independently of the library."""
    w = A @ x + b
    lo_eff, hi_eff = np.array(lo, dtype=float), np.array(hi, dtype=float)
    if findex is not None:
        for i, j in enumerate(findex):
            if j >= 0:
                lo_eff[i], hi_eff[i] = lo[i] * abs(x[j]), hi[i] * abs(x[j])
    r = x - np.clip(x - w, lo_eff, hi_eff)
    return np.max(np.abs(r)) / (1.0 + np.max(np.abs(b)))


def cli_path():
    """The mlcp program: the build's (MLCP_BUILD_DIR), else the one pip installed next to this
    interpreter, else build/bin/mlcp of the source tree."""
    if BUILD is not None:
        return BUILD / "bin" / "mlcp"
    for scripts in (sysconfig.get_path("scripts"), pathlib.Path(sys.executable).parent):
        if (pathlib.Path(scripts) / "mlcp").exists():
            return pathlib.Path(scripts) / "mlcp"
    return SOURCE / "build" / "bin" / "mlcp"


def cli(*args):
    """Runs the mlcp program; returns (exit code, stdout, stderr)."""
    exe = cli_path()
    if not exe.exists():
        pytest.fail(f"{exe} not built (set MLCP_BUILD_DIR)")
    p = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=60)
    return p.returncode, p.stdout, p.stderr


def cli_error(command, *args):
    """The one-line message the mlcp program prints for invalid input, without its prefix."""
    code, _, err = cli(command, *args)
    assert code == 2, f"mlcp {command} exited {code}: {err}"
    line = err.strip().splitlines()[-1]
    prefix = f"mlcp {command}: "
    assert line.startswith(prefix), line
    return line[len(prefix):]
