"""rccx.view: the web page of a Python program's robots (C++ view::serve). The server, fetched
over HTTP as a browser would, reports the joints the robot itself reports after a move, and the
goal where forward kinematics puts it; a port in use and a served robot raise rccx.ViewError
with rccx's message; close() frees the port; a cell's robots are served each with its own."""

import json
import pathlib
import socket
import time
import urllib.error
import urllib.request

import numpy as np
import pytest

from _support import import_rccx

rccx = import_rccx()

CELLS = pathlib.Path(__file__).resolve().parents[2] / "cells"


@pytest.fixture(name="assets")
def fixture_assets(tmp_path):
    """A stand-in front end (the real bundle is the view's end-to-end test's)."""
    (tmp_path / "index.html").write_text("<!doctype html><title>rccx view from python</title>")
    (tmp_path / "app.js").write_text("console.log('rccx');")
    return tmp_path


def get(view, path):
    with urllib.request.urlopen(view.url.rstrip("/") + path, timeout=10) as r:
        return r.status, r.headers.get("Content-Type", ""), r.read().decode()


def get_json(view, path):
    status, _, body = get(view, path)
    assert status == 200
    return json.loads(body)


def state_at(view, t_s, index=0):
    """The server's last sample of robot `index` once it has caught up with time t_s (the server's
    thread drains the taps every 1/rate s of wall time)."""
    deadline = time.monotonic() + 10
    while True:
        latest = get_json(view, "/api/state")["robots"][index]  # None before the first sample
        if latest is not None and latest["t"] >= t_s - 0.02 - 1e-9:
            return latest
        assert time.monotonic() < deadline, f"the view's samples did not reach t = {t_s} s"
        time.sleep(0.05)


def frame(scene, name):
    found = [f for f in scene["frames"] if f["name"] == name]
    return found[0] if found else None


def test_serves_the_robots_joints_and_goal(assets):
    with rccx.Robot("puma560") as robot, \
            rccx.view.serve(robot, port=0, announce=False, assets=assets) as view:
        assert view.port != 0
        assert view.url == f"http://127.0.0.1:{view.port}/"
        status, kind, page = get(view, "/")
        assert status == 200 and "rccx view from python" in page and kind.startswith("text/html")

        k = robot.kinematics
        scene = get_json(view, "/api/scene")
        assert [r["name"] for r in scene["robots"]] == ["puma560"]
        assert len(scene["robots"][0]["joints"]) == k.dof
        assert scene["mode"] == "live"

        goal = k.ready + np.array([0.3, -0.2, 0.1, 0.2, -0.3, 0.1])
        motion = robot.move(rccx.joints("A", goal))
        # The move drew its goal, where forward kinematics puts the tool (the robot's base is
        # the world's).
        a = frame(get_json(view, "/api/scene"), "A")
        assert a is not None and a["robot"] == 0
        np.testing.assert_allclose(a["pose"][12:15], k.forward(goal)[:3, 3], atol=1e-9)

        assert robot.waitfor(motion.end, timeout=30) == "reached"
        robot.wait_for(0.2)  # at rest: every sample since the same
        latest = state_at(view, robot.time)
        assert abs(latest["t"] - robot.time) <= 0.02 + 1e-9
        # What the server reports is the robot's own reading, and where the move went.
        np.testing.assert_allclose(latest["qm"], robot.q, rtol=0, atol=1e-9)
        np.testing.assert_allclose(latest["qm"], goal, rtol=0, atol=1e-3)
        stats = view.stats()
        assert stats["samples_sent"] > 0 and stats["samples_dropped"] == 0
        assert "127.0.0.1" in repr(view)
    assert view.closed
    with pytest.raises(rccx.ViewError, match="closed"):
        _ = view.url


def test_samples_follow_a_motion(assets):
    """Mid-motion the server's samples are the robot's: its joints at the sample's time."""
    with rccx.Robot("puma560") as robot, \
            rccx.view.serve(robot, port=0, announce=False, assets=assets) as view:
        k = robot.kinematics
        robot.set_velocity(0.05, 0.3)
        motion = robot.move(rccx.joints("B", k.ready + np.array([0.6, 0, 0, 0, 0, 0])))
        assert robot.waitfor(motion.start, timeout=30) == "reached"
        robot.wait_for(0.3)
        assert not robot.happened(motion.end)
        latest = state_at(view, robot.time)
        # The tap keeps a sample every 20 ms of sample time: the robot's last one or close to it.
        if latest["t"] == pytest.approx(robot.time, abs=1e-9):
            np.testing.assert_allclose(latest["qm"], robot.q, rtol=0, atol=1e-9)
        else:
            np.testing.assert_allclose(latest["qm"], robot.q, rtol=0, atol=0.02)
        assert latest["qm"][0] > k.ready[0] + 1e-3  # moving
        assert latest.get("goal") == "B"


def test_port_in_use_raises_and_close_frees_it(assets):
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen()
    port = taken.getsockname()[1]
    with rccx.Robot("microbo") as robot:
        with pytest.raises(rccx.ViewError, match=f"port {port} on 127.0.0.1 is in use"):
            rccx.view.serve(robot, port=port, announce=False, assets=assets)
        taken.close()
        view = rccx.view.serve(robot, port=port, announce=False, assets=assets)
        assert view.port == port
        assert get(view, "/")[0] == 200
        # One view a robot: its session has one tap.
        with pytest.raises(rccx.ViewError, match="already served"):
            rccx.view.serve(robot, port=0, announce=False, assets=assets)
        view.close()
        view.close()  # idempotent
        with pytest.raises(urllib.error.URLError):
            urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5)
        # The port is free: a listener binds it (as the view does, SO_REUSEADDR), and so does
        # a new view of the same robot.
        again = socket.socket()
        again.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        again.bind(("127.0.0.1", port))
        again.close()
        with rccx.view.serve(robot, port=port, announce=False, assets=assets) as view2:
            assert get(view2, "/")[0] == 200


def test_bad_arguments_raise(assets):
    with rccx.Robot("microbo") as robot:
        with pytest.raises(TypeError, match="rccx.Robot"):
            rccx.view.serve(rccx.kin.robot("puma560"), port=0)
        with pytest.raises(ValueError, match="port"):
            rccx.view.serve(robot, port=70000, announce=False, assets=assets)
        with pytest.raises(rccx.ViewError, match="1 .. 200 Hz"):
            rccx.view.serve(robot, port=0, rate=0.0, announce=False, assets=assets)
        with pytest.raises(rccx.ViewError, match="not an IP address"):
            rccx.view.serve(robot, port=0, address="nowhere", announce=False, assets=assets)
        # None of them left a view behind.
        with rccx.view.serve(robot, port=0, announce=False, assets=assets) as view:
            assert get(view, "/")[0] == 200
    with pytest.raises(rccx.SessionError, match="closed"):
        rccx.view.serve(robot, port=0, announce=False, assets=assets)


def test_the_view_keeps_the_robot_alive(assets):
    robot = rccx.Robot("puma560")
    view = rccx.view.serve(robot, port=0, announce=False, assets=assets)
    k = robot.kinematics
    goal = k.ready + np.array([0.2, 0, 0, 0, 0, 0])
    assert robot.waitfor(robot.move(rccx.joints("C", goal)).end, timeout=30) == "reached"
    q = robot.q
    t = robot.time
    del robot  # the view holds it: its samples are still served
    latest = state_at(view, t)
    np.testing.assert_allclose(latest["qm"], q, rtol=0, atol=1e-9)
    view.close()


def test_a_cells_robots(assets):
    # Without collision checks: the two wrists' turns bring the arms within braking distance,
    # which is the collision test's matter, not the view's.
    with rccx.Cell(str(CELLS / "cvarl.json"), collision_checks=False) as cell:
        cell.start()
        with rccx.view.serve(cell, port=0, announce=False, assets=assets) as view:
            scene = get_json(view, "/api/scene")
            names = [r["name"] for r in scene["robots"]]
            assert sorted(names) == sorted(cell.robot_names)
            motions = {}
            for name in names:
                arm = cell.robot(name)
                q = arm.kinematics.ready.copy()
                q[3] += 0.3  # a wrist
                motions[name] = arm.move(rccx.joints(f"{name}_GOAL", q))
            assert cell.waitfor([cell.event(n, m.end) for n, m in motions.items()],
                                timeout=60) == "reached"
            cell.wait_for(0.2)
            for i, name in enumerate(names):
                arm = cell.robot(name)
                latest = state_at(view, arm.time, i)
                np.testing.assert_allclose(latest["qm"], arm.q, rtol=0, atol=1e-9)
                goal = frame(get_json(view, "/api/scene"), f"{name}_GOAL")
                assert goal is not None and goal["robot"] == i
                world = cell.base(name) @ arm.kinematics.forward(motions_goal(arm))
                np.testing.assert_allclose(goal["pose"][12:15], world[:3, 3], atol=1e-9)
            # One robot of the cell is served by this view: a view of it alone is refused.
            with pytest.raises(rccx.ViewError, match="already served"):
                rccx.view.serve(cell.robot(names[0]), port=0, announce=False, assets=assets)
        # Closed: a cell's robot may have a view of its own.
        with rccx.view.serve(cell.robot(names[0]), port=0, announce=False,
                             assets=assets) as one:
            robots = get_json(one, "/api/scene")["robots"]
            assert len(robots) == 1
            assert len(robots[0]["joints"]) == cell.robot(names[0]).kinematics.dof


def motions_goal(arm):
    q = arm.kinematics.ready.copy()
    q[3] += 0.3
    return q


def test_the_built_front_end_by_default():
    """Without assets= the view serves the page the build made (find_assets: the C++ search)."""
    found = rccx.view.find_assets()
    if found is None:
        pytest.skip("the view's front end was not built (node / npm missing)")
    with rccx.Robot("microbo") as robot, rccx.view.serve(robot, port=0, announce=False) as view:
        status, kind, page = get(view, "/")
        assert status == 200 and kind.startswith("text/html")
        assert page == (pathlib.Path(found) / "index.html").read_text()
