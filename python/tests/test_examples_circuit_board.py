"""python/examples/circuit_board.py against examples/10_circuit_board on cells/cvarl.json in
simulated time: the same pads probed, on the still and the moving board alike, every probe
within the pads' 2 mm (geometry: the Microbo's measured tip against the pad from the PUMA's
measured joints), and the C++'s table value for value."""

import csv

import pytest

from _examples_support import check_help, cpp_example, run_cpp, run_python
from _support import import_rccx

rccx = import_rccx()


def table(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


@pytest.mark.parametrize("options", [[], ["--moving-speed", "10"]])
def test_probes_as_cpp(tmp_path, options):
    c = run_cpp(cpp_example("RCCX_EX_CIRCUIT_BOARD"), *options, "--csv", tmp_path / "cpp.csv")
    assert c.returncode == 0, c.stdout + c.stderr
    p = run_python("circuit_board", *options, "--csv", tmp_path / "py.csv")
    assert p.returncode == 0, p.stdout + p.stderr
    tc, tp = table(tmp_path / "cpp.csv"), table(tmp_path / "py.csv")
    assert [r["pad"] for r in tp] == [r["pad"] for r in tc] and len(tp) == 8
    for rc, rp in zip(tc, tp):
        assert float(rp["max_error_mm"]) <= 2.0, rp
        assert int(rp["samples"]) > 0
        moving = [float(r["board_speed_mm_s"]) > 0.5 for r in (rc, rp)]
        assert moving[0] == moving[1], (rc, rp)
        assert abs(float(rp["touched_s"]) - float(rc["touched_s"])) < 0.2, (rc, rp)
        assert rp["hand_closed"] == rc["hand_closed"]
    # The same equations (to the bit: the same constants, multiplied in the same order) on the
    # same simulated plants, measured the same way: the C++'s table, value for value.
    assert tp == tc
    assert "collision stops 0" in p.stdout


def test_help():
    check_help("circuit_board")
