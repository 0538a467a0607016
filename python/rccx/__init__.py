"""rccx for Python: robot kinematics (rccx.kin) over rccx's C++ library.

Transforms are NumPy (4, 4) float64 arrays, positions in m; joint values are rad (revolute) or
m (prismatic). docs/PYTHON.md has the API beside the C++ names.
"""

from ._rccx import RobotFileError, UnreachableError
from . import kin

__all__ = ["kin", "RobotFileError", "UnreachableError"]
