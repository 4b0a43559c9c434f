"""Viewer layouts (rerun blueprints): the 3D scene on the left, the plots on the right."""

from __future__ import annotations

from typing import Any

#: plot panels of a flight recording: (title, entity paths)
FLIGHT_PANELS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("airspeed [m/s]", ("plots/airspeed",)),
    ("altitude [m]", ("plots/altitude",)),
    ("tether tension [N]", ("plots/tension",)),
    ("reel speed [m/s] (+ out)", ("plots/reel_speed",)),
    ("duty [-], fold [-]", ("plots/duty", "plots/fold")),
    ("power [W]", ("plots/power/**",)),
    ("cumulative energy [J]", ("plots/energy/**",)),
    ("tracking error [m]", ("plots/tracking_error",)),
)

#: plot panels of an optimised-cycle recording
CYCLE_PANELS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("airspeed [m/s]", ("plots/airspeed",)),
    ("altitude [m]", ("plots/altitude",)),
    ("tether tension [N]", ("plots/tension",)),
    ("reel speed [m/s] (+ out)", ("plots/reel_speed",)),
    ("alpha, bank [rad]", ("plots/alpha", "plots/bank")),
    ("thrust [N]", ("plots/thrust",)),
    ("power [W]", ("plots/power/**",)),
    ("cumulative energy [J]", ("plots/energy/**",)),
)


def layout(panels: tuple[tuple[str, tuple[str, ...]], ...], title: str) -> Any:
    """3D view of ``world`` (2/5 of the width) beside a grid of time-series panels (a second tab
    holds the run's markdown report) and a phase lane."""
    import rerun.blueprint as rrb

    plots = [rrb.TimeSeriesView(name=name, origin="/", contents=list(paths)) for name, paths in panels]
    right = rrb.Vertical(
        rrb.Tabs(rrb.Grid(*plots, grid_columns=2, name="time series"),
                 rrb.TextDocumentView(name="report", origin="/", contents=["report"]), active_tab=0),
        rrb.StateTimelineView(name="phase", origin="/", contents=["phase"]),
        row_shares=[8, 1],
    )
    scene = rrb.Spatial3DView(name=title, origin="world", contents=["world/**"])
    return rrb.Blueprint(rrb.Horizontal(scene, right, column_shares=[2, 3]), collapse_panels=False)


def flight_blueprint(title: str = "flight") -> Any:
    return layout(FLIGHT_PANELS, title)


def cycle_blueprint(title: str = "optimised cycle") -> Any:
    return layout(CYCLE_PANELS, title)


__all__ = ["CYCLE_PANELS", "FLIGHT_PANELS", "cycle_blueprint", "flight_blueprint", "layout"]
