"""What the tests of the Python module share: importing it (skipped, saying why, when it was not
built; an error when ctest runs them, RCCX_PYTHON_REQUIRED=1), the rccx command as the C++
oracle, the robots' files, random joint values within limits."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

REQUIRED = os.environ.get("RCCX_PYTHON_REQUIRED") == "1"
ROBOTS_DIR = pathlib.Path(
    os.environ.get("RCCX_ROBOTS_DIR", pathlib.Path(__file__).resolve().parents[2] / "robots"))
CLI = os.environ.get("RCCX_CLI", "")


def import_rccx():
    """The module rccx; the calling test module is skipped with the reason when it cannot be
    imported, unless ctest runs it (then the import error fails the run)."""
    try:
        import rccx  # noqa: PLC0415
    except ImportError as e:
        if REQUIRED:
            raise
        pytest.skip(f"the Python module rccx is not importable ({e}); build it (RCCX_PYTHON) and "
                    "set PYTHONPATH=<build>/python, or run ctest -L python",
                    allow_module_level=True)
    return rccx


def need_cli():
    if not CLI:
        if REQUIRED:
            pytest.fail("RCCX_CLI is not set: ctest names the rccx command")
        pytest.skip("RCCX_CLI (the rccx command, the C++ oracle) is not set; run ctest -L python")


def cli(*args):
    """Runs the rccx command; (exit code, stdout, stderr)."""
    need_cli()
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, timeout=120,
                       check=False)
    return r.returncode, r.stdout, r.stderr


def cli_json(*args):
    code, out, err = cli(*args)
    assert code == 0, f"rccx {' '.join(map(str, args))}: exit {code}: {err}"
    return json.loads(out)


def skip_if_control_ended(arm):
    """Real time on a loaded machine: a sample that overran its period ends control (RTC's
    guard, as it should); that judges the machine, not the binding: the test is skipped, saying
    why, instead of failing or passing silently."""
    if not arm.controlling:
        pytest.skip(f"real time under load: control ended ({arm.wait_for(0.0)}; "
                    f"{arm.failures()})")


def numbers(values):
    """Comma-separated, each as Python's repr (round-trips a float64 exactly)."""
    return ",".join(repr(float(v)) for v in values)


def random_joints(k, count, seed):
    """count joint vectors (rad or m) drawn uniformly within k's limits (continuous joints:
    within a turn either side of zero)."""
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(k.lower), k.lower, -np.pi)
    hi = np.where(np.isfinite(k.upper), k.upper, np.pi)
    return lo + (hi - lo) * rng.random((count, k.dof))


def random_transform(rng, reach_m=1.0):
    """A random rigid transform (4, 4): an orthonormal, right-handed rotation (QR of a random
    matrix), a position within `reach_m` (m) of the origin along each axis."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    T = np.eye(4)
    T[:3, :3] = q
    T[:3, 3] = rng.uniform(-reach_m, reach_m, 3)
    return T
