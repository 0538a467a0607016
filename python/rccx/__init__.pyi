from . import kin as kin

class UnreachableError(ValueError):
    """No joint values within limits put the robot at the pose; the message says why."""

class RobotFileError(ValueError):
    """A robot file or URDF that cannot be used; the message names the file, joint and key."""

__all__ = ["kin", "RobotFileError", "UnreachableError"]
