from dataclasses import dataclass

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .kin import Kinematics
from .log import RunLog

@dataclass(frozen=True)
class Series:
    x: np.ndarray
    y: np.ndarray
    colour: str
    label: str
    dashed: bool
    width: float

@dataclass(frozen=True)
class Panel:
    title: str
    xlabel: str
    ylabel: str
    series: list[Series]
    equal_axes: bool

@dataclass(frozen=True)
class RunPlot:
    robot_title: str
    samples: int
    duration_s: float
    worst_path_error_m: float
    panels: list[Panel]

def series(log: RunLog, robot: Kinematics | None = None) -> RunPlot:
    """The numbers of rccx plot's four panels (joints deg/mm, tool path mm, speed mm/s, path
    error mm), from C++ view::run_plot."""
def draw_panel(ax: Axes, panel: Panel) -> None: ...
def figures(log: RunLog, robot: Kinematics | None = None) -> list[Figure]:
    """One Figure a panel."""
def figure(log: RunLog, robot: Kinematics | None = None, title: str | None = None) -> Figure:
    """The four panels in one Figure, as rccx plot lays them out."""

__all__ = ["Panel", "RunPlot", "Series", "figure", "figures", "series", "draw_panel"]
