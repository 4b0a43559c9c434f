"""The Python API (fdm_awe.api on the package's top level): the commands' numbers, the example
references, lazy imports; and the outputs the commands share with it (fly's table, the files
written, ``info --export``)."""

from __future__ import annotations

import contextlib
import io
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fdm_awe
from fdm_awe.cli import main
from fdm_awe.errors import InputError
from fdm_awe.example_refs import EXAMPLES, examples_folder

REPO = Path(__file__).resolve().parent.parent
#: a quick cycle: the paper scenario's nominal glider at 3 m/s on a coarse mesh (as the wheel check)
QUICK = dict(scenario="paper", config="nominal", wind=3.0, mesh="10,8,3", time_budget=60.0)
QUICK_ARGS = ["--scenario", "paper", "--config", "nominal", "--wind", "3", "--mesh", "10,8,3", "--time-budget", "60"]


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def test_import_fdm_awe_stays_light():
    code = ("import sys, fdm_awe; heavy = [m for m in ('numpy', 'casadi', 'jsbsim', 'numba', 'fdm_awe.api') "
            "if m in sys.modules]; print(heavy, callable(fdm_awe.sweep), fdm_awe.sweep.__name__)")
    proc = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["[]", "True", "fdm_awe.sweep"]
    for name in ("optimize", "fly", "sweep", "load_reference", "OptimizeResult", "FlightResult", "SweepResult"):
        assert name in fdm_awe.__all__ and callable(getattr(fdm_awe, name))


def test_sweep_stays_callable_after_its_modules_are_imported():
    import fdm_awe.sweep.spec  # noqa: F401  (the sub-package's modules)

    assert callable(fdm_awe.sweep) and fdm_awe.sweep.spec.__name__ == "fdm_awe.sweep.spec"


def test_every_example_is_a_stored_reference_and_loads():
    assert examples_folder() == REPO / "tests" / "data"
    for name, file in EXAMPLES.items():
        ref = fdm_awe.load_reference(f"example:{name}")
        cfg = name.split("-")[-2]
        assert ref.metadata["config"] == cfg and ref.metadata["wind_mps"] == float(name.split("-")[-1])
        assert ref.metadata["scenario"] == ("paper" if name.startswith("paper") else "physical")
        assert Path(ref.source).name == file
    with pytest.raises(InputError, match=r"load_reference example:nominal-9: no such example \(allowed .*nominal-8"):
        fdm_awe.load_reference("example:nominal-9")


def test_fly_refuses_an_unknown_example_in_one_line_before_any_work():
    code, out, err = _run(["fly", "--reference", "example:glider", "--cycles", "1"])
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "--reference example:glider: no such example" in err and "foldable-8" in err


@pytest.fixture(scope="module")
def quick_cycle():
    return fdm_awe.optimize(**QUICK)


@pytest.mark.timeout(240)
def test_optimize_gives_the_numbers_of_the_command(quick_cycle, tmp_path):
    assert quick_cycle.ok
    code, out, _ = _run(["optimize", *QUICK_ARGS, "--json", str(tmp_path / "opt.json")])
    assert code == 0
    cli = json.loads((tmp_path / "opt.json").read_text())
    api = json.loads(quick_cycle.to_json())
    for key in ("status", "scenario", "config", "wind_mps", "T1_s", "T2_s", "E_generated_J", "E_thrust_J",
                "E_reel_in_J", "E_net_J", "P_avg_W"):
        assert api[key] == cli[key], key
    assert quick_cycle.E_net_J == cli["E_net_J"]
    wrote = next(line for line in out.splitlines() if line.startswith("wrote: "))[7:].split(", ")
    assert wrote == [str(tmp_path / "opt.trajectory.json"), str(tmp_path / "opt.json")]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["opt.json", "opt.trajectory.json"]
    # E_net = E_generated - E_thrust - E_reel_in, each term >= 0
    assert min(api["E_generated_J"], api["E_thrust_J"], api["E_reel_in_J"]) >= 0
    assert api["E_net_J"] == pytest.approx(api["E_generated_J"] - api["E_thrust_J"] - api["E_reel_in_J"], abs=1e-6)
    a = quick_cycle.arrays()
    assert list(a)[0] == "t_s" and "x_m" in a and "phase" in a
    assert all(re.search(r"_[A-Za-z0-9]+$", k) for k in a if k != "phase")  # the unit in every name
    assert np.all(np.diff(a["t_s"]) >= 0) and a["t_s"][-1] == pytest.approx(api["T1_s"] + api["T2_s"], rel=1e-6)


@pytest.mark.timeout(120)
def test_tracking_reference_from_an_optimiser_result(quick_cycle):
    """The documented route: ``TrackingReference.from_ocp(result)`` (raised on a CycleResult before)."""
    from fdm_awe.autopilot.tracking import TrackingReference

    ref = TrackingReference.from_ocp(quick_cycle.result)
    same = TrackingReference.from_ocp(quick_cycle.reference())
    assert ref.period == pytest.approx(quick_cycle.T1_s + quick_cycle.T2_s, rel=1e-9)
    assert ref.meta["config"] == "nominal" and ref.meta["energies"]["E_net_J"] == pytest.approx(quick_cycle.E_net_J)
    assert ref.period == same.period


def test_to_dataframe_without_pandas_says_what_it_needs(quick_cycle):
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match=r"needs pandas.*arrays\(\)"):
            quick_cycle.to_dataframe()
    else:
        df = quick_cycle.to_dataframe()
        assert list(df.columns) == list(quick_cycle.arrays())


def test_bad_keywords_are_one_line_errors_before_any_work():
    with pytest.raises(InputError, match=r"--wind 30.*0\.\.25"):
        fdm_awe.optimize(wind=30.0)
    with pytest.raises(InputError, match=r"--cycles 0.*1\.\.1000"):
        fdm_awe.fly("example:nominal-8", cycles=0)
    with pytest.raises(InputError, match="--wind: the reference"):
        fdm_awe.fly("example:nominal-8", wind=10.0)
    ref = fdm_awe.load_reference("example:nominal-8")  # a reference in memory: the same checks as a file's
    with pytest.raises(InputError, match="--wind: the reference given fixes this"):
        fdm_awe.fly(ref, wind=10.0)
    with pytest.raises(InputError, match="--config foldable: the reference given was optimised for the configuration"):
        fdm_awe.fly(ref, config="foldable")
    with pytest.raises(TypeError, match="unexpected keyword argument 'winds'"):
        fdm_awe.sweep("x", winds="8")


@pytest.mark.timeout(240)
def test_fly_gives_the_numbers_and_outputs_of_the_command(tmp_path):
    flight = fdm_awe.fly("example:nominal-8", cycles=1)
    out_dir = tmp_path / "out"
    code, out, _ = _run(["fly", "--reference", "example:nominal-8", "--cycles", "1", "--quiet", "--out",
                         str(out_dir), "--json", str(tmp_path / "fly.json")])
    assert code == flight.exit_code == 0 and flight.status == "ok"
    cli = json.loads((tmp_path / "fly.json").read_text())
    assert flight.cycles == cli["cycles"]  # a flight is deterministic: the same numbers
    assert flight.document["optimised"] == cli["optimised"]
    # the optimised energy beside the flown one, in the table and the JSON
    opt = cli["optimised"]["E_net_J"]
    assert opt == pytest.approx(fdm_awe.load_reference("example:nominal-8").metadata["energies"]["E_net_J"])
    header = next(line for line in out.splitlines() if line.lstrip().startswith("cycle"))
    assert "opt net J" in header and "net J" in header
    row = next(line.split() for line in out.splitlines() if re.match(r"\s+0\s+\d", line))
    assert row[0] == "0" and float(row[7]) == pytest.approx(opt, abs=0.05)
    assert float(row[6]) == pytest.approx(cli["cycles"][0]["E_net_J"], abs=0.05)
    # cycles from 0 in the table, the JSON and flight.md
    assert cli["cycles"][0]["index"] == 0
    md = (out_dir / "flight.md").read_text()
    assert re.search(r"^\| 0 \|", md, re.M) and not re.search(r"^\| 1 \|", md, re.M)
    # the real-time factor printed as measured (two digits below 10)
    rtf = float(re.search(r"\(([0-9.e+]+)x real time, measured\)", out).group(1))
    assert rtf == pytest.approx(cli["realtime_factor"], rel=0.06, abs=0.06)
    # --out lists every file it wrote
    listed = next(line for line in out.splitlines() if line.startswith("wrote: "))[7:].split(", ")
    assert set(listed) == {str(p) for p in out_dir.iterdir() if not p.name.startswith(".")} | {str(tmp_path / "fly.json")}
    # units in every CSV column name
    header = (out_dir / "flight.csv").read_text().splitlines()[0].split(",")
    assert all(re.search(r"_[A-Za-z0-9]+$", c) for c in header if c != "phase")
    a = flight.arrays()
    assert set(a) == set(header) and len(a["t_s"]) > 1000


@pytest.mark.timeout(240)
def test_fly_an_optimised_cycle_in_memory(quick_cycle):
    flight = fdm_awe.fly(quick_cycle, cycles=1)
    assert flight.document["scenario"] == "paper" and flight.document["plant"] == "paper"
    assert flight.optimised["E_net_J"] == pytest.approx(quick_cycle.E_net_J)
    assert len(flight.cycles) == 1 and flight.cycles[0]["index"] == 0
    assert flight.document["reference"] is None  # flown from memory


def test_info_export_writes_the_definition_folders_and_refuses_a_non_empty_folder(tmp_path):
    dest = tmp_path / "defs"
    code, out, _ = _run(["info", "--export", str(dest)])
    assert code == 0
    got = sorted(p.relative_to(dest).as_posix() for p in dest.rglob("*") if p.is_file())
    want = sorted(p.relative_to(fdm_awe.ROOT).as_posix() for f in fdm_awe.DEFINITION_FOLDERS
                  for p in (fdm_awe.ROOT / f).rglob("*.xml"))
    assert got == want and len(got) >= 10 and f"exported {len(got)} definition files" in out
    assert (dest / "aircraft/glider_unfolded/glider_unfolded.xml").read_bytes() == \
        (fdm_awe.ROOT / "aircraft/glider_unfolded/glider_unfolded.xml").read_bytes()
    code, out, err = _run(["info", "--export", str(dest)])
    assert code == 2 and out == "" and err.count("\n") == 1 and "--export" in err and "not empty" in err
    (tmp_path / "file").write_text("x")
    code, _, err = _run(["info", "--export", str(tmp_path / "file")])
    assert code == 2 and "not a folder" in err
    empty = tmp_path / "empty"
    empty.mkdir()
    assert _run(["info", "--export", str(empty)])[0] == 0 and (empty / "engine").is_dir()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".part")]


@pytest.mark.timeout(300)
def test_sweep_gives_the_document_of_the_command(tmp_path):
    res = fdm_awe.sweep(tmp_path / "sw", wind="3", config="nominal", scenario="paper", mesh="10,8,3", cold=True,
                        workers=1)
    assert res.exit_code == 0 and res.document["n_points"] == 1 and res.document["complete"]
    (p,) = res.points
    assert p["config"] == "nominal" and p["wind_mps"] == 3.0
    a = res.arrays()
    assert a["wind_mps"].tolist() == [3.0] and np.isfinite(a["P_avg_W"]).all()
    assert (tmp_path / "sw" / "points.csv").is_file() and Path(res.document["files"]["table"]).name == "points.csv"
    assert not [f for f in (tmp_path / "sw").iterdir() if f.suffix == ".json"]  # no JSON asked for, none written
