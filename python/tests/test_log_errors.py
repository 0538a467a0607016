"""Bad logs: rccx.log.load raises rccx.RunLogError with the message `rccx plot` prints for the
same file (the same C++ reader), a missing file FileNotFoundError; nothing is changed."""

import numpy as np
import pytest

from _data_support import rccx_plot
from _support import import_rccx, need_cli

rccx = import_rccx()

HEADER = "# rccx-log 1 robot=puma560 kinematics=0000000000000000 name=p period_ns=10000000 " \
         "clock=simulated rccx=0.1.0\n"
COLUMNS = "t,seg," + ",".join(f"q{i}" for i in range(1, 7)) + "," + \
          ",".join(f"qm{i}" for i in range(1, 7)) + ",x,y,z,ax,ay,az\n"


def row(t, seg=0, cells=None):
    values = cells if cells is not None else ["0"] * 18
    return f"{t},{seg}," + ",".join(values) + "\n"


BAD = {
    "empty": "",
    "columns": HEADER + "t,seg,q1,q2\n" + row(0.01),
    "misnamed_column": HEADER + COLUMNS.replace("qm3", "qx3") + row(0.01),
    "not_a_number": HEADER + COLUMNS + row(0.01) + row(0.02, cells=["0"] * 5 + ["abc"] + ["0"] * 12),
    "nan": HEADER + COLUMNS + row(0.01, cells=["nan"] + ["0"] * 17),
    "time_backwards": HEADER + COLUMNS + row(0.02) + row(0.01),
    "too_few_cells": HEADER + COLUMNS + row(0.01, cells=["0"] * 17),
    "negative_segment": HEADER + COLUMNS + row(0.01, seg=-1),
    "no_samples": HEADER + COLUMNS,
    "broken_header": "# rccx-log 1 robot=puma560\n" + COLUMNS + row(0.01),
    "binary": "\x00\x01\x02 not a log\n",
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_log_raises_rccx_plots_message(case, tmp_path):
    need_cli()
    path = tmp_path / f"{case}.csv"
    path.write_text(BAD[case], encoding="latin-1")
    before = path.read_bytes()
    with pytest.raises(rccx.RunLogError) as e:
        rccx.log.load(path)
    assert isinstance(e.value, ValueError)
    message = str(e.value)
    assert str(path) in message
    out = tmp_path / "out.svg"
    code, _, err = rccx_plot(path, out)
    assert code == 2 and not out.exists()
    # rccx plot prints "error: MESSAGE" (and a hint line); the same C++ message.
    assert err.splitlines()[0] == f"error: {message}"
    assert path.read_bytes() == before


def test_a_missing_log_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="no such file"):
        rccx.log.load(tmp_path / "none.csv")
    assert not (tmp_path / "none.csv").exists()


def test_a_directory_is_refused(tmp_path):
    with pytest.raises(rccx.RunLogError, match="cannot read the log"):
        rccx.log.load(tmp_path)


def test_a_log_of_another_robot_is_refused(tmp_path):
    """A header naming a robot whose geometry is not the shipped one: refused when drawn, unless
    its own robot file is given; the samples are read all the same."""
    path = tmp_path / "odd.csv"
    path.write_text(HEADER + COLUMNS + row(0.01) + row(0.02))
    log = rccx.log.load(path)
    assert log.robot_name == "puma560" and log.samples.shape == (2,)
    np.testing.assert_array_equal(log.samples["t_s"], [0.01, 0.02])
    with pytest.raises(rccx.RunLogError, match="which is no shipped robot"):
        log.robot()
    with pytest.raises(rccx.RunLogError, match="not of robot puma560"):
        rccx.plot.series(log, rccx.kin.robot("puma560"))
