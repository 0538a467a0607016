"""python/examples/plot_log.py on the washer's log: it prints `rccx plot`'s worst path error and
writes five PNG files; a bad log exits 2 saying why."""

import pathlib
import subprocess
import sys

from _data_support import WORST, rccx_plot, washer_log
from _support import import_rccx

import_rccx()
EXAMPLE = pathlib.Path(__file__).resolve().parents[1] / "examples" / "plot_log.py"


def run(*args):
    return subprocess.run([sys.executable, EXAMPLE, *map(str, args)], capture_output=True,
                          text=True, timeout=300, check=False)


def test_plot_log_writes_the_pngs(tmp_path):
    path, _ = washer_log(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    r = run(path, out)
    assert r.returncode == 0, r.stderr
    _, plot_out, err = rccx_plot(path, tmp_path / "w.svg")
    assert f"worst path error {WORST.search(plot_out).group(1)} mm" in r.stdout
    for name in ["washer_joints", "washer_path", "washer_speed", "washer_path_error", "washer"]:
        assert (out / f"{name}.png").read_bytes()[:4] == b"\x89PNG"


def test_plot_log_refuses_a_bad_log(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,seg\n")
    r = run(bad, tmp_path)
    assert r.returncode == 2 and "error:" in r.stderr and str(bad) in r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]
