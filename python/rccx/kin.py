"""Robots and their kinematics: forward, inverse (every configuration) and Jacobian.

    import numpy as np, rccx
    k = rccx.kin.robot("puma560")            # or robot_file(path), urdf(path)
    T = k.forward(k.ready)                   # (4, 4), m
    q = k.inverse(T, configuration="lun")    # (6,), rad; rccx.UnreachableError if none
    Ts = k.forward(np.zeros((1000, k.dof)))  # (1000, 4, 4) in one call
"""

from ._rccx.kin import Kinematics, robot, robot_file, robot_names, urdf

__all__ = ["Kinematics", "robot", "robot_file", "robot_names", "urdf"]
