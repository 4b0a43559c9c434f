"""The 3D scene of a recording (NED, winch at the origin): ground, winch, wind, paths, glider.

Entity layout (all under ``world``, whose view coordinates are FRD = north, east, down, so
the viewer shows altitude upwards):

- ``world/ground`` grid lines every 50 m; ``world/winch`` the winch; ``world/wind`` an arrow
  showing where the wind blows to (length 10 m per m/s);
- ``world/<path>/<phase>`` a path drawn as one line strip per phase run (``world/flown/live``:
  the path flown so far, re-sent every second of flight time);
- ``world/glider`` pose over time (translation + attitude quaternion), with
  ``world/glider/airframe`` the glider as a mesh drawn ``scale`` times enlarged (a 1.1 m glider
  is a dot next to a 250 m line): ``body`` (fuselage and tail) and ``wing``, whose span follows
  the fold state over time;
- ``world/forces/<name>`` arrows of the forces on the glider (lift, drag, tether, thrust) from
  its CG, ``FORCE_SCALE`` m per N, the scale and the forces' origin told in the static
  ``description`` of ``world/forces``;
- ``world/tether`` the straight line winch -> glider over time (the lumped line: its segments,
  coloured by tension, and ``world/tether_tension`` the tension along it).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .rrd import RecordingSink, segments_by_label
from .scene import REFERENCE_COLOR, TETHER_COLOR, WIND_COLOR, glider_shape, ground_grid, phase_color

#: default enlargement of the drawn glider
GLIDER_SCALE = 10.0
#: length of the force arrows [m per N]
FORCE_SCALE = 1.0
#: colour of each force arrow
FORCE_COLORS: dict[str, tuple[int, int, int]] = {
    "lift": (31, 119, 180), "drag": (255, 127, 14), "tether": TETHER_COLOR, "thrust": (44, 160, 44),
}
#: what the force arrows show (the static description of ``world/forces``; ``{scale}`` m per N)
FORCES_TEXT = ("Forces on the glider, arrows from its CG, {scale:g} m per N: lift and drag (aerodynamic force "
               "from Newton's second law on the logged motion, split in wind axes; the side force is not drawn), "
               "tether (the ground station's force on the glider, as logged), thrust (logged thrust along the "
               "body x axis).")


def log_static_scene(rf: RecordingSink, extent: tuple[tuple[float, float], tuple[float, float]],
                     wind_ned: Sequence[float] | None) -> None:
    """View coordinates, ground grid, winch and wind arrow."""
    rr = rf.rr
    rf.static("world", rr.ViewCoordinates.FRD)
    grid = ground_grid(*extent)
    rf.static("world/ground", rr.LineStrips3D(grid, colors=[(170, 170, 170)], radii=[0.15]))
    rf.static("world/winch", rr.Points3D([[0.0, 0.0, 0.0]], radii=[3.0], colors=[(0, 0, 0)], labels=["winch"]))
    if wind_ned is not None:
        w = np.asarray(wind_ned, float)
        sp = float(np.linalg.norm(w))
        if sp > 0:
            origin = np.array([extent[0][0] + 20.0, extent[1][0] + 20.0, -2.0])
            rf.static("world/wind", rr.Arrows3D(vectors=[10.0 * w], origins=[origin], colors=[WIND_COLOR],
                                                radii=[1.0], labels=[f"wind {sp:.1f} m/s"]))


def log_path(rf: RecordingSink, entity: str, points: np.ndarray, labels: Sequence[str], *, radius: float = 0.6,
             reference: bool = False, t: float | None = None) -> None:
    """A path, one line strip per phase run, coloured by phase (``reference``: lighter, thinner):
    static, or from simulation time ``t`` [s] on."""
    rr = rf.rr
    runs: dict[str, list[np.ndarray]] = {}
    for lab, seg in segments_by_label(points, labels):
        runs.setdefault(lab, []).append(seg)
    for lab, segs in runs.items():
        c = np.array(phase_color(lab), float)
        if reference:
            c = 0.55 * c + 0.45 * np.array(REFERENCE_COLOR) + 0.0
        strips = rr.LineStrips3D(segs, colors=[tuple(int(v) for v in c)], radii=[radius],
                                 labels=[f"{'reference ' if reference else ''}{lab}"])
        if t is None:
            rf.static(f"{entity}/{lab}", strips)
        else:
            rf.at(f"{entity}/{lab}", t, strips)


def log_paths_so_far(rf: RecordingSink, entity: str, t: np.ndarray, paths: Sequence[Sequence[tuple[str, np.ndarray]]],
                     *, radius: float = 0.5) -> None:
    """The path flown so far at each simulation time of ``t`` [s] into one entity, in one call:
    ``paths[i]`` the path at ``t[i]`` as its runs of one phase (label, points (n, 3) NED m),
    each drawn as a line strip coloured by its phase (a run of fewer than 2 points is left out)."""
    if not len(t):
        return
    strips, colors, lengths = [], [], []
    for runs in paths:
        kept = [(lab, pts) for lab, pts in runs if len(pts) >= 2]
        strips += [pts for _, pts in kept]
        colors += [phase_color(lab) for lab, _ in kept]
        lengths.append(len(kept))
    cols = rf.rr.LineStrips3D.columns(strips=strips, colors=colors, radii=np.full(len(strips), radius))
    rf.columns(entity, np.asarray(t, float), cols.partition(lengths=lengths))


def log_airframe(rf: RecordingSink, scale: float = GLIDER_SCALE, aircraft: Any = None) -> None:
    """The static part of the glider: its enlargement and the body mesh (fuselage, tail, fin) of
    ``aircraft`` (None: the package's glider)."""
    rr = rf.rr
    verts, tris = glider_shape(aircraft).body_mesh()
    rf.static("world/glider/airframe", rr.Transform3D(scale=scale))
    rf.static("world/glider/airframe", rr.AnyValues(description=f"the glider, drawn {scale:g} times enlarged"))
    rf.static("world/glider/airframe/body", rr.Mesh3D(vertex_positions=verts, triangle_indices=tris,
                                                      albedo_factor=(60, 60, 70)))


def log_glider(rf: RecordingSink, t: np.ndarray, pos: np.ndarray, quat_wxyz: np.ndarray, fold: np.ndarray | None,
               *, fold_step: float = 0.01, last_fold: float | None = None, aircraft: Any = None) -> float | None:
    """Glider pose over time and its wing mesh; the wing is re-sent only when the fold state has
    moved by ``fold_step`` since the last sent shape (``last_fold``: sent before these rows,
    None: nothing yet); the wing of ``aircraft`` (None: the package's glider). Returns the fold
    state of the last wing sent."""
    rr = rf.rr
    shape = glider_shape(aircraft)
    ok = np.all(np.isfinite(pos), axis=1) & np.all(np.isfinite(quat_wxyz), axis=1)
    t, pos, q = t[ok], pos[ok], quat_wxyz[ok]
    if not len(t):
        return last_fold
    xyzw = q[:, [1, 2, 3, 0]]
    rf.columns("world/glider", t, rr.Transform3D.columns(translation=pos, quaternion=xyzw))
    f = np.zeros(len(t)) if fold is None else np.nan_to_num(np.asarray(fold, float)[ok])
    for i in range(len(f)):
        if last_fold is None or abs(f[i] - last_fold) >= fold_step or (f[i] != last_fold and i == len(f) - 1):
            last_fold = float(f[i])
            verts, tris = shape.wing_mesh(last_fold)
            rf.at("world/glider/airframe/wing", float(t[i]), rr.Mesh3D(vertex_positions=verts, triangle_indices=tris,
                                                                       albedo_factor=(230, 230, 235)))
    return last_fold


def log_forces_description(rf: RecordingSink, scale: float = FORCE_SCALE) -> None:
    """The static description of the force arrows (what they are, ``scale`` m per N)."""
    rf.static("world/forces", rf.rr.AnyValues(description=FORCES_TEXT.format(scale=scale), scale_m_per_N=float(scale)))


def log_forces(rf: RecordingSink, t: np.ndarray, pos: np.ndarray, forces: dict[str, np.ndarray],
               scale: float = FORCE_SCALE) -> None:
    """One arrow per force and row at ``world/forces/<name>``: from the glider's CG ``pos``
    (n, 3) NED [m], ``scale`` [m per N] times the force (n, 3) NED [N]; rows with a non-finite
    position or force are skipped."""
    rr = rf.rr
    for name, f in forces.items():
        ok = np.all(np.isfinite(pos), axis=1) & np.all(np.isfinite(f), axis=1)
        n = int(ok.sum())
        if not n:
            continue
        cols = rr.Arrows3D.columns(vectors=scale * f[ok], origins=pos[ok], colors=[FORCE_COLORS.get(name, (0, 0, 0))] * n,
                                   radii=[0.25] * n, labels=[name] * n)
        rf.columns(f"world/forces/{name}", t[ok], cols)


def log_tether(rf: RecordingSink, t: np.ndarray, pos: np.ndarray, tension: np.ndarray | None = None) -> None:
    """Straight tether winch -> glider over time; thin and grey when slack, red when loaded."""
    rr = rf.rr
    ok = np.all(np.isfinite(pos), axis=1)
    t, pos = t[ok], pos[ok]
    if not len(t):
        return
    n = len(t)
    strips = np.zeros((n, 2, 3))
    strips[:, 1] = pos
    tens = np.zeros(n) if tension is None else np.nan_to_num(np.asarray(tension, float)[ok])
    taut = tens > 0.5
    colors = np.where(taut[:, None], np.array(TETHER_COLOR), np.array((150, 150, 150))).astype(np.uint8)
    radii = np.where(taut, 0.35, 0.15).astype(np.float32)
    rf.columns("world/tether", t, rr.LineStrips3D.columns(strips=strips, colors=colors, radii=radii))


def log_tether_nodes(rf: RecordingSink, t: np.ndarray, nodes: np.ndarray, tension: np.ndarray) -> None:
    """The lumped line over time: ``nodes`` (m, N+1, 3) m NED winch first, ``tension`` (m, N) N per
    segment. Each segment is drawn grey when slack and from orange to red with its share of the
    largest tension of the flight; ``world/tether_tension`` holds the tension along the line
    (winch first) as a bar chart at each sample."""
    rr = rf.rr
    top = max(float(np.nanmax(tension)) if tension.size else 0.0, 1e-9)
    for k in range(len(t)):
        p = nodes[k]
        if not np.all(np.isfinite(p)):
            continue
        strips = np.stack([p[:-1], p[1:]], axis=1)
        f = np.clip(np.nan_to_num(tension[k]) / top, 0.0, 1.0)
        taut = f > 0.0
        col = np.array(TETHER_COLOR, float)
        warm = np.array((255.0, 160.0, 60.0))
        colors = np.where(taut[:, None], warm + f[:, None] * (col - warm), 150.0).astype(np.uint8)
        radii = np.where(taut, 0.35, 0.15).astype(np.float32)
        rf.at("world/tether", float(t[k]), rr.LineStrips3D(strips, colors=colors, radii=radii))
        rf.at("world/tether_tension", float(t[k]), rr.BarChart(np.nan_to_num(tension[k])))


def log_point(rf: RecordingSink, entity: str, t: np.ndarray, pos: np.ndarray, color: Sequence[int], radius: float = 1.5) -> None:
    """A moving marker (e.g. the current reference point); rows with NaN are skipped."""
    rr = rf.rr
    ok = np.all(np.isfinite(pos), axis=1)
    if not ok.any():
        return
    n = int(ok.sum())
    rf.columns(entity, t[ok], rr.Points3D.columns(positions=pos[ok], colors=[tuple(color)] * n, radii=[radius] * n))


def log_error_line(rf: RecordingSink, entity: str, t: np.ndarray, pos: np.ndarray, ref: np.ndarray) -> None:
    """A thin line from the glider to its reference point over time (the tracking error)."""
    rr = rf.rr
    ok = np.all(np.isfinite(pos), axis=1) & np.all(np.isfinite(ref), axis=1)
    if not ok.any():
        return
    strips = np.stack([pos[ok], ref[ok]], axis=1)
    n = len(strips)
    rf.columns(entity, t[ok], rr.LineStrips3D.columns(strips=strips, colors=[REFERENCE_COLOR] * n,
                                                      radii=[0.1] * n))


def log_phase(rf: RecordingSink, t: np.ndarray, labels: Sequence[str], *, previous: str | None = None,
              states: Sequence[str] | set[str] | None = None) -> None:
    """Phase as a state lane: one state change per switch (``previous``: the label before these
    rows, None when they are the first), coloured per label of ``states`` (default ``labels``)."""
    rr = rf.rr
    if not len(t):
        return
    idx = [i for i in range(len(labels)) if labels[i] != (labels[i - 1] if i else previous)]
    values = sorted(set(labels) if states is None else set(states))
    rf.static("phase", rr.StateConfiguration(values=values, colors=[phase_color(v) for v in values]))
    if idx:
        rf.columns("phase", np.asarray(t)[idx], rr.StateChange.columns(state=[labels[i] for i in idx]))


__all__ = ["FORCES_TEXT", "FORCE_COLORS", "FORCE_SCALE", "GLIDER_SCALE", "log_airframe", "log_error_line", "log_forces",
           "log_forces_description", "log_glider", "log_path", "log_paths_so_far", "log_phase", "log_point",
           "log_static_scene", "log_tether", "log_tether_nodes"]
