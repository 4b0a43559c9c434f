"""Viewer layouts (rerun blueprints): the 3D scene on the left, the plots on the right.

A flight's layout also has the mode lane (a plot panel: autopilot mode number, winch mode,
phase code, lined up with the other plots) and shows below the plots the phase lane with the
same modes by name under it (a state timeline: the autopilot's mode and the winch's mode as
coloured lanes), the log of the mode changes (one line per change, its level per mode) and the
event log (autopilot messages, how the run ended). A panel may get a fixed initial y-range (``y_ranges``): the flight's
power panel is given a robust one (:func:`fdm_awe.recording.series.robust_range`), so the
motor's start-up spike does not squash it; its title then says so.
"""

from __future__ import annotations

from typing import Any

from .series import robust_note

#: title of the power panel (both layouts)
POWER_PANEL = "power [W]"

#: title of a flight's mode lane: the autopilot's mode number, the winch's mode and the phase code
MODE_PANEL = "modes: autopilot (MAVLink custom_mode), winch (0 generator, 1 motor), phase (0 gen., 1 rec.)"

#: root of a flight's named mode lanes (state changes): ``modes/autopilot``, ``modes/winch``
MODE_LANES = "modes"
#: entity of a flight's log of mode changes (text log: one line per change of a lane)
MODE_LOG = "mode_changes"
#: title of a flight's state timeline of the modes by name
STATE_PANEL = "autopilot mode, winch mode"

#: plot panels of a flight recording: (title, entity paths)
FLIGHT_PANELS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("airspeed [m/s]", ("plots/airspeed",)),
    ("altitude [m]", ("plots/altitude",)),
    ("tether tension [N]", ("plots/tension",)),
    ("attitude [rad]", ("plots/attitude/**",)),
    ("alpha, beta [rad]", ("plots/flow/**",)),
    ("surfaces, throttle [-]", ("plots/surfaces/**",)),
    ("forces on the glider [N]", ("plots/forces/**",)),
    ("reel speed [m/s] (+ out)", ("plots/reel_speed",)),
    ("duty [-], fold [-]", ("plots/duty", "plots/fold")),
    (POWER_PANEL, ("plots/power/**",)),
    ("cumulative energy [J]", ("plots/energy/**",)),
    ("tracking error [m]", ("plots/tracking_error",)),
    (MODE_PANEL, ("plots/mode/**",)),
)

#: plot panels of an optimised-cycle recording
CYCLE_PANELS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("airspeed [m/s]", ("plots/airspeed",)),
    ("altitude [m]", ("plots/altitude",)),
    ("tether tension [N]", ("plots/tension",)),
    ("reel speed [m/s] (+ out)", ("plots/reel_speed",)),
    ("alpha, bank [rad]", ("plots/alpha", "plots/bank")),
    ("thrust [N]", ("plots/thrust",)),
    (POWER_PANEL, ("plots/power/**",)),
    ("cumulative energy [J]", ("plots/energy/**",)),
)


def layout(panels: tuple[tuple[str, tuple[str, ...]], ...], title: str, *, events: bool = False,
           y_ranges: dict[str, tuple[float, float]] | None = None, grid_columns: int = 2, modes: bool = False) -> Any:
    """3D view of ``world`` (2/5 of the width) beside a grid of time-series panels (a second tab
    holds the run's markdown report), a phase lane and, with ``events``, the event log; with
    ``modes``, the named mode lanes (:data:`MODE_LANES`) under the phase lane and the log of
    mode changes (:data:`MODE_LOG`) beside them.
    ``y_ranges``: panel title -> initial robust y-range; such a panel's title says so."""
    import rerun.blueprint as rrb

    y_ranges = y_ranges or {}
    plots = []
    for name, paths in panels:
        rng = y_ranges.get(name)
        axis = {} if rng is None else {"axis_y": rrb.ScalarAxis(range=rng, zoom_lock=False)}
        plots.append(rrb.TimeSeriesView(name=name if rng is None else f"{name} ({robust_note()})", origin="/",
                                        contents=list(paths), **axis))
    lane = rrb.StateTimelineView(name="phase", origin="/", contents=["phase"])
    if modes:
        lane = rrb.Vertical(lane, rrb.StateTimelineView(name=STATE_PANEL, origin="/", contents=[f"{MODE_LANES}/**"]),
                            row_shares=[1, 2])
    logs = [rrb.TextLogView(name="mode changes", origin=MODE_LOG)] if modes else []
    if events:
        logs.append(rrb.TextLogView(name="events", origin="events"))
    bottom = rrb.Horizontal(lane, *logs, column_shares=[len(logs), *([1] * len(logs))]) if logs else lane
    right = rrb.Vertical(
        rrb.Tabs(rrb.Grid(*plots, grid_columns=grid_columns, name="time series"),
                 rrb.TextDocumentView(name="report", origin="/", contents=["report"]), active_tab=0),
        bottom,
        row_shares=[6, 3] if modes else [7, 2] if events else [8, 1],
    )
    scene = rrb.Spatial3DView(name=title, origin="world", contents=["world/**"])
    return rrb.Blueprint(rrb.Horizontal(scene, right, column_shares=[2, 3]), collapse_panels=False)


def flight_blueprint(title: str = "flight", power_range: tuple[float, float] | None = None) -> Any:
    """Layout of a flight (``power_range``: robust y-range of the power panel [W])."""
    return layout(FLIGHT_PANELS, title, events=True, grid_columns=3, modes=True,
                  y_ranges=None if power_range is None else {POWER_PANEL: power_range})


def cycle_blueprint(title: str = "optimised cycle") -> Any:
    return layout(CYCLE_PANELS, title)


__all__ = ["CYCLE_PANELS", "FLIGHT_PANELS", "MODE_LANES", "MODE_LOG", "MODE_PANEL", "POWER_PANEL", "STATE_PANEL",
           "cycle_blueprint", "flight_blueprint", "layout"]
