"""A cell from Python: two robots of cells/cvarl.json, one moving after the other's motion
ends (the reports' times say the order), a robot object keeping its cell alive."""

import gc
import pathlib

import numpy as np
import pytest

from _support import import_rccx

rccx = import_rccx()

CELLS = pathlib.Path(__file__).resolve().parents[2] / "cells"


def test_cell_robots_wait_on_each_other():
    cell = rccx.Cell(str(CELLS / "cvarl.json"))
    assert set(cell.robot_names) == {"puma", "microbo"}
    cell.start()
    puma, microbo = cell.robot("puma"), cell.robot("microbo")
    kp, km = puma.kinematics, microbo.kinematics
    assert kp.name == "puma260" and km.name == "microbo"
    mp = puma.move(rccx.joints("P_UP", kp.ready + np.array([0.1, 0, 0, 0, 0, 0])))
    mm = microbo.move(rccx.joints("M_TURN", km.ready + 0.1 * np.eye(km.dof)[0]),
                      after=cell.event("puma", mp.end))
    assert cell.waitfor([cell.event("puma", mp.end), cell.event("microbo", mm.end)],
                        timeout=60) == "reached"
    rp, rm = puma.report(mp), microbo.report(mm)
    assert rm["start"] >= rp["end"] > rp["start"]
    np.testing.assert_allclose(puma.q, kp.ready + np.array([0.1, 0, 0, 0, 0, 0]), atol=2e-3)
    # world <- base and the base-inverse constant agree
    np.testing.assert_allclose(cell.base_inv_transform("puma").value @ cell.base("puma"),
                               np.eye(4), atol=1e-12)
    assert cell.tool_frame("puma").kind == "functional"
    with pytest.raises(ValueError, match="puma"):
        cell.robot("nobody")
    # the robot keeps the cell alive
    del cell
    gc.collect()
    assert puma.wait_for(0.1) is None
    assert puma.controlling


def test_cell_file_errors():
    with pytest.raises((FileNotFoundError, rccx.CellFileError, ValueError)):
        rccx.Cell("/no/such/cell.json")
