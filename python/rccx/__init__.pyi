from . import kin as kin

class UnreachableError(ValueError):
    """No joint values within limits put the robot at the pose; the message says why."""

class RobotFileError(ValueError):
    """A robot file or URDF that cannot be used; the message names the file, joint and key."""

__all__ = ["kin", "RobotFileError", "UnreachableError"]

# Run logs, the plots of `rccx plot`, the position database.
from . import db as db, log as log, plot as plot

class RunLogError(ValueError):
    """A file that is not a run log rccx writes, or a log of another robot than the one given;
    the message names the file, the line and the column."""

class DatabaseError(RuntimeError):
    """A position database that cannot be used (missing, not a database, corrupt, from a newer
    rccx, closed), or a request it refuses; nothing was changed."""

class DatabaseBusy(DatabaseError):
    """Another process held the position database for longer than the wait (wait_s)."""

class InvalidTransform(DatabaseError, ValueError):
    """A transform, name, robot, configuration or note put() refuses; nothing was stored."""

__all__ += ["db", "log", "plot", "DatabaseBusy", "DatabaseError", "InvalidTransform",
            "RunLogError"]
# Position equations and robots (rccx/motion.pyi).
from .motion import (Arm as Arm, Cell as Cell, CellFileError as CellFileError,
                     Equation as Equation, EquationError as EquationError, Event as Event,
                     Gate as Gate, LogError as LogError, Motion as Motion,
                     MotionError as MotionError, Position as Position, Product as Product,
                     Robot as Robot, SessionError as SessionError, Stream as Stream,
                     Together as Together, Transform as Transform, When as When, const as const,
                     hold as hold, joints as joints, position as position, stream as stream,
                     t6 as t6)

__all__ += ["Arm", "Cell", "CellFileError", "Equation", "EquationError", "Event", "Gate",
            "LogError", "Motion", "MotionError", "Position", "Product", "Robot", "SessionError",
            "Stream", "Together", "Transform", "When", "const", "hold", "joints", "position",
            "stream", "t6"]
# Force (rccx/motion.pyi).
from .motion import external_wrench as external_wrench, wrench_at_tool as wrench_at_tool

__all__ += ["external_wrench", "wrench_at_tool"]
# The web page of a running program (rccx/view.pyi).
from . import view as view

class ViewError(RuntimeError):
    """The view cannot start (port in use, address, a robot another view serves) or is closed."""

__all__ += ["ViewError", "view"]
