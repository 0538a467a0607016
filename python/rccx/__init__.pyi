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
