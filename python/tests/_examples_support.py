"""What the example tests share: running python/examples/NAME.py (sys.executable, this test's
environment) and the C++ example it follows (its path from ctest's RCCX_EX_* variable)."""

import os
import pathlib
import re
import subprocess
import sys

import pytest

from _support import REQUIRED

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def cpp_example(variable):
    """The C++ example's path from the environment; the test is skipped (failed under ctest)
    when it is not given."""
    path = os.environ.get(variable, "")
    if not path:
        if REQUIRED:
            pytest.fail(f"{variable} is not set: ctest names the C++ example")
        pytest.skip(f"{variable} (the C++ example this one follows) is not set; "
                    "run ctest -L python")
    return path


def run_python(name, *args, timeout=600):
    """python/examples/<name>.py with args: the CompletedProcess (text)."""
    return subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py"), *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, check=False)


def run_cpp(path, *args, timeout=600):
    return subprocess.run([path, *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, check=False)


def number_after(text, prefix):
    """The first number after `prefix` in text (a regex prefix); AssertionError when none."""
    m = re.search(prefix + r"\s*([-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?)", text)
    assert m, f"no {prefix!r} in:\n{text}"
    return float(m.group(1))


def check_help(name):
    """--help exits 0 and describes the options; a bad option exits 2 (argparse)."""
    h = run_python(name, "--help", timeout=60)
    assert h.returncode == 0, h.stderr
    assert "usage:" in h.stdout and "--help" in h.stdout
    bad = run_python(name, "--no-such-option", timeout=60)
    assert bad.returncode == 2 and "unrecognized arguments" in bad.stderr
