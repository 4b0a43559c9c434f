"""A flight's recording over its two timelines (simulation time and pumping cycle), its mode
lane and the path flown so far, read back with rerun's reader.

The flights are a small circle (radius 20 m at 100 m, 14 m/s: a period of about 9 s) flown
for three cycles, and 3 s of it switched to RECOVER after 2 s.
"""

from __future__ import annotations

import numpy as np
import pytest

from fdm_awe.mode_table import MODE_NUMBERS
from fdm_awe.recording import FlightRecording, record_flight, rrd_entities, rrd_values
from fdm_awe.recording.flight import LIVE_PATH, PATH_EVERY_S
from fdm_awe.recording.inspect import rrd_timeline, rrd_views
from fdm_awe.recording.rrd import CYCLE_TIMELINE, TIMELINE

CYCLES = 3


@pytest.fixture(scope="module")
def small_circle():
    from fdm_awe.autopilot.tracking import TrackingReference

    th = np.linspace(0.0, 2.0 * np.pi, 24, endpoint=False)
    pts = np.c_[60.0 + 20.0 * np.cos(th), 20.0 * np.sin(th), np.full_like(th, -100.0)]
    return TrackingReference.from_waypoints(pts, None, None, speed=14.0)


@pytest.fixture(scope="module")
def cycles_rrd(small_circle, tmp_path_factory):
    from fdm_awe.sim.flight import fly

    rep = fly(small_circle, config="foldable", cycles=CYCLES)
    path = record_flight(rep, small_circle, tmp_path_factory.mktemp("rec") / "cycles.rrd")
    return rep, path


def _cycle_of_rows(rep) -> np.ndarray:
    """The cycle each row belongs to: the label carried forward, 0 before the first cycle."""
    lab = np.asarray(rep.cycle_index, int)
    out = np.zeros(len(lab), int)
    cur = 0
    for i, c in enumerate(lab):
        cur = c if c >= 0 else cur
        out[i] = cur
    return out


def test_every_row_carries_its_cycle_0_to_k_minus_1(small_circle, cycles_rrd):
    rep, path = cycles_rrd
    assert rep.status == "ok" and [c.index for c in rep.cycles] == list(range(CYCLES))
    assert all(c.complete for c in rep.cycles)
    tl = rrd_timeline(path, CYCLE_TIMELINE)
    assert tl, "no temporal rows"
    for entity, info in tl.items():  # the scene, the plots, the lanes, the events: every row
        assert info.on_timeline == info.rows > 0, entity
    assert tl["/plots/altitude"].values == tuple(range(CYCLES))
    assert tl["/events"].values[-1] == CYCLES - 1  # the end of the flight: in the last cycle
    # row by row: the cycle the flight's log labels it with, carried over the rows outside a cycle
    _, cyc_t, cyc = rrd_values(path, "/plots/altitude", "Scalars:scalars", timeline=CYCLE_TIMELINE)
    _, t, alt = rrd_values(path, "/plots/altitude", "Scalars:scalars", timeline=TIMELINE)
    expect = _cycle_of_rows(rep)
    assert len(t) == len(expect)
    # rrd_values reads a sequence as if it were nanoseconds: back to the cycle numbers
    np.testing.assert_array_equal(np.rint(np.asarray(cyc_t) * 1e9).astype(int), np.sort(expect))
    # each cycle starts where the last one ended (the rows' labels and the cycle log agree, to a
    # row) and at least about one lap of the circle after it (the glider's own pace: a cycle is
    # never cut short; the rejoin of a lost path may fly a lap twice over: the first cycle takes
    # 17.9 s, the second 9.5 s, the circle's period is 8.95 s)
    starts = [float(rep.result.t[np.argmax(expect == k)] - rep.result.t[0]) for k in range(CYCLES)]
    row = float(np.median(np.diff(rep.result.t)))
    np.testing.assert_allclose(np.diff(starts), [c.T1_s + c.T2_s for c in rep.cycles[:-1]], rtol=0.0, atol=1.5 * row)
    assert np.all(np.diff(starts) > 0.8 * small_circle.period)


def test_no_wall_clock_timeline(cycles_rrd):
    _, path = cycles_rrd
    for name in ("log_time", "log_tick"):
        assert all(info.on_timeline == 0 for info in rrd_timeline(path, name).values()), name


def test_path_so_far_grows_during_the_flight_and_the_whole_path_ends_it(cycles_rrd):
    rep, path = cycles_rrd
    _, times, strips = rrd_values(path, "/" + LIVE_PATH, "LineStrips3D:strips")
    T = rep.sim_time_s
    assert T > CYCLES * 5.0
    # about one path a second of flight time, from the start to the end
    assert len(times) == pytest.approx(T / PATH_EVERY_S, abs=2)
    assert times[0] == pytest.approx(0.0, abs=1e-6) and times[-1] <= T + 1e-6
    assert np.all(np.diff(times) > 0.5 * PATH_EVERY_S)
    counts = [sum(len(s) for s in row) for row in strips]
    before = [c for t, c in zip(times, counts) if 2.0 <= t < T - 2.0]
    assert len(before) > 10 and np.all(np.diff(before) > 0)  # it grows, second by second
    # the path so far at time t lies on the flown path up to t
    k = len(times) // 2
    pts = np.concatenate([np.asarray(s, float) for s in strips[k]])
    flown = rep.result.pos[rep.result.t - rep.result.t[0] <= times[k] + 1e-6]
    d = np.min(np.linalg.norm(pts[:, None, :] - flown[None, ::4, :], axis=2), axis=1)
    assert d.max() < 1.0
    assert np.linalg.norm(pts[-1] - flown[-1]) < 5.0  # it reaches the glider (14 m/s x 0.2 s + margin)
    # at the end: the path so far cleared, the whole path (every row) in its place
    ent = rrd_entities(path)
    assert "Clear:is_recursive" in ent["/" + LIVE_PATH].components
    assert ent["/world/flown/generation"].t_min == pytest.approx(T, abs=1e-6)
    _, _, whole = rrd_values(path, "/world/flown/generation", "LineStrips3D:strips")
    assert sum(len(s) for s in whole[-1]) > 4 * max(counts)


def test_mode_lane_of_a_cycling_flight(cycles_rrd):
    rep, path = cycles_rrd
    _, t, rows = rrd_values(path, "/plots/mode/autopilot", "Scalars:scalars")
    assert set(np.asarray(rows, float).ravel()) == {MODE_NUMBERS["AUTO"]}
    assert t[0] == pytest.approx(0.0) and t[-1] == pytest.approx(rep.sim_time_s, abs=1e-6)
    _, _, phase = rrd_values(path, "/plots/mode/phase", "Scalars:scalars")
    assert set(np.asarray(phase, float).ravel()) <= {0.0, 1.0, -1.0}
    _, _, winch = rrd_values(path, "/plots/mode/winch", "Scalars:scalars")
    assert set(np.asarray(winch, float).ravel()) <= {0.0, 1.0}
    views = rrd_views(path)
    lane = [name for name, q in views.items() if any("plots/mode" in x for x in q)]
    assert len(lane) == 1 and "autopilot" in lane[0]


def _switched_flight(reference, tmp_path, k_switch: int = 240):
    """3 s of ``reference`` with the autopilot switched to RECOVER at step ``k_switch`` (2 s),
    buffered by a FlightRecording: (report, its recording, the buffer's recording)."""
    from fdm_awe.sim.flight import fly

    held = {}

    def setup(ap, sim):
        held["ap"] = ap
        rec.setup(ap, sim)

    def switch(k, state, gs_out):
        if k == k_switch:
            assert held["ap"].set_mode("RECOVER")

    rec = FlightRecording(tmp_path / "buffered.rrd", reference, chain=switch)
    rep = fly(reference, config="foldable", cycles=1, t_end=3.0, on_step=rec, setup=setup)
    buffered = rec.finish()  # from the buffered steps
    return rep, record_flight(rep, reference, tmp_path / "report.rrd"), buffered


def test_mode_lane_shows_the_switch_to_recover(small_circle, tmp_path):
    rep, from_report, from_buffer = _switched_flight(small_circle, tmp_path)
    t_switch = 240 / 120.0
    assert any("mode AUTO -> RECOVER" in str(m) for _, m in rep.autopilot_log)
    for path in (from_report, from_buffer):
        _, t, rows = rrd_values(path, "/plots/mode/autopilot", "Scalars:scalars")
        t, v = np.asarray(t), np.asarray(rows, float).ravel()
        assert set(v) == {MODE_NUMBERS["AUTO"], MODE_NUMBERS["RECOVER"]}, path
        assert np.all(v[t < t_switch - 0.02] == MODE_NUMBERS["AUTO"]), path
        assert np.all(v[t > t_switch + 0.02] == MODE_NUMBERS["RECOVER"]), path
        # the step is drawn where it happened: a sample on each side within two steps of it
        assert np.min(np.abs(t[v == MODE_NUMBERS["RECOVER"]] - t_switch)) < 2.5 / 120.0, path
        assert np.min(np.abs(t[v == MODE_NUMBERS["AUTO"]] - t_switch)) < 2.5 / 120.0, path
        _, _, phase = rrd_values(path, "/plots/mode/phase", "Scalars:scalars")
        assert np.asarray(phase, float).ravel()[-1] == 1.0  # RECOVER flies the recovery phase


def _states(path, entity: str) -> tuple[np.ndarray, list[str]]:
    """Times [s] and names of the state changes of lane ``entity``."""
    _, t, rows = rrd_values(path, entity, "StateChange:state")
    return np.asarray(t, float), [r[0] for r in rows]


def test_the_modes_are_named_where_they_change(small_circle, tmp_path):
    """The switch to RECOVER of the buffered and of the report's recording, by name: the
    autopilot's lane AUTO from the first row, then RECOVER within one scene frame (1/30 s) of
    the switch; the log of mode changes says ``AUTO -> RECOVER`` there as a warning, with the
    phase's change to recovery and the winch's modes by name; the blueprint holds the state
    lanes and the text view of the changes beside the numeric lane."""
    from fdm_awe.recording.blueprint import MODE_LOG, STATE_PANEL
    from fdm_awe.recording.inspect import rrd_view_classes

    rep, from_report, from_buffer = _switched_flight(small_circle, tmp_path)
    t_switch, frame = 240 / 120.0, 1.0 / 30.0
    for path in (from_report, from_buffer):
        t, names = _states(path, "/modes/autopilot")
        assert names == ["AUTO", "RECOVER"] and t[0] == pytest.approx(0.0), (path, names)
        assert abs(t[1] - t_switch) <= frame, (path, t)
        tw, winch = _states(path, "/modes/winch")
        assert set(winch) <= {"generator", "motor"} and winch and all(a != b for a, b in zip(winch, winch[1:])), path
        _, tt, texts = rrd_values(path, "/" + MODE_LOG, "TextLog:text")
        _, _, levels = rrd_values(path, "/" + MODE_LOG, "TextLog:level")
        log = [(float(x), str(m[0]), str(lv[0])) for x, m, lv in zip(tt, texts, levels)]
        assert (0.0, "autopilot AUTO", "INFO") in log, log
        hit = [e for e in log if e[1] == "autopilot AUTO -> RECOVER"]
        assert len(hit) == 1 and abs(hit[0][0] - t_switch) <= frame and hit[0][2] == "WARN", log
        rec = [e for e in log if e[1] == "phase generation -> recovery"]
        assert len(rec) == 1 and abs(rec[0][0] - t_switch) <= frame, log  # RECOVER flies the recovery phase
        assert [e[1].split()[-1] for e in log if e[1].startswith("winch")] == winch, log
        # the numeric lane stays, lined up with the plots, and steps at the same time
        _, tn, rows = rrd_values(path, "/plots/mode/autopilot", "Scalars:scalars")
        tn, v = np.asarray(tn), np.asarray(rows, float).ravel()
        assert np.min(tn[v == MODE_NUMBERS["RECOVER"]]) == pytest.approx(t[1], abs=1e-6), path
        kinds = rrd_view_classes(path)
        assert kinds.get("mode changes") == "TextLog" and kinds.get(STATE_PANEL) == "StateTimeline", kinds
        assert "modes/**" in rrd_views(path)[STATE_PANEL]


def test_a_flight_started_in_recover_records_recover_from_its_first_row(small_circle, tmp_path):
    from fdm_awe.sim.flight import fly

    rep = fly(small_circle, config="foldable", cycles=1, t_end=1.0, setup=lambda ap, sim: ap.set_mode("RECOVER"))
    path = record_flight(rep, small_circle, tmp_path / "recover.rrd")
    _, t, rows = rrd_values(path, "/plots/mode/autopilot", "Scalars:scalars")
    assert t[0] == pytest.approx(0.0) and set(np.asarray(rows, float).ravel()) == {MODE_NUMBERS["RECOVER"]}
    assert rrd_timeline(path, CYCLE_TIMELINE)["/plots/altitude"].values == (0,)  # no cycle begun: cycle 0
