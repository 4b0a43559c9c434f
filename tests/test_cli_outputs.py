"""Outputs of the command line: checked before any work, never an input, written atomically,
JSON without NaN, Ctrl-C keeps what was flown (exit 130).

"Before any work" is observed, not assumed: the functions that do a command's work (flight,
optimisation, sweep, reading the definitions) are replaced by spies that fail the test when
called, and the command must still return 2 quickly, having written nothing.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fdm_awe.cli import main

DATA = Path(__file__).parent / "data"
REF = DATA / "ref_physical_nominal_8mps.json"


def _tree(root: Path) -> set[str]:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def _refused(argv: list[str], capsys, *words: str) -> str:
    """``main(argv)`` returns 2 within 10 s with one error line holding ``words``."""
    t0 = time.monotonic()
    rc = main(argv)
    wall = time.monotonic() - t0
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert wall < 10.0, wall  # the checks take milliseconds; the work would take 10 s or more
    assert "\n" not in err and "error:" in err, err
    for w in words:
        assert w in err, (w, err)
    return err


def _bad_output_cases(tmp: Path) -> list[tuple[list[str], str]]:
    """(argv, option named) for every output option of every command; the bad path is in a
    folder that does not exist, or is an existing folder where a file is needed, or a file
    where a folder is needed."""
    missing = tmp / "no_such_folder" / "out.json"
    folder = tmp / "a_folder"
    folder.mkdir()
    a_file = tmp / "a_file"
    a_file.write_text("x")
    ok_dir = str(tmp / "ok_out")
    ref = str(REF)
    return [
        (["fly", "--reference", ref, "--json", str(missing)], "--json"),
        (["fly", "--reference", ref, "--json", str(folder)], "--json"),
        (["fly", "--reference", ref, "--rrd", str(missing)], "--rrd"),
        (["fly", "--reference", ref, "--out", str(a_file)], "--out"),
        (["fly", "--json", str(missing)], "--json"),  # optimises first: still refused before that
        (["optimize", "--json", str(missing)], "--json"),
        (["optimize", "--trajectory", str(missing)], "--trajectory"),
        (["optimize", "--rrd", str(folder)], "--rrd"),
        (["optimize", "--out", str(a_file)], "--out"),
        (["info", "--json", str(missing)], "--json"),
        (["sweep", "--wind", "8", "--out", str(a_file)], "--out"),
        (["sweep", "--wind", "8", "--out", ok_dir, "--json", str(missing)], "--json"),
        (["compare", "--report", str(missing)], "--report"),
        (["compare", "--json", str(folder)], "--json"),
    ]


def test_bad_output_paths_exit_2_before_any_work(tmp_path, no_work, capsys):
    for argv, option in _bad_output_cases(tmp_path):
        before = _tree(tmp_path)
        _refused(argv, capsys, option)
        assert _tree(tmp_path) == before, argv  # nothing written, no folder created, no temporary file


def test_output_equal_to_an_input_is_refused(tmp_path, no_work, capsys):
    """An output may not overwrite the reference, the parameter file or a definition file,
    nor another option's output."""
    from fdm_awe import ROOT

    ref = tmp_path / "ref.json"
    shutil.copy(REF, ref)
    content = ref.read_bytes()
    params = tmp_path / "params.json"
    for argv, option in [
        (["fly", "--reference", str(ref), "--json", str(ref)], "--json"),
        (["fly", "--reference", str(ref), "--rrd", str(ref)], "--rrd"),
        (["fly", "--reference", str(ref), "--params", str(params), "--json", str(params)], "--json"),
    ]:
        _refused(argv, capsys, option, "input")
        assert ref.read_bytes() == content
    # a definition file is an input of every run
    defn = ROOT / "aircraft" / "glider_foldable" / "glider_foldable.xml"
    before = defn.read_bytes()
    _refused(["info", "--json", str(defn)], capsys, "--json", "input")
    _refused(["optimize", "--trajectory", str(defn)], capsys, "--trajectory", "input")
    assert defn.read_bytes() == before
    # two options, one file
    _refused(["fly", "--reference", str(ref), "--json", str(tmp_path / "x"), "--rrd", str(tmp_path / "x")], capsys,
             "--rrd", "--json")
    # a file --out would write is another option's output
    _refused(["fly", "--reference", str(ref), "--out", str(tmp_path / "run"), "--json",
              str(tmp_path / "run" / "flight.csv")], capsys, "flight.csv")
    assert set(os.listdir(tmp_path)) == {"ref.json"}


def _short_flights(monkeypatch, t_end: float = 3.0, mode: str | None = None) -> list[dict]:
    """``fdm_awe.sim.flight.fly`` flies ``t_end`` seconds (optionally starting in ``mode``); returns
    the list the keyword arguments of each call are appended to."""
    import fdm_awe.sim.flight as flight

    calls: list[dict] = []
    real = flight.fly

    def short(*a, **kw):
        calls.append(kw)
        if mode is not None:
            inner = kw.get("setup")

            def setup(ap, sim):
                if inner is not None:
                    inner(ap, sim)
                ap.set_mode(mode)

            kw = {**kw, "setup": setup}
        return real(*a, **{**kw, "t_end": t_end})

    monkeypatch.setattr(flight, "fly", short)
    return calls


def test_fly_json_of_a_flight_ended_by_an_event_has_null_for_nan(tmp_path, monkeypatch, capsys):
    """MANUAL with the elevator at full deflection from the reference's start ends in an event
    within seconds (exit 1). Numbers the report cannot compute are NaN in
    Python (injected here into the real report: the ledger residual and one ledger term); the
    JSON is strict JSON with null for them."""
    import fdm_awe.sim.flight as flight
    from fdm_awe.sixdof.state import Surfaces

    real = flight.fly

    def event_flight(*a, **kw):
        cli_setup = kw["setup"]

        def setup(ap, sim):
            cli_setup(ap, sim)
            ap.set_mode("MANUAL")
            ap.manual = Surfaces(0.0, -1.0, 0.0, 0.0, 0.0)

        rep = real(*a, **{**kw, "t_end": 30.0, "setup": setup})
        rep.ledger_residual_rel = math.nan
        rep.ledger["glider_residual_J"] = math.inf
        return rep

    monkeypatch.setattr(flight, "fly", event_flight)
    out = tmp_path / "run.json"
    rc = main(["fly", "--reference", str(REF), "--mode", "RECOVER", "--quiet", "--json", str(out)])
    text = out.read_text()
    doc = json.loads(text, parse_constant=lambda c: pytest.fail(f"JSON holds {c}"))
    assert rc == 1 and doc["status"] not in ("ok", "landed")  # an event ended it
    assert doc["ledger_residual_rel"] is None and doc["ledger"]["glider_residual_J"] is None
    assert "NaN" not in text and "Infinity" not in text
    assert doc["turbulence"] is None


def test_fly_records_the_turbulence_level_and_seed(tmp_path, monkeypatch):
    from fdm_awe.turbulence import Turbulence

    calls = _short_flights(monkeypatch)
    out = tmp_path / "run.json"
    assert main(["fly", "--reference", str(REF), "--turbulence", "light:2147483647", "--quiet", "--json", str(out)]) == 0
    assert calls[-1]["turbulence"] == Turbulence("level", "light", 2147483647)
    doc = json.loads(out.read_text())["turbulence"]
    assert (doc["form"], doc["level"], doc["seed"]) == ("level", "light", 2147483647)
    assert doc["w20_mps"] == pytest.approx(15.0 * 1852.0 / 3600.0) and doc["severity_index"] == 3
    assert main(["fly", "--reference", str(REF), "--turbulence", "moderate", "--quiet", "--json", str(out)]) == 0
    assert calls[-1]["turbulence"] == Turbulence("level", "moderate", 1)
    doc = json.loads(out.read_text())["turbulence"]
    assert (doc["level"], doc["seed"], doc["w20_mps"]) == ("moderate", 1, pytest.approx(30.0 * 1852.0 / 3600.0))


def test_fly_records_the_iec_target_and_the_turbulence_met(tmp_path, monkeypatch, capsys):
    """``iec:A``: the hub is the reference's mean height, the target IEC's sigma_1 there; the
    measured turbulence comes from the wind the glider met over the (3 s) flight."""
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.turbulence import mean_height

    _short_flights(monkeypatch)
    out = tmp_path / "run.json"
    assert main(["fly", "--reference", str(REF), "--turbulence", "iec:A:3", "--quiet", "--json", str(out)]) == 0
    doc = json.loads(out.read_text())["turbulence"]
    ref = TrackingReference.from_ocp_file(REF)
    hub = mean_height(ref.t, -ref.pos[:, 2])
    assert (doc["form"], doc["iec_class"], doc["i_ref"], doc["seed"]) == ("iec", "A", 0.16, 3)
    assert doc["hub_height_m"] == pytest.approx(hub, rel=0.02) and 40.0 < hub < 200.0
    assert doc["wind_hub_mps"] == pytest.approx(8.0)  # uniform wind
    sigma_1 = 0.16 * (0.75 * 8.0 + 5.6)
    assert doc["target"]["sigma_u_mps"] == pytest.approx(sigma_1, rel=1e-5)
    assert doc["target"]["intensity"] == pytest.approx(sigma_1 / 8.0, rel=1e-5)
    m = doc["measured"]
    assert m["duration_s"] == pytest.approx(3.0, abs=0.02) and m["mean_wind_mps"] == pytest.approx(8.0)
    assert 0.0 < m["sigma_u_mps"] < 3.0 * sigma_1 and 0.0 < m["sigma_w_mps"] < 3.0 * sigma_1
    assert m["intensity"] == pytest.approx(m["sigma_u_mps"] / 8.0, abs=2e-6)  # 6 decimals in the JSON
    line = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("turbulence iec:A:3: ")]
    assert len(line) == 1 and "target sigma_u 1.86 m/s at " in line[0] and "intensity 0.232" in line[0]


def test_writers_leave_no_partial_file_when_they_raise(tmp_path, monkeypatch):
    """CSV, PNG, markdown, rrd and JSON writers: an exception while writing leaves the target as
    it was (absent, or its old content) and no temporary file."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from fdm_awe.fileio import write_json
    from fdm_awe.recording import csvexport, plots
    from fdm_awe.recording import flight as recflight
    from fdm_awe.recording.csvexport import write_series_csv
    from fdm_awe.recording.series import Series

    # CSV: the phase column is one label short, so the writer raises on the last row
    n = 5000
    s = Series(np.arange(n) * 0.01, {"x": ("m", np.arange(n, dtype=float))}, ["generation"] * (n - 1))
    with pytest.raises(IndexError):
        write_series_csv(s, tmp_path / "t.csv")
    assert os.listdir(tmp_path) == []
    # an existing file keeps its content
    (tmp_path / "t.csv").write_text("old\n")
    with pytest.raises(IndexError):
        csvexport.write_series_csv(s, tmp_path / "t.csv")
    assert (tmp_path / "t.csv").read_text() == "old\n" and os.listdir(tmp_path) == ["t.csv"]
    (tmp_path / "t.csv").unlink()

    # PNG: the figure is written in full, then the writer raises (as Ctrl-C would)
    fig = plt.figure()
    real_savefig = fig.savefig

    def savefig_then_raise(path, **kw):
        real_savefig(path, **kw)
        assert Path(path).stat().st_size > 0 and Path(path).name != "p.png"  # written under a temporary name
        raise KeyboardInterrupt

    fig.savefig = savefig_then_raise
    with pytest.raises(KeyboardInterrupt):
        plots._save(fig, tmp_path / "p.png")
    assert os.listdir(tmp_path) == []

    # rrd: record_flight raising half-way leaves no recording
    def boom(*a, **kw):
        raise KeyboardInterrupt

    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.sim.flight import fly

    rep = fly(TrackingReference.from_ocp_file(str(REF)), config="nominal", cycles=1, t_end=1.0)
    monkeypatch.setattr(recflight, "_log_events", boom)
    with pytest.raises(KeyboardInterrupt):
        recflight.record_flight(rep, None, tmp_path / "f.rrd")
    assert os.listdir(tmp_path) == []

    # JSON: a value that cannot be written raises before the target is touched
    (tmp_path / "d.json").write_text("{}\n")
    with pytest.raises(TypeError):
        write_json(tmp_path / "d.json", {"a": object()})
    assert (tmp_path / "d.json").read_text() == "{}\n" and os.listdir(tmp_path) == ["d.json"]


def test_fly_ctrl_c_while_writing_outputs_keeps_the_finished_files(tmp_path, monkeypatch, capsys):
    """Ctrl-C while the outputs are written (here: in the plots): the recording written before
    stays, nothing is truncated, the JSON lists what exists, exit 130."""
    import fdm_awe.recording.plots as plots

    _short_flights(monkeypatch)

    def interrupted(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(plots, "plot_flight", interrupted)
    out = tmp_path / "run.json"
    rc = main(["fly", "--reference", str(REF), "--quiet", "--out", str(tmp_path / "run"), "--json", str(out)])
    assert rc == 130
    doc = json.loads(out.read_text())
    assert doc["outputs_cut_short"] is True and doc["status"] == "ok"
    assert Path(doc["rrd"]).stat().st_size > 0 and "plots" not in doc and "csv" not in doc
    assert sorted(os.listdir(tmp_path / "run")) == ["flight.rrd"]
    assert "interrupted" in capsys.readouterr().err


@pytest.mark.timeout(120)
def test_fly_ctrl_c_writes_the_flight_so_far_and_exits_130(tmp_path):
    """SIGINT to a running ``fdm-awe fly`` (3 cycles paced at 30x real time, so the flight
    lasts at least 6 s on any machine): the JSON and the CSV of the steps flown are written,
    status interrupted, fewer than the 180 s of 3 cycles simulated, exit 130, no traceback."""
    out, run = tmp_path / "J.json", tmp_path / "run"
    env = dict(os.environ, JSBSIM_DEBUG="0", MPLBACKEND="Agg")
    p = subprocess.Popen([sys.executable, "-m", "fdm_awe", "fly", "--reference", str(REF), "--cycles", "3",
                          "--realtime", "30", "--quiet", "--json", str(out), "--out", str(run)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
    try:
        # the flight's loop starts right after this line (JSBSim and the autopilot are set up)
        head = []
        while not head or ("flying:" not in head[-1] and head[-1]):
            head.append(p.stderr.readline())
        assert "flying:" in head[-1], head
        time.sleep(2.0)
        p.send_signal(signal.SIGINT)
        stdout, stderr = p.communicate(timeout=90)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == 130, stderr
    assert "Traceback" not in stderr
    doc = json.loads(out.read_text())
    assert doc["status"] == "interrupted"
    assert 0.0 < doc["sim_time_s"] < 180.0
    assert doc["cycles"] and doc["cycles"][-1]["complete"] is False
    csv_rows = (run / "flight.csv").read_text().splitlines()
    assert len(csv_rows) > 1 and csv_rows[0].startswith("t_s,")
    last_t = float(csv_rows[-1].split(",")[0])
    assert last_t == pytest.approx(doc["sim_time_s"], abs=0.02)  # the CSV holds every step flown
    assert "status interrupted" in stdout
    assert not [f for f in os.listdir(run) if f.startswith(".")]  # no temporary file left


@pytest.mark.timeout(240)
def test_fly_without_options_flies_and_leaves_nothing_behind(tmp_path, monkeypatch):
    """``fdm-awe fly`` with the defaults (one cycle here: physical nominal 8 m/s, optimised
    first) completes with status ok; the optimised reference is flown from memory, so the
    working folder holds only the JSON asked for."""
    monkeypatch.chdir(tmp_path)
    rc = main(["fly", "--cycles", "1", "--quiet", "--json", "run.json"])
    doc = json.loads((tmp_path / "run.json").read_text())
    assert rc == 0 and doc["status"] == "ok", doc["message"]
    assert (doc["scenario"], doc["config"], doc["wind_mps"]) == ("physical", "nominal", 8.0)
    assert doc["reference"] is None and doc["cycles"][0]["complete"]
    assert os.listdir(tmp_path) == ["run.json"]
