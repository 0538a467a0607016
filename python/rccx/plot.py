"""The plots of `rccx plot` as Matplotlib figures: the numbers from rccx's C++ (view::run_plot,
the same series `rccx plot` draws into its SVG), the drawing from Matplotlib.

    import rccx
    log = rccx.log.load("run.csv")
    fig = rccx.plot.figure(log)                  # the four panels, as `rccx plot` lays them out
    fig.savefig("run.png")
    for f in rccx.plot.figures(log): ...         # one Figure a panel
    p = rccx.plot.series(log)                    # the numbers only: p.panels[k].series[j].x ...

The figures are matplotlib.figure.Figure objects made without pyplot (no global state; any
backend saves them). Panels, in order: the joints (deg or mm against t s; measured solid,
commanded dashed), the tool path in the plane it spans most (mm, equal axes), the speed along
the path (mm/s), the path error (mm).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _rccx
from .log import RunLog

__all__ = ["Panel", "RunPlot", "Series", "figure", "figures", "series", "draw_panel"]


@dataclass(frozen=True)
class Series:
    """One line: y against x, in its panel's units (xlabel, ylabel)."""
    x: np.ndarray
    y: np.ndarray
    colour: str
    label: str    # "" for a commanded joint (dashed, beside its measured one)
    dashed: bool
    width: float  # px in the SVG


@dataclass(frozen=True)
class Panel:
    title: str
    xlabel: str   # with its unit ("t s", "x mm")
    ylabel: str
    series: list[Series]
    equal_axes: bool  # the same scale on both axes (the tool path)


@dataclass(frozen=True)
class RunPlot:
    """What `rccx plot` draws: its subtitle's figures and its four panels."""
    robot_title: str
    samples: int
    duration_s: float
    worst_path_error_m: float
    panels: list[Panel]


def series(log: RunLog, robot: _rccx.kin.Kinematics | None = None) -> RunPlot:
    """The series of `rccx plot` for log (C++ view::run_plot), drawn as its header's robot (or
    `robot`: see RunLog.robot). Raises rccx.RunLogError as `rccx plot` refuses."""
    title, samples, duration_s, worst_m, panels = _rccx.plot.run_plot(log._data, robot)
    return RunPlot(title, samples, duration_s, worst_m,
                   [Panel(t, xl, yl, [Series(*s) for s in ss], eq) for t, xl, yl, ss, eq in panels])


def draw_panel(ax, panel: Panel) -> None:
    """Draws one panel into a Matplotlib Axes: its lines, title, axis labels and legend."""
    for s in panel.series:
        ax.plot(s.x, s.y, color=s.colour, linestyle="--" if s.dashed else "-",
                linewidth=s.width * 0.75, label=s.label or None)  # px at 96 dpi -> pt
    ax.set_title(panel.title, fontsize=10)
    ax.set_xlabel(panel.xlabel)
    ax.set_ylabel(panel.ylabel)
    ax.grid(True, color="#e4e4e4")
    if panel.equal_axes:
        ax.set_aspect("equal", adjustable="datalim")
    if any(s.label for s in panel.series):
        ax.legend(fontsize=8, loc="best")


def _new_figure(**kwargs):
    from matplotlib.figure import Figure  # noqa: PLC0415 (Matplotlib only when plotting)
    return Figure(**kwargs)


def figures(log: RunLog, robot: _rccx.kin.Kinematics | None = None) -> list:
    """The four panels of `rccx plot`, one matplotlib.figure.Figure each (6 x 4.5 in)."""
    out = []
    for panel in series(log, robot).panels:
        fig = _new_figure(figsize=(6, 4.5), layout="constrained")
        draw_panel(fig.add_subplot(), panel)
        out.append(fig)
    return out


def figure(log: RunLog, robot: _rccx.kin.Kinematics | None = None, title: str | None = None):
    """The four panels in one matplotlib.figure.Figure laid out as `rccx plot`'s SVG (2 x 2,
    12 x 9 in), headed by title (default: the log's file name) and the same subtitle."""
    p = series(log, robot)
    fig = _new_figure(figsize=(12, 9), layout="constrained")
    if title is None:
        import os  # noqa: PLC0415
        title = os.path.basename(log.path)
    fig.suptitle(f"{title}\n{p.robot_title}: {p.samples} samples, {p.duration_s:.2f} s; worst path "
                 f"error {p.worst_path_error_m * 1e3:.3f} mm (measured tool from the commanded "
                 "path, every sample)", fontsize=11)
    for k, panel in enumerate(p.panels):
        draw_panel(fig.add_subplot(2, 2, k + 1), panel)
    return fig
