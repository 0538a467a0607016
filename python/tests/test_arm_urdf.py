"""rccx.Robot on robots from URDF (issue 26's robots, issue 27's "cover its robots too"): the
shipped UR5e and Panda by name, and any robot rccx.kin loads (a robot file, a URDF) by its model.
Each moves along a Cartesian line to a goal 50 mm below its ready pose, in simulated time; the
goal is checked against the URDF read independently (rccx.kin.urdf of the shipped file) and the
line against geometry (every logged tool point within 1 mm of the straight segment)."""

import os
import pathlib

import numpy as np
import pytest

import rccx

ROBOTS = pathlib.Path(os.environ.get("RCCX_ROBOTS_DIR", pathlib.Path(__file__).parents[2] / "robots"))


def line_to(arm, drop_m, log_path=None):
    k = arm.kinematics
    start = k.forward(arm.q)
    goal = start.copy()
    goal[2, 3] -= drop_m
    arm.set_mode("cartesian")
    arm.set_velocity(0.1, 1.0)
    m = arm.move(rccx.position("DOWN", rccx.t6() == rccx.const("GOAL", goal)))
    assert arm.waitfor(m.end, timeout=30.0) == "reached", arm.failures()
    return start, goal


@pytest.mark.parametrize("name", ["ur5e", "panda"])
def test_a_urdf_robot_by_name_moves_on_a_straight_line_to_its_goal(name, tmp_path):
    log = tmp_path / f"{name}.csv"
    with rccx.Robot(name, log=str(log)) as arm:
        start, goal = line_to(arm, 0.05)
        arm.wait_for(0.5)
        # The shipped URDF read on its own gives the same T6 for the arm's joints.
        urdf = rccx.kin.urdf(str(ROBOTS / f"{name}.urdf"))
        reached = urdf.forward(arm.q)
        assert np.abs(reached[:3, 3] - goal[:3, 3]).max() < 0.5e-3
        assert np.abs(reached[:3, :3] - goal[:3, :3]).max() < 1e-3
        assert arm.failures() == []
    samples = rccx.log.load(str(log)).samples
    assert len(samples) > 10
    # Every commanded tool point on the segment from start to goal (within 1 mm).
    a, b = start[:3, 3], goal[:3, 3]
    u = (b - a) / np.linalg.norm(b - a)
    commanded = urdf.forward(samples["commanded"])[:, :3, 3]
    off_line = np.linalg.norm(np.cross(commanded - a, u), axis=1)
    assert off_line.max() < 1e-3, off_line.max()


def test_a_robot_from_a_urdf_model_is_driven_like_a_shipped_one():
    model = rccx.kin.urdf(str(ROBOTS / "ur5e.urdf"))
    with rccx.Robot(model) as arm:
        assert arm.kinematics.dof == 6
        assert np.allclose(arm.kinematics.forward(model.ready), model.forward(model.ready))
        # The URDF's own ready pose is all zeros, the arm stretched out (no line down from
        # there keeps the tool's orientation): first to the robot file's ready pose, in joints.
        ready = rccx.kin.robot("ur5e").ready
        assert arm.waitfor(arm.move(rccx.joints("READY", ready)).end, timeout=30.0) == "reached"
        _, goal = line_to(arm, 0.03)
        assert np.abs(model.forward(arm.q)[:3, 3] - goal[:3, 3]).max() < 1e-3


def test_a_robot_is_a_name_or_a_model_and_nothing_else():
    with pytest.raises(TypeError, match="rccx.kin.Kinematics"):
        rccx.Robot(42)
    with pytest.raises(KeyError, match="ur5e"):
        rccx.Robot("ur6")
