"""PNG figures in the style of the paper's Fig. 7 (3D cycle) and Fig. 8 (time histories).

- :func:`plot_flight` (a flight: FlightReport / FlightResult, optionally with its reference)
  writes ``<prefix>_3d.png`` and ``<prefix>_time.png`` into a folder;
- :func:`plot_cycle` does the same for an optimised cycle (reference-trajectory file,
  trajectory or CycleResult);
- :func:`plot_compare` overlays several optimised cycles (e.g. nominal vs foldable).

Altitude is drawn upwards (h = -z of NED); positions relative to the winch; phases coloured
(generation blue, recovery orange) in the paths and as shaded bands in the time histories.
Layout: matplotlib's constrained layout keeps every label inside the picture; a panel's legend
sits above its axes (never on the data), the phase legend beside the panels. A flight's power
panel has a robust y-range (:func:`~fdm_awe.recording.series.robust_range`: percentiles of the
samples after the first second), so the motor's start-up spike does not squash it; its legend
says so (an optimised cycle has no start-up: full range). Matplotlib runs headless (Agg).
Every PNG is written under a temporary name and renamed when complete
(:func:`fdm_awe.fileio.atomic_path`): an interrupted save leaves no truncated image.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..fileio import atomic_path
from .rrd import segments_by_label
from .scene import WIND_COLOR, phase_color_float
from .series import Series, cycle_series, flight_series, load_reference, robust_note, robust_range

DEG = 180.0 / np.pi
#: y label of the power panel (its y-range is the robust one)
POWER_LABEL = "power [W]"


def plot_paths(outdir: str | Path, prefix: str) -> tuple[Path, Path]:
    """The two PNGs :func:`plot_flight`, :func:`plot_cycle` and :func:`plot_compare` write into
    ``outdir``: ``<prefix>_3d.png`` and ``<prefix>_time.png``."""
    d = Path(outdir)
    return d / f"{prefix}_3d.png", d / f"{prefix}_time.png"


def _save(fig, out) -> Path:  # noqa: ANN001 - a matplotlib Figure
    """Write ``fig`` to ``out`` atomically (PNG; folders created), close it and return the path.
    The picture is cut to the drawn artists (``bbox_inches="tight"``), so no label a 3D axes
    draws beyond its box is clipped."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    try:
        with atomic_path(out, suffix=".png") as tmp:
            fig.savefig(tmp, format="png", bbox_inches="tight", pad_inches=0.15)
    finally:
        _plt().close(fig)
    return out

def _plt() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _title(meta: dict[str, Any], what: str) -> str:
    from .flight import describe

    return describe(meta, what)


def _reference_series(reference: Any) -> Series | None:
    """A reference as a Series over one cycle (TrackingReference, file, trajectory or CycleResult)."""
    if reference is None:
        return None
    if hasattr(reference, "T1") and hasattr(reference, "sample") and hasattr(reference, "pos"):
        from ..trajectory import PHASE_NAMES

        pos = np.asarray(reference.pos, float)
        labels = [PHASE_NAMES[int(p)] if 0 <= int(p) < len(PHASE_NAMES) else str(p) for p in reference.phase]
        pos = np.vstack([pos, pos[:1]])
        labels = labels + labels[-1:]
        t = np.r_[np.asarray(reference.t, float), reference.period]
        cols = {"x": ("m", pos[:, 0]), "y": ("m", pos[:, 1]), "z": ("m", pos[:, 2])}
        return Series(t=t, columns=cols, phase=labels, meta=dict(reference.meta))
    return cycle_series(reference)


def _wind(meta: dict[str, Any], reference: Any) -> np.ndarray | None:
    for src in (meta, getattr(reference, "meta", None) or {}):
        w = src.get("wind_ned_mps") if isinstance(src, dict) else None
        if w is not None:
            return np.asarray(w, float)
    if reference is not None and not hasattr(reference, "T1"):
        try:
            w = load_reference(reference).metadata.get("wind_ned_mps")
            return None if w is None else np.asarray(w, float)
        except Exception:  # noqa: BLE001 - the arrow is decoration only
            return None
    w = meta.get("wind_mps")
    return None if w is None else np.array([float(w), 0.0, 0.0])


def _draw_path(ax: Any, pos: np.ndarray, labels: Sequence[str], *, ls: str = "-", lw: float = 1.8,
               alpha: float = 1.0, prefix: str = "", seen: set | None = None) -> None:
    seen = set() if seen is None else seen
    for lab, seg in segments_by_label(pos, labels):
        key = prefix + lab
        ax.plot(seg[:, 0], seg[:, 1], -seg[:, 2], ls=ls, lw=lw, alpha=alpha, color=phase_color_float(lab),
                label=None if key in seen else f"{prefix}{lab}")
        seen.add(key)


def figure_3d(paths: Sequence[tuple[str, np.ndarray, Sequence[str], str]], title: str, wind: np.ndarray | None,
              out: str | Path, tether_from: np.ndarray | None = None) -> Path:
    """3D figure of paths ``(name, pos (n, 3) NED, phase labels, linestyle)``; returns the PNG path."""
    plt = _plt()
    fig = plt.figure(figsize=(9.0, 7.0), dpi=110, layout="constrained")
    ax = fig.add_subplot(projection="3d")
    draw_scene_3d(ax, paths, wind, tether_from)
    ax.set_title(title, fontsize=10)
    h, lab = ax.get_legend_handles_labels()
    fig.legend(h, lab, loc="outside lower center", ncol=4, fontsize=8, frameon=False)
    return _save(fig, out)


def draw_scene_3d(ax: Any, paths: Sequence[tuple[str, np.ndarray, Sequence[str], str]], wind: np.ndarray | None,
                  tether_from: np.ndarray | None = None) -> None:
    """Paths, winch, wind arrow, ground shadow, labelled axes with true proportions on a 3D axes."""
    allp = [np.zeros((1, 3))]
    for name, pos, labels, ls in paths:
        pos = np.asarray(pos, float)
        allp.append(pos[np.all(np.isfinite(pos), axis=1)])
        _draw_path(ax, pos, labels, ls=ls, lw=1.2 if ls != "-" else 2.0, alpha=0.75 if ls != "-" else 1.0,
                   prefix=f"{name} " if name else "")
    a = np.vstack(allp)
    ax.scatter([0], [0], [0], marker="s", s=60, color="k", label="winch", depthshade=False)
    if tether_from is not None and np.all(np.isfinite(tether_from)):
        p = np.asarray(tether_from, float)
        ax.plot([0, p[0]], [0, p[1]], [0, -p[2]], color="0.5", lw=0.8, ls=":", label="tether at start")
    xmin, xmax = min(a[:, 0].min(), 0.0), a[:, 0].max()
    ymin, ymax = a[:, 1].min(), a[:, 1].max()
    hmax = max((-a[:, 2]).max(), 1.0)
    span = max(xmax - xmin, ymax - ymin, hmax, 1.0)
    if wind is not None and np.linalg.norm(wind[:2]) > 0:
        w = np.asarray(wind, float)
        L = 0.2 * span
        d = w / np.linalg.norm(w)
        x0, y0 = xmin, ymin
        ax.quiver(x0, y0, 0.0, d[0] * L, d[1] * L, 0.0, color=np.array(WIND_COLOR) / 255.0, lw=2.5,
                  arrow_length_ratio=0.25, label=f"wind {np.linalg.norm(w):.1f} m/s")
    # ground shadow of the first path
    if paths:
        pos = np.asarray(paths[0][1], float)
        ax.plot(pos[:, 0], pos[:, 1], np.zeros(len(pos)), color="0.8", lw=0.8, zorder=0)
    ax.set_xlabel("north x [m]")
    ax.set_ylabel("east y [m]")
    ax.set_zlabel("altitude h [m]")
    # true proportions, but no axis thinner than 40 % of the largest (keeps ticks readable)
    ext = np.array([max(xmax - xmin, 1.0), max(ymax - ymin, 1.0), hmax * 1.05])
    lo = 0.4 * ext.max()
    for i, (a0, a1) in enumerate(((xmin, xmax), (ymin, ymax))):
        if ext[i] < lo:
            c = 0.5 * (a0 + a1)
            (ax.set_xlim if i == 0 else ax.set_ylim)(c - 0.5 * lo, c + 0.5 * lo)
            ext[i] = lo
    ax.set_zlim(0.0, hmax * 1.05)
    ext[2] = max(ext[2], lo)
    ax.set_box_aspect(tuple(ext))
    from matplotlib.ticker import MaxNLocator

    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(6))
    ax.view_init(elev=22, azim=-125)


def thin(t: np.ndarray, y: np.ndarray, max_points: int = 4000) -> tuple[np.ndarray, np.ndarray]:
    """At most about ``max_points`` samples for drawing: per bucket of samples the minimum and
    the maximum are kept (in time order), so spikes survive; NaN buckets stay NaN (gaps)."""
    n = len(t)
    if n <= max_points:
        return t, y
    k = int(np.ceil(2 * n / max_points))
    m = (n // k) * k
    tb, yb = t[:m].reshape(-1, k), y[:m].reshape(-1, k)
    filled = np.where(np.isfinite(yb), yb, np.nan)
    allnan = ~np.isfinite(filled).any(axis=1)
    lo = np.where(allnan, 0, np.nanargmin(np.where(allnan[:, None], 0.0, filled), axis=1))
    hi = np.where(allnan, 0, np.nanargmax(np.where(allnan[:, None], 0.0, filled), axis=1))
    first, second = np.minimum(lo, hi), np.maximum(lo, hi)
    rows = np.arange(len(tb))
    tt = np.column_stack([tb[rows, first], tb[rows, second]]).ravel()
    yy = np.column_stack([yb[rows, first], yb[rows, second]]).ravel()
    yy[np.repeat(allnan, 2)] = np.nan
    return np.r_[tt, t[m:]], np.r_[yy, y[m:]]


def _shade_phases(ax: Any, s: Series) -> None:
    for lab, i0, i1 in s.phase_segments():
        t1 = s.t[min(i1 + 1, len(s.t) - 1)]
        ax.axvspan(s.t[i0], t1, color=phase_color_float(lab), alpha=0.08, lw=0)


def _panels(s: Series, kind: str) -> list[tuple[str, list[tuple[str, str, float]]]]:
    """(y label, [(series, legend, factor)]) per panel."""
    P: list[tuple[str, list[tuple[str, str, float]]]] = [
        ("altitude, distance [m]", [("altitude", "altitude h", 1.0), ("distance", "winch distance |P|", 1.0),
                                    ("tether_length", "tether length l", 1.0)]),
        ("airspeed [m/s]", [("airspeed", "airspeed V", 1.0)]),
    ]
    if kind == "flight":
        P += [
            ("attitude [deg]", [("alpha", "alpha", DEG), ("roll", "bank phi", DEG), ("pitch", "pitch theta", DEG)]),
            ("surfaces, throttle, fold [-]", [("aileron", "aileron", 1.0), ("elevator", "elevator", 1.0),
                                              ("rudder", "rudder", 1.0), ("throttle", "throttle", 1.0),
                                              ("fold", "fold state", 1.0)]),
        ]
    else:
        P += [
            ("alpha, bank [deg]", [("alpha", "alpha", DEG), ("bank", "bank phi", DEG), ("gamma", "path angle gamma", DEG)]),
            ("thrust [N], fold [-]", [("thrust", "thrust T [N]", 1.0), ("fold", "fold state [-]", 1.0)]),
        ]
    P += [
        ("tether tension [N]", [("tension", "tension G", 1.0)]),
        ("reel speed [m/s] (+ out)", [("reel_speed", "reel speed", 1.0)]),
    ]
    if kind == "flight":
        P += [(POWER_LABEL, [("p_electrical", "winch electrical (+ out)", 1.0), ("prop_power", "propeller electrical", 1.0)])]
    else:
        P += [(POWER_LABEL, [("p_generated", "generated", 1.0), ("p_thrust", "thrust", 1.0), ("p_reel_in", "reel-in", 1.0)])]
    P += [("cumulative energy [J]", [("E_generated", "generated", 1.0), ("E_thrust", "thrust", 1.0),
                                     ("E_reel_in", "reel-in", 1.0), ("E_net", "net (gen - thrust - reel-in)", 1.0)])]
    if kind == "flight" and "track_error" in s and np.isfinite(s["track_error"]).any():
        P += [("tracking error [m]", [("track_error", "|p - p_ref|", 1.0)])]
    return [(lab, [c for c in cols if c[0] in s]) for lab, cols in P if any(c[0] in s for c in cols)]


def _legend_above(ax: Any, ncol: int, fontsize: float = 7) -> None:
    """The panel's legend in rows above its axes (the constrained layout makes room)."""
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.02), ncol=max(1, ncol), fontsize=fontsize, frameon=False,
              borderaxespad=0.0, handlelength=1.5, columnspacing=1.0)


def time_figure(s: Series, title: str, kind: str = "flight") -> Any:
    """The Figure of :func:`figure_time` (not saved)."""
    plt = _plt()
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    panels = _panels(s, kind)
    ncol = 2
    nrow = int(np.ceil(len(panels) / ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(13.0, 2.9 * nrow + 0.8), dpi=100, sharex=True, squeeze=False,
                             layout="constrained")
    for ax, (ylab, cols) in zip(axes.flat, panels):
        _shade_phases(ax, s)
        for key, leg, f in cols:
            ax.plot(*thin(s.t, s[key] * f), lw=1.2, label=leg)
        ax.set_ylabel(ylab)
        ax.grid(True, alpha=0.3)
        robust = kind == "flight" and ylab == POWER_LABEL  # a flight's start-up spike; a cycle has none
        if robust:
            rng = robust_range(s.t, [s[key] * f for key, _, f in cols])
            if rng is not None:
                ax.set_ylim(*rng)
                ax.add_line(Line2D([], [], color="none", label=robust_note()))
        if len(ax.get_legend_handles_labels()[0]) > 1:
            _legend_above(ax, min(len(cols) + robust, 3))
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    if len(s.t) > 1 and s.t[-1] > s.t[0]:
        axes.flat[0].set_xlim(float(s.t[0]), float(s.t[-1]))  # the time axis spans the run (shared)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    for i in range(len(panels), nrow * ncol):  # the panel above a hidden one carries the time axis
        above = axes.flat[i - ncol]
        above.xaxis.set_tick_params(labelbottom=True)
        above.set_xlabel("time [s]")
    labs = [lab for lab, _, _ in s.phase_segments()]
    handles = [Patch(color=phase_color_float(lab), alpha=0.3, label=lab) for lab in dict.fromkeys(labs)]
    fig.legend(handles=handles, loc="outside right upper", fontsize=9, title="phase")
    fig.suptitle(title, fontsize=11)
    return fig


def figure_time(s: Series, title: str, out: str | Path, kind: str = "flight") -> Path:
    """Time histories (Fig. 8 style) of ``s``; returns the PNG path."""
    return _save(time_figure(s, title, kind), out)


def plot_flight(flight: Any, reference: Any = None, outdir: str | Path = ".", prefix: str = "flight") -> list[Path]:
    """Fig. 7 / Fig. 8 style PNGs of a flight: ``<prefix>_3d.png``, ``<prefix>_time.png``."""
    s = flight_series(flight)
    rs = _reference_series(reference)
    meta = dict(s.meta)
    title = _title(meta, "flight")
    paths = [("flown", s.pos, s.phase, "-")]
    if rs is not None:
        paths.append(("reference", rs.pos, rs.phase, "--"))
    f3, ft = plot_paths(outdir, prefix)
    p3 = figure_3d(paths, title, _wind(meta, reference), f3, tether_from=s.pos[0] if len(s.pos) else None)
    pt = figure_time(s, title, ft, kind="flight")
    return [p3, pt]


def plot_cycle(reference: Any, outdir: str | Path = ".", prefix: str = "cycle") -> list[Path]:
    """Fig. 7 / Fig. 8 style PNGs of an optimised cycle: ``<prefix>_3d.png``, ``<prefix>_time.png``."""
    s = cycle_series(reference)
    title = _title(s.meta, "optimised cycle")
    f3, ft = plot_paths(outdir, prefix)
    p3 = figure_3d([("", s.pos, s.phase, "-")], title, _wind(s.meta, reference), f3, tether_from=s.pos[0])
    pt = figure_time(s, title, ft, kind="cycle")
    return [p3, pt]


def plot_compare(references: Sequence[Any], names: Sequence[str], outdir: str | Path = ".",
                 prefix: str = "compare") -> list[Path]:
    """Optimised cycles side by side: 3D paths overlaid (one line style each) and the main
    time histories overlaid (``<prefix>_3d.png``, ``<prefix>_time.png``)."""
    plt = _plt()
    series = [cycle_series(r) for r in references]
    styles = ["-", "--", ":", "-."]
    meta = series[0].meta
    base = {k: meta.get(k) for k in ("scenario", "wind_mps")}
    title = _title(base, "optimised cycles: " + " vs ".join(names))
    f3, ft = plot_paths(outdir, prefix)
    p3 = figure_3d([(n, s.pos, s.phase, styles[i % 4]) for i, (n, s) in enumerate(zip(names, series))], title,
                   _wind(meta, references[0]), f3)
    keys = [("altitude", "altitude [m]", 1.0), ("airspeed", "airspeed [m/s]", 1.0), ("tension", "tension [N]", 1.0),
            ("reel_speed", "reel speed [m/s]", 1.0), ("thrust", "thrust [N]", 1.0), ("E_net", "net energy [J]", 1.0)]
    fig, axes = plt.subplots(3, 2, figsize=(12.0, 9.5), dpi=100, sharex=False, layout="constrained")
    for ax, (key, ylab, f) in zip(axes.flat, keys):
        for i, (n, s) in enumerate(zip(names, series)):
            if key in s:
                ax.plot(s.t, s[key] * f, ls=styles[i % 4], lw=1.4, label=n)
                t1 = s.meta.get("T1_s")
                if t1:
                    ax.axvline(float(t1), ls=styles[i % 4], color="0.5", lw=0.8)
        ax.set_ylabel(ylab)
        ax.set_xlabel("cycle time [s]")
        ax.grid(True, alpha=0.3)
        _legend_above(ax, len(names), fontsize=8)
    fig.suptitle(title + "  (grey lines: end of generation)", fontsize=11)
    return [p3, _save(fig, ft)]


def plot_summary(flight: Any, reference: Any = None, out: str | Path = "cycle.png", title: str | None = None) -> Path:
    """One picture of a flight for a README: the 3D cycle (flown and reference, coloured by
    phase) beside altitude, tension / reel speed and the cumulative energies."""
    plt = _plt()
    from matplotlib.patches import Patch

    s = flight_series(flight)
    rs = _reference_series(reference)
    meta = dict(s.meta)
    title = title or _title(meta, "flight")
    fig = plt.figure(figsize=(14.0, 7.5), dpi=100, layout="constrained")
    gs = fig.add_gridspec(3, 2, width_ratios=[1.25, 1.0])
    ax = fig.add_subplot(gs[:, 0], projection="3d")
    paths = [("flown", s.pos, s.phase, "-")]
    if rs is not None:
        paths.append(("reference", rs.pos, rs.phase, "--"))
    draw_scene_3d(ax, paths, _wind(meta, reference), s.pos[0] if len(s.pos) else None)
    h, lab = ax.get_legend_handles_labels()
    ax.legend(h, lab, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=4, fontsize=8, frameon=False)
    rows = [
        ("altitude [m]", [("altitude", "altitude h"), ("tether_length", "tether length l")]),
        ("tension [N] / reel speed [m/s]", [("tension", "tension G [N]"), ("reel_speed", "reel speed [m/s] (+ out)")]),
        ("cumulative energy [J]", [("E_generated", "generated"), ("E_thrust", "thrust"), ("E_reel_in", "reel-in"),
                                   ("E_net", "net")]),
    ]
    for i, (ylab, cols) in enumerate(rows):
        axr = fig.add_subplot(gs[i, 1])
        _shade_phases(axr, s)
        for key, leg in cols:
            axr.plot(*thin(s.t, s[key]), lw=1.2, label=leg)
        axr.set_ylabel(ylab)
        axr.grid(True, alpha=0.3)
        _legend_above(axr, len(cols))
        if i == len(rows) - 1:
            axr.set_xlabel("time [s]")
        else:
            axr.tick_params(labelbottom=False)
    handles = [Patch(color=phase_color_float(lab), alpha=0.3, label=lab) for lab in dict.fromkeys(s.phase)]
    fig.legend(handles=handles, loc="outside right upper", fontsize=8, title="phase (shaded)")
    fig.suptitle(title, fontsize=11)
    return _save(fig, out)


__all__ = ["POWER_LABEL", "draw_scene_3d", "figure_3d", "figure_time", "time_figure", "plot_compare", "plot_cycle", "plot_flight", "plot_paths",
           "plot_summary"]
