"""What the tests of rccx.log, rccx.plot and rccx.db share: recording a run with the C++ washer
example (RCCX_LOG) or the rccx command (--log), and reading a log with Python's csv module, the
independent reader the C++ one is checked against."""

import csv
import os
import re
import subprocess

import pytest

from _support import REQUIRED, cli

WASHER = os.environ.get("RCCX_WASHER", "")


def washer_log(directory):
    """Runs examples/04_washer (C++) with RCCX_LOG; (the log's path, the washer's stdout)."""
    if not WASHER:
        if REQUIRED:
            pytest.fail("RCCX_WASHER is not set: ctest names examples/04_washer")
        pytest.skip("RCCX_WASHER (examples/04_washer) is not set; run ctest -L python")
    path = directory / "washer.csv"
    env = dict(os.environ, RCCX_LOG=str(path))
    r = subprocess.run([WASHER], capture_output=True, text=True, timeout=300, env=env,
                       check=False)
    assert r.returncode == 0, f"04_washer exited {r.returncode}: {r.stderr}"
    assert path.exists()
    return path, r.stdout


def report_log(directory, robot="puma560", seconds="0.5"):
    """`rccx report --robot ROBOT --seconds S --log FILE` (the robot holding still)."""
    path = directory / f"report_{robot}.csv"
    code, out, err = cli("report", "--robot", robot, "--seconds", seconds, "--every", seconds,
                         "--log", path)
    assert code == 0, f"rccx report: exit {code}: {err}"
    return path


def read_csv(path):
    """(header words dict or None, column names, rows as lists of str), by Python's csv."""
    with open(path, newline="", encoding="utf-8") as f:
        lines = f.read().splitlines()
    header = None
    if lines[0].startswith("# rccx-log"):
        words = lines[0].split()[3:]
        header = dict(w.split("=", 1) for w in words)
        lines = lines[1:]
    table = list(csv.reader(lines))
    return header, table[0], table[1:]


WORST = re.compile(r"worst path error ([0-9]+\.[0-9]+) mm \(measured tool from the commanded path")


def rccx_plot(log_path, out_path, *args):
    """`rccx plot LOG -o OUT`: (exit code, stdout, stderr)."""
    return cli("plot", log_path, "-o", out_path, *args)
