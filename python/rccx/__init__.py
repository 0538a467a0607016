"""rccx for Python: robot kinematics (rccx.kin) over rccx's C++ library.

Transforms are NumPy (4, 4) float64 arrays, positions in m; joint values are rad (revolute) or
m (prismatic). docs/PYTHON.md has the API beside the C++ names.
"""

from ._rccx import RobotFileError, UnreachableError
from . import kin

__all__ = ["kin", "RobotFileError", "UnreachableError"]

# Run logs, the plots of `rccx plot`, the position database (rccx.plot imports Matplotlib only
# when it draws).
from ._rccx import DatabaseBusy, DatabaseError, InvalidTransform, RunLogError
from . import db, log, plot

__all__ += ["db", "log", "plot", "DatabaseBusy", "DatabaseError", "InvalidTransform",
            "RunLogError"]
# Position equations and robots (docs/PYTHON.md, "Position equations" and "Driving a robot").
from ._rccx import (Arm, Cell, CellFileError, EquationError, Event, Gate, LogError, Motion,
                    MotionError, Position, Robot, SessionError, Stream, Together, Transform, When,
                    const, hold, joints, stream, t6)
from .motion import Equation, Product, position

__all__ += ["Arm", "Cell", "CellFileError", "Equation", "EquationError", "Event", "Gate",
            "LogError", "Motion", "MotionError", "Position", "Product", "Robot", "SessionError",
            "Stream", "Together", "Transform", "When", "const", "hold", "joints", "position",
            "stream", "t6"]
# Force: the wrist sensor's reading compensated and carried to the tool (python/examples/
# touch_and_wipe.py).
from ._rccx import external_wrench, wrench_at_tool

__all__ += ["external_wrench", "wrench_at_tool"]
# The web page of a running program (docs/PYTHON.md, "Watching a program").
from ._rccx import ViewError
from . import view

__all__ += ["ViewError", "view"]
