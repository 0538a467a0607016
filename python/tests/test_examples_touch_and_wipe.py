"""python/examples/touch_and_wipe.py against examples/11_touch_and_wipe on the same table and
force (the MuJoCo plant, simulated time): the same output, line for line, and the touch and
force within the example's bounds of the truth (0.5 mm, 10 %); the force bindings it uses against their
definitions."""

import math

import numpy as np
import pytest

from _examples_support import check_help, cpp_example, number_after, run_cpp, run_python
from _support import import_rccx

rccx = import_rccx()

TABLE_MM, FORCE_N = -210.0, 8.0  # not the defaults: the options reach the programs


def figures(out):
    return (number_after(out, r"touched at z ="), number_after(out, r"N: measured"))


def test_same_touch_and_force_as_cpp():
    args = ("--table-mm", TABLE_MM, "--force", FORCE_N)
    c = run_cpp(cpp_example("RCCX_EX_TOUCH_AND_WIPE"), *args)
    assert c.returncode == 0, c.stdout + c.stderr
    p = run_python("touch_and_wipe", *args)
    assert p.returncode == 0, p.stdout + p.stderr
    z_c, f_c = figures(c.stdout)
    z_p, f_p = figures(p.stdout)
    # Geometry: the table found where it is, the force held as asked.
    assert abs(z_p - TABLE_MM) < 0.5
    assert abs(f_p - FORCE_N) < 0.1 * FORCE_N
    # The C++ on the same input (the same plant, the same sample loop, the same readings
    # compensated the same way): the same lines, to the printed digit.
    assert (z_p, f_p) == (z_c, f_c)
    assert p.stdout.splitlines() == c.stdout.splitlines()
    assert "done" in p.stdout


def test_external_wrench_and_at_tool():
    # A hanging 0.4 kg tool, com 50 mm along T6's z, T6 pointing down: the reading is its
    # weight; the contacts' wrench is then zero.
    m_kg, com = 0.4, np.array([0.0, 0.0, 0.05])
    T6 = np.eye(4)
    T6[:3, :3] = [[1, 0, 0], [0, -1, 0], [0, 0, -1]]
    g_sensor = T6[:3, :3].T @ [0.0, 0.0, -9.81 * m_kg]
    reading = np.concatenate([g_sensor, np.cross(com, g_sensor)])
    np.testing.assert_allclose(rccx.external_wrench(reading, T6, m_kg, com), np.zeros(6),
                               atol=1e-12)
    # A bias is taken out as it is.
    bias = np.array([0.1, -0.2, 0.3, 0.01, 0.02, -0.03])
    np.testing.assert_allclose(rccx.external_wrench(reading + bias, T6, m_kg, com, bias),
                               np.zeros(6), atol=1e-12)
    # At the tool 100 mm along z: the same force, the torque of the force about the new origin.
    tool = np.eye(4)
    tool[2, 3] = 0.1
    w = np.array([1.0, 2.0, 3.0, 0.0, 0.0, 0.0])
    at = rccx.wrench_at_tool(tool, w)
    np.testing.assert_allclose(at[:3], w[:3])
    np.testing.assert_allclose(at[3:], np.cross([0, 0, -0.1], w[:3]), atol=1e-15)
    with pytest.raises(ValueError, match="shape"):
        rccx.external_wrench(np.zeros(5), T6)
    with pytest.raises(ValueError, match="finite"):
        rccx.wrench_at_tool(tool, [math.nan, 0, 0, 0, 0, 0])


def test_mujoco_robot_arguments():
    with pytest.raises(ValueError, match="plant"):
        rccx.Robot("puma560", plant="water")
    with pytest.raises(ValueError, match="half_size_m"):
        rccx.Robot("puma560", plant="mujoco",
                   scene={"boxes": [{"name": "t", "half_size_m": [0, 1, 1]}]})
    with pytest.raises(ValueError, match="no_such_key"):
        rccx.Robot("puma560", plant="mujoco", scene={"no_such_key": 1})
    with pytest.raises(ValueError, match="only the \"mujoco\" plant"):
        rccx.Robot("puma560", plant="servo", scene={})
    with pytest.raises(TypeError, match="scene"):
        rccx.Robot("puma560", scene={"tool": {"mass_kg": object()}})
    with rccx.Robot("puma560") as arm:  # the servo plant: no sensor
        assert arm.wrench is None
        with pytest.raises(ValueError, match="mass_kg"):
            arm.set_tool_load(-1.0)
        m = arm.move(arm.park)
        assert arm.waitfor(m.end) == "reached"
        assert arm.contact(m) is None
        with pytest.raises(rccx.MotionError, match="no contact"):
            arm.update_from_contact(m, rccx.hold("X"), arm.park)
    with rccx.Robot("puma560", plant="mujoco") as arm:
        assert arm.wrench.shape == (6,)
    # A scene as JSON text, or with NumPy values; it implies the MuJoCo plant.
    scene = {"tool": {"com_m": np.zeros(3), "mass_kg": np.float64(1)}}
    with rccx.Robot("puma560", scene=scene) as arm:
        assert arm.wrench is not None
    with rccx.Robot("puma560", plant="mujoco", scene='{"tool": {"mass_kg": 1.0}}') as arm:
        arm.wait_for(0.1)  # the sensor reads the tool's weight, whichever way T6 points
        assert abs(np.linalg.norm(arm.wrench[:3]) - 9.81) < 0.3, arm.wrench
        contact = rccx.external_wrench(arm.wrench, arm.kinematics.forward(arm.q), 1.0)
        assert np.abs(contact[:3]).max() < 0.3, contact


def test_no_table_no_contact():
    """The table 90 mm below where the program believes it: the guarded move (down to 30 mm
    below) ends without contact, and the example says so and exits 1."""
    p = run_python("touch_and_wipe", "--table-mm", -290)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "no contact" in p.stderr


def test_help():
    check_help("touch_and_wipe")
