import os
from typing import Optional, Union

import numpy as np
import numpy.typing as npt

_ArrayLike = npt.ArrayLike
_F64 = npt.NDArray[np.float64]

class Kinematics:
    """A robot model and its solver (C++ rccx::kin::Kinematics)."""

    def forward(self, q: _ArrayLike) -> _F64:
        """T6 in the base frame (m): q (dof,) -> (4, 4); q (N, dof) -> (N, 4, 4). q: rad or m."""
    def jacobian(self, q: _ArrayLike) -> _F64:
        """Geometric Jacobian of T6 in the base frame: (6, dof) or (N, 6, dof); rows m/s then rad/s."""
    def inverse(
        self,
        T: _ArrayLike,
        configuration: Optional[str] = None,
        near: Optional[_ArrayLike] = None,
        redundant: Optional[float] = None,
    ) -> _F64:
        """Joint values (dof,), rad or m, within limits that put T6 at T (4, 4), m.

        Raises rccx.UnreachableError with rccx's reason, ValueError for bad arguments."""
    def inverse_all(
        self, T: _ArrayLike, near: Optional[_ArrayLike] = None
    ) -> list[tuple[Optional[str], _F64]]:
        """Every configuration's solution within limits: (configuration name or None, q)."""
    def configuration_of(self, q: _ArrayLike) -> Optional[str]:
        """The configuration q (rad or m) is in; None for robots solved numerically."""
    @property
    def name(self) -> str: ...
    @property
    def title(self) -> str: ...
    @property
    def dof(self) -> int: ...
    @property
    def solver(self) -> str:
        """"microbo", "puma" or "dh"."""
    @property
    def configuration_names(self) -> list[str]: ...
    @property
    def joint_names(self) -> list[str]: ...
    @property
    def joint_units(self) -> list[str]:
        """"rad" or "m" per joint."""
    @property
    def lower(self) -> _F64:
        """Lower limits, rad or m (dof,)."""
    @property
    def upper(self) -> _F64:
        """Upper limits, rad or m (dof,)."""
    @property
    def ready(self) -> _F64:
        """Ready pose, rad or m (dof,)."""
    @property
    def max_velocity(self) -> _F64:
        """Fastest joint speeds, rad/s or m/s (dof,)."""

def robot_names() -> list[str]: ...
def robot(name: str) -> Kinematics:
    """A shipped robot ("puma560", "ur5e", "panda", ...); KeyError for an unknown name."""
def robot_file(path: Union[str, os.PathLike[str]]) -> Kinematics:
    """A robot file (JSON); FileNotFoundError, rccx.RobotFileError."""
def urdf(
    path: Union[str, os.PathLike[str]],
    base_link: Optional[str] = None,
    tip_link: Optional[str] = None,
) -> Kinematics:
    """The chain of a URDF from base_link (default: root) to tip_link (default: the only leaf)."""

__all__ = ["Kinematics", "robot", "robot_file", "robot_names", "urdf"]
