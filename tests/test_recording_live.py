"""A flight streamed live to a viewer (``fdm-awe fly --connect [ADDR]`` / ``--spawn``).

The viewer stand-in is rerun's own gRPC server (``rerun --port P --save FILE``, the CLI of
the rerun-sdk package): it listens where a viewer listens and writes what arrives to FILE,
which the test reads back. The flight is the 3 s circle of test_recording.py, 2 s of it.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest
from test_cli_outputs import REF, _refused
from test_recording import circle  # noqa: F401 - fixture

from fdm_awe.cli import main
from fdm_awe.recording import flight_forces, rrd_entities, rrd_values
from fdm_awe.recording.inspect import rerun_cli, rrd_timeline


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def viewer(tmp_path):
    """A local gRPC server saving what it receives: ``(port, stop)``; ``stop(last)`` waits until
    the entity ``last`` (the last one sent) is in the file (the server writes what it received
    some time after the sender is done), ends the server (Ctrl-C) and returns the file's path."""
    port = _free_port()
    out = tmp_path / "received.rrd"
    proc = subprocess.Popen([rerun_cli(), "--port", str(port), "--save", str(out)], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=dict(os.environ, RUST_LOG="warn"), start_new_session=True)
    try:
        deadline = time.monotonic() + 60.0
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1.0).close()
                break
            except OSError:
                assert proc.poll() is None and time.monotonic() < deadline, "the rerun server did not start"
                time.sleep(0.1)

        def stop(last: str):
            until = time.monotonic() + 60.0
            while time.monotonic() < until:
                try:
                    if last in rrd_entities(out):
                        break
                except Exception:  # noqa: BLE001 - not written yet, or half a message
                    pass
                time.sleep(0.2)
            os.killpg(proc.pid, signal.SIGINT)  # the CLI wrapper and the server it runs
            proc.wait(timeout=60)
            return out

        yield port, stop
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def test_live_flight_streams_what_the_file_holds(circle, viewer):  # noqa: F811
    from fdm_awe.recording import LiveFlight
    from fdm_awe.recording.series import flight_series
    from fdm_awe.sim.flight import fly

    port, stop = viewer
    # flush_s 0: a slice after every step, whatever the machine's speed (the slices' seams everywhere)
    live = LiveFlight.open(circle, url=f"rerun+http://127.0.0.1:{port}/proxy", flush_s=0.0)
    flushes = []
    real_flush = live.flush
    live.flush = lambda final=False: (flushes.append(final), real_flush(final))[1]
    rep = fly(circle, config="foldable", cycles=1, t_end=2.0, on_step=live, setup=live.setup)
    live.finish(rep)
    saved = stop("/report")  # the report goes last
    assert len(flushes) == len(rep.result.t) and flushes[-1] is True  # one a step, the rest at the end

    ent = rrd_entities(saved)
    n = len(rep.result.t)
    assert ent["/plots/altitude"].rows == n and ent["/plots/tension"].rows == n - 1  # every row, once
    for e in ("/world/glider", "/world/forces/lift", "/world/tether", "/plots/forces/drag"):
        assert ent[e].t_max == pytest.approx(rep.sim_time_s, abs=1e-6), e
    for e in ("/world/glider/airframe/body", "/world/glider/airframe/wing", "/world/forces/thrust", "/world/flown/generation",
              "/plots/attitude/roll", "/plots/flow/alpha", "/plots/surfaces/elevator", "/phase", "/report"):
        assert e in ent, e
    # the values are the flight's, the energies continued from slice to slice
    s = flight_series(rep)
    for entity, key in (("/plots/altitude", "altitude"), ("/plots/energy/net", "E_net"), ("/plots/flow/alpha", "alpha")):
        _, times, rows = rrd_values(saved, entity, "Scalars:scalars")
        np.testing.assert_allclose(np.asarray(rows, float).ravel(), s[key], rtol=1e-9, atol=1e-9, err_msg=key)
    f = flight_forces(rep)
    _, times, rows = rrd_values(saved, "/plots/forces/lift", "Scalars:scalars")
    np.testing.assert_allclose(np.asarray(rows, float).ravel(), f.L[1:], rtol=1e-9)
    _, _, texts = rrd_values(saved, "/events", "TextLog:text")
    assert texts[-1][0].startswith("end: ok")
    # the cycle on every row; the mode lane; the path so far sent while flying, then the whole path
    for entity, info in rrd_timeline(saved, "cycle").items():
        assert info.on_timeline == info.rows > 0 and info.values == (0,), entity
    _, _, modes = rrd_values(saved, "/plots/mode/autopilot", "Scalars:scalars")
    assert set(np.asarray(modes, float).ravel()) == {10.0}  # AUTO
    # the modes by name, streamed slice by slice: the same changes as the file of the flight
    from fdm_awe.recording import record_flight

    whole = record_flight(rep, circle, saved.with_name("whole.rrd"))
    for entity, component in (("/modes/autopilot", "StateChange:state"), ("/modes/winch", "StateChange:state"),
                              ("/mode_changes", "TextLog:text")):
        live_rows, file_rows = ([(round(t, 6), r) for t, r in zip(*rrd_values(f, entity, component)[1:])]
                                for f in (saved, whole))
        assert sorted(live_rows) == sorted(file_rows) and live_rows, (entity, live_rows, file_rows)
    assert (0.0, ["autopilot AUTO"]) in live_rows
    _, times, strips = rrd_values(saved, "/world/flown/live", "LineStrips3D:strips")
    counts = [sum(len(p) for p in row) for row in strips]
    assert times[:2] == pytest.approx([0.0, 1.0], abs=0.01) and counts[1] > counts[0]
    assert ent["/world/flown/generation"].t_min == pytest.approx(rep.sim_time_s, abs=1e-6)


def _short_flight(monkeypatch, t_end: float = 2.0) -> None:
    """``fdm_awe.sim.flight.fly`` flies ``t_end`` seconds."""
    import fdm_awe.sim.flight as flight

    real = flight.fly
    monkeypatch.setattr(flight, "fly", lambda *a, **kw: real(*a, **{**kw, "t_end": t_end}))


def test_fly_connect_streams_to_a_running_viewer(viewer, monkeypatch, tmp_path):
    port, stop = viewer
    _short_flight(monkeypatch)
    out = tmp_path / "run.json"
    assert main(["fly", "--reference", str(REF), "--quiet", "--connect", str(port), "--json", str(out)]) == 0
    saved = stop("/report")
    ent = rrd_entities(saved)
    assert {"/world/glider/airframe/body", "/world/forces/tether", "/plots/tension", "/events"} <= set(ent)
    assert ent["/world/glider"].t_max == pytest.approx(2.0, abs=1e-6)
    assert out.exists()  # the command's own outputs as without the live view


def test_live_options_are_refused_before_any_work(no_work, capsys, monkeypatch, tmp_path):
    ref = str(REF)
    _refused(["fly", "--reference", ref, "--connect", "http://127.0.0.1:9876/proxy"], capsys, "--connect",
             "not a rerun viewer address")
    _refused(["fly", "--reference", ref, "--connect", "rerun+http://127.0.0.1:9876/elsewhere"], capsys, "--connect")
    _refused(["fly", "--reference", ref, "--connect", str(_free_port())], capsys, "--connect", "no viewer listens")
    assert main(["fly", "--reference", ref, "--spawn", "--connect"]) == 2  # one or the other
    assert "not allowed with" in capsys.readouterr().err
    import fdm_awe.recording.inspect as inspect

    def missing():
        raise FileNotFoundError("no rerun")

    monkeypatch.setattr(inspect, "rerun_cli", missing)
    _refused(["fly", "--reference", ref, "--spawn"], capsys, "--spawn", "viewer program was not found")
    monkeypatch.undo()
    if sys.platform.startswith("linux"):
        monkeypatch.delenv("DISPLAY", raising=False)
        monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
        _refused(["fly", "--reference", ref, "--spawn"], capsys, "--spawn", "no display")
    assert os.listdir(tmp_path) == []


def test_spawn_runs_rerun_viewer_program_and_streams_to_it(viewer, monkeypatch):
    """--spawn starts rerun's viewer program on rerun's default port and streams to it; the
    start is replaced here by a connection to the test's server (no display to open a window)."""
    import rerun as rr

    from fdm_awe.recording.blueprint import flight_blueprint
    from fdm_awe.recording.stream import DEFAULT_PORT, ViewerSink

    port, stop = viewer
    calls = []

    def spawn(**kw):
        calls.append(kw)
        kw["recording"].connect_grpc(f"rerun+http://127.0.0.1:{port}/proxy", default_blueprint=kw["default_blueprint"])

    monkeypatch.setattr(rr, "spawn", spawn)
    sink = ViewerSink(spawn=True, blueprint=flight_blueprint("spawned"), name="spawned")
    sink.static("world/winch", rr.Points3D([[0.0, 0.0, 0.0]]))
    assert sink.close()
    (kw,) = calls
    assert kw["executable_path"] == rerun_cli() and kw["port"] == DEFAULT_PORT and kw["connect"] is True
    assert "/world/winch" in rrd_entities(stop("/world/winch"))
