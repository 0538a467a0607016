"""Run logs: the CSV a session writes with RCCX_LOG=FILE or --log FILE, read by rccx's C++
reader (view::load_run_log, the one `rccx plot` and `rccx view --log` use).

    import rccx
    log = rccx.log.load("run.csv")       # rccx.RunLogError (a ValueError) when it is not one
    log.robot_name, log.period_s         # from the header line
    s = log.samples                      # NumPy structured array, one element a sample
    s["t_s"], s["measured"][:, 0]        # s; rad or m
    e = log.path_errors_m()              # (N,), m: what `rccx plot` calls the path error
"""

from __future__ import annotations

import os

import numpy as np

from . import _rccx

__all__ = ["RunLog", "load", "sample_dtype"]


def sample_dtype(dof: int) -> np.dtype:
    """The dtype of RunLog.samples for a robot of dof joints; each field is a column of the log:

    t_s         float64         time, s (the session's clock)
    segment     int32           the motion segment's index (seg)
    commanded   float64 (dof,)  commanded joints q1..qN: rad (revolute) or m (prismatic)
    measured    float64 (dof,)  measured joints qm1..qmN: rad or m
    p_m         float64 (3,)    commanded tool position x, y, z in the base frame, m
    approach    float64 (3,)    commanded approach vector ax, ay, az (unit length)
    """
    return np.dtype([("t_s", np.float64), ("segment", np.int32),
                     ("commanded", np.float64, (dof,)), ("measured", np.float64, (dof,)),
                     ("p_m", np.float64, (3,)), ("approach", np.float64, (3,))])


class RunLog:
    """A run log read whole. Made by rccx.log.load(path).

    path: the file. dof: the number of joints. samples: the rows (see sample_dtype).
    From the header line (None each in a log written before headers, rccx < 0.1.0):
    robot_name (the robot file's name, e.g. "puma560"), name (the robot's name in its cell),
    kinematics (16 hex digits telling its geometry), period_s (sample period, s), simulated
    (simulated clock rather than real time), rccx_version.
    """

    def __init__(self, data: _rccx.log.RunLogData) -> None:
        self._data = data
        self.path: str = data.origin
        self.dof: int = data.dof
        header = data.header()
        self.has_header: bool = header is not None
        robot, kinematics, name, period_ns, simulated, version = header or (None,) * 6
        self.robot_name: str | None = robot
        self.kinematics: str | None = kinematics
        self.name: str | None = name
        self.period_s: float | None = None if period_ns is None else period_ns * 1e-9
        self.simulated: bool | None = simulated
        self.rccx_version: str | None = version
        samples = np.empty(data.size, dtype=sample_dtype(self.dof))
        samples["t_s"] = data.t_s()
        samples["segment"] = data.segment()
        samples["commanded"] = data.commanded()
        samples["measured"] = data.measured()
        samples["p_m"] = data.p_m()
        samples["approach"] = data.approach()
        samples.flags.writeable = False  # the log as read; copy it to change it
        self.samples: np.ndarray = samples

    def __len__(self) -> int:
        return len(self.samples)

    def __repr__(self) -> str:
        who = self.robot_name if self.has_header else "no header"
        return (f"<rccx.log.RunLog {self.path!r}: {who}, {len(self)} samples, "
                f"{self.samples['t_s'][-1] - self.samples['t_s'][0]:.2f} s>")

    def robot(self, robot: _rccx.kin.Kinematics | None = None) -> _rccx.kin.Kinematics:
        """The robot the log is drawn as (C++ view::log_robot): the one its header names (a
        shipped robot), else `robot` (a rccx.kin.Kinematics), which must then be the header's
        robot (its name and geometry). Raises rccx.RunLogError saying which to give."""
        return self._data.robot(robot)

    def path_errors_m(self, robot: _rccx.kin.Kinematics | None = None) -> np.ndarray:
        """The path error at each sample, m, shape (N,) (C++ view::path_errors_m): how far the
        measured tool point is from the commanded path (the nearest point of the commanded
        polyline from 600 samples before to 50 after). Its maximum is `rccx plot`'s "worst path
        error". robot: as for robot(). The GIL is released while it computes."""
        return self._data.path_errors_m(robot)


def load(path: str | os.PathLike[str]) -> RunLog:
    """Reads the run log at path (a CSV rccx wrote: RCCX_LOG=FILE, --log FILE).

    Raises FileNotFoundError for a missing file, rccx.RunLogError (a ValueError) for a file that
    is not such a log, with rccx's message naming the line and column. The GIL is released while
    it parses."""
    return RunLog(_rccx.log.RunLogData(os.fspath(path)))
