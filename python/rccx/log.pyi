import os

import numpy as np

from .kin import Kinematics

def sample_dtype(dof: int) -> np.dtype:
    """Fields: t_s float64 (s), segment int32, commanded (dof,) and measured (dof,) float64
    (rad or m), p_m (3,) float64 (m), approach (3,) float64 (unit vector)."""

class RunLog:
    path: str
    dof: int
    samples: np.ndarray
    """Structured array (read-only), one element a sample: see sample_dtype."""
    has_header: bool
    robot_name: str | None
    kinematics: str | None
    name: str | None
    period_s: float | None
    """Sample period, s."""
    simulated: bool | None
    rccx_version: str | None
    def __len__(self) -> int: ...
    def robot(self, robot: Kinematics | None = None) -> Kinematics:
        """The robot the log is drawn as: its header's (or `robot`, which must match it)."""
    def path_errors_m(self, robot: Kinematics | None = None) -> np.ndarray:
        """The path error at each sample, m, shape (N,); its max is rccx plot's worst."""

def load(path: str | os.PathLike[str]) -> RunLog:
    """Reads a run log (RCCX_LOG, --log). Raises FileNotFoundError, rccx.RunLogError."""

__all__ = ["RunLog", "load", "sample_dtype"]
