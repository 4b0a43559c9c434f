"""``sweep --fly`` end to end: a short sweep (nominal, 10 and 12 m/s, mesh 20/12/3, flyable
bounds) whose points are flown in 6-DOF (light turbulence, 2 seeds, 1 cycle each: 4 flights)
on Dask; killed with SIGKILL after its first stored flight, resumed (only the missing flights
are flown), and compared with the same sweep on one worker (identical flown numbers: a flight
is deterministic given its point, air and seed). The reconstructed reference of a point is its
optimised cycle exactly."""

from __future__ import annotations

import contextlib
import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ARGS = ["sweep", "--wind", "10,12", "--config", "nominal", "--mesh", "20,12,3", "--no-cold-check", "--fly",
        "--fly-seeds", "2", "--fly-cycles", "1", "--no-progress", "--yield", "rayleigh:7"]


def _env() -> dict:
    env = dict(os.environ, JSBSIM_DEBUG="0", MPLBACKEND="Agg")
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _cli(out: Path, *extra: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fdm_awe", *ARGS, "--out", str(out), *extra], env=_env(), cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)


def _records(out: Path) -> list[Path]:
    """The stored flight records of a sweep folder (not the hidden temporary file of a write in
    progress, ``.<name>.<pid>@<host>.<random>.part.json``)."""
    d = out / "flights"
    return [p for p in d.glob("*.json") if not p.name.startswith(".")] if d.is_dir() else []


def _flown(out: Path) -> dict:
    """Flight id -> the flown numbers (everything but the wall time and the worker)."""
    res = {}
    for p in _records(out):
        r = json.loads(p.read_text())
        res[r["id"]] = {k: v for k, v in r.items() if k not in ("wall_s", "worker")}
    return res


@pytest.mark.timeout(600)
def test_fly_killed_resumes_only_missing_flights_and_one_worker_matches(tmp_path):
    a = tmp_path / "a"
    proc = subprocess.Popen([sys.executable, "-m", "fdm_awe", *ARGS, "--out", str(a), "--workers", "2"], env=_env(),
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    import psutil

    family: list = []
    try:
        t_end = time.monotonic() + 300
        while time.monotonic() < t_end and proc.poll() is None:
            with contextlib.suppress(psutil.Error):  # the Dask scheduler, nanny and worker processes
                family = psutil.Process(proc.pid).children(recursive=True) or family
            if _records(a):
                break
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)  # the command and its Dask processes
        for child in family:  # and any that left the process group
            with contextlib.suppress(psutil.Error):
                child.kill()
        proc.wait(timeout=30)
    # count once every process of the killed run is gone (a dying worker writes nothing more)
    gone, alive = psutil.wait_procs(family, timeout=30)
    assert not alive, f"processes of the killed run still alive: {alive}"
    kept = {p.name: p.stat().st_mtime_ns for p in _records(a)}
    assert 1 <= len(kept) < 4, "the kill came after the first stored flight and before the last"
    # a write cut by the kill leaves at most its hidden temporary file, never a partial record
    assert all(p.name.startswith(".") and ".part" in p.name for p in (a / "flights").iterdir() if p.name not in kept)

    # the temporary file of a write the kill cut short (the killed command's own, surely dead, pid)
    from fdm_awe.fileio import _host

    cut = a / "flights" / f".f-cut.json.{proc.pid}@{_host()}.x1y2z3.part.json"
    cut.write_text('{"id": "f-cut", "cyc')

    r = _cli(a, "--workers", "2")
    assert r.returncode == 0, r.stdout + r.stderr
    # the points were finished before the kill; only the missing flights are flown now
    assert "2 already done, 0 computed now" in r.stdout
    assert f"flights: 4 total, {len(kept)} already done, {4 - len(kept)} flown now" in r.stdout
    assert {p.name: p.stat().st_mtime_ns for p in _records(a) if p.name in kept} == kept
    assert not [p for p in (a / "flights").iterdir() if p.name.startswith(".")]  # the cut write is cleared
    # a third run flies nothing
    r3 = _cli(a, "--workers", "1")
    assert r3.returncode == 0 and "flights: 4 total, 4 already done, 0 flown now" in r3.stdout

    b = tmp_path / "b"
    rb = _cli(b, "--workers", "1")
    assert rb.returncode == 0, rb.stdout + rb.stderr
    fa, fb = _flown(a), _flown(b)
    assert len(fa) == 4 and fa == fb  # bit-identical numbers with one and two workers, after a kill or not
    assert {r["seed"] for r in fa.values()} == {1, 2} and {r["wind_mps"] for r in fa.values()} == {10.0, 12.0}
    # every flight ran (a flight status of the simulator, not an exception) and the ratings are recorded
    for r in fa.values():
        assert r["status"] != "error" and r["rated_tension_N"] == 50.0 and r["rated_current_A"] > 0
        for c in r["cycle_list"]:
            if c["complete"]:
                assert c["P_W"] == pytest.approx(c["E_net_J"] / c["T_s"], rel=1e-12) and 5.0 < c["T_s"] < 120.0

    # the report: the CSV with units in its columns, one row per point, the flown stats within their bounds
    rows = list(csv.DictReader((a / "power_curve.csv").open()))
    assert [float(x["wind_mps"]) for x in rows] == [10.0, 12.0]
    for x in rows:
        assert x["P_opt_W"] and x["P_loyd_W"] and x["P_quasi_steady_W"]
        n = int(x["cycles_complete"])
        assert int(x["cycles_asked"]) == 2 and 0 <= n <= 2 and float(x["completion"]) == n / 2
        if n:
            assert float(x["P_flown_min_W"]) <= float(x["P_flown_mean_W"]) <= float(x["P_flown_max_W"])
            assert float(x["peak_tension_N"]) > 0 and float(x["track_rms_m"]) >= 0
    assert (a / "power_curve_flown.png").stat().st_size > 10_000
    md = (a / "power_curve.md").read_text()
    assert "## Cut-in and rated wind" in md and "## Energy yield" in md and "Rayleigh 7 m/s" in md
    ys = list(csv.DictReader((a / "yield.csv").open()))
    assert {y["source"] for y in ys} <= {"optimised", "flown"} and "optimised" in {y["source"] for y in ys}
    for y in ys:  # the default clip: never negative
        assert float(y["mean_power_W"]) >= 0 and float(y["aep_kWh_per_yr"]) == pytest.approx(
            float(y["mean_power_W"]) * 8.766, rel=1e-9)
    # --report-only with another site: nothing flown or solved, the yield from the stored curve
    rr = _cli(a, "--report-only", "--yield", "weibull:2:9")
    assert rr.returncode == 0 and "flown now" not in rr.stdout and "Weibull k=2 c=9 m/s" in rr.stdout


def test_rebuilt_reference_is_the_optimised_cycle(tmp_path):
    """The flown reference rebuilt from a stored solution has the optimised energies exactly."""
    from fdm_awe.sweep.flown import point_result
    from fdm_awe.sweep.runner import run_point
    from fdm_awe.sweep.spec import Point

    p = Point("physical", "nominal", 10.0, 200.0, 250.0, mesh=(6, 4, 3), line="sized", line_weight=True,
              propeller="engine", bounds="flyable", tension_margin=0.25, stall_margin=0.15)
    rec, warm = run_point(p)
    assert rec["status"] == "ok" and rec["bounds"] == "flyable"
    res = point_result(p, warm)
    assert res.ok and res.P_avg_W == rec["P_avg_W"] and res.T1_s == rec["T1_s"] and res.T2_s == rec["T2_s"]
    assert res.problem.bounds.cl_margin == 0.85 and res.problem.bounds.phi_max == 0.8
    assert res.problem.bounds.tension_margin == 0.25


def test_flyable_points_have_the_bounds_fly_optimises_with():
    from fdm_awe.commands._fly_optimise import flyable_bounds
    from fdm_awe.sweep import runner

    from fdm_awe.commands._fly_optimise import FLY_STALL_MARGIN, FLY_TENSION_MARGIN

    assert runner.flyable_bounds() == flyable_bounds()
    assert (runner.FLYABLE_TENSION_MARGIN, runner.FLYABLE_STALL_MARGIN) == (FLY_TENSION_MARGIN, FLY_STALL_MARGIN)
