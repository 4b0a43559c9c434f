"""The drive as design data (docs/folding_map.md): a supply voltage is a ground-station variant
file derived from the definition in one place (:mod:`fdm_awe.groundstation.variants`), the
optimiser's drive bound follows it as the motor's physics says, ``scripts/drive_map.py`` sweeps
supply x folded span x wind with it and co-designs the supply (:mod:`fdm_awe.sweep.codesign`):
the best power is never below the grid's best at that wind, the voltage it names lies in the
range. Bad input is one line and exit 2 before any solve."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from fdm_awe.errors import InputError
from fdm_awe.groundstation.definitions import load_ground_station
from fdm_awe.groundstation.steady import motor_max_reel_in_speed, motor_steady
from fdm_awe.groundstation.variants import check_supply_voltage, supply_variant_text, write_supply_variant
from fdm_awe.sweep.codesign import supply_search

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "drive_map.py"
sys.path.insert(0, str(ROOT / "scripts"))

import drive_map  # noqa: E402


def _run_script(*args: str, timeout: float = 60.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True, timeout=timeout,
                          cwd=ROOT, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin", "JSBSIM_DEBUG": "0"})


@pytest.mark.parametrize("args, words", [
    (["--supply-voltage", "24,300"], ("--supply-voltage", "300", "6..200")),
    (["--supply-voltage", "5"], ("--supply-voltage", "6..200")),
    (["--supply-voltage", "24,,48"], ("--supply-voltage",)),
    (["--codesign-wind", "30"], ("--codesign-wind", "0..25")),
    (["--codesign-steps", "99", "--codesign-wind", "10"], ("--codesign-steps", "0..20")),
    (["--codesign-wind", "10", "--supply-voltage", "36"], ("--supply-voltage", "two voltages")),
])
def test_bad_input_is_one_line_and_exit_2_before_any_work(tmp_path, args, words):
    out = tmp_path / "out"
    p = _run_script(*args, "--out", str(out))
    assert p.returncode == 2, p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), p.stderr
    assert all(w in lines[0] for w in words), lines[0]
    assert not (out / "stations").exists()  # nothing written, nothing solved


def test_a_variant_out_of_range_is_refused():
    with pytest.raises(InputError, match=r"--supply-voltage 250.*6\.\.200 V"):
        check_supply_voltage(250.0)
    with pytest.raises(InputError, match="--supply-voltage nan"):
        supply_variant_text(float("nan"))


def test_the_supply_reaches_the_drive_as_the_motor_says(tmp_path):
    """The variant changes the supply (and the speed loop's gains with it: Kp V_a and Ki V_a
    held, the loop's crossover kept), nothing else; the fastest reel-in is affine in the supply
    with the slope r_w / (K + R B / K) of the steady motor (the fixed drops stay), and at full
    speed the motor needs exactly the variant's supply; the optimiser's reel-in bound read from
    the variant file equals the one of ``supply_voltage`` on the package's file."""
    from fdm_awe.ocp.build import get_nlp
    from fdm_awe.ocp.problem import CycleProblem, Mesh

    base = load_ground_station()
    params = {v: write_supply_variant(v, tmp_path / f"gs{v:g}.xml").load() for v in (24.0, 36.0, 48.0)}
    for v, p in params.items():
        assert p.converter.supply_voltage == v
        assert p.controller.kp * v == pytest.approx(base.controller.kp * 48.0, rel=1e-5)
        assert p.controller.ki * v == pytest.approx(base.controller.ki * 48.0, rel=1e-5)
        assert (p.machine, p.winch, p.tether) == (base.machine, base.winch, base.tether)
    assert params[48.0].controller == base.controller  # the package's own supply: the same drive
    speed = {v: motor_max_reel_in_speed(0.0, p) for v, p in params.items()}
    m, w = base.machine, base.winch
    slope = w.radius / (m.k + m.resistance * w.viscous_friction / m.k)
    assert speed[36.0] - speed[24.0] == pytest.approx(12.0 * slope, rel=1e-9)
    assert speed[48.0] - speed[36.0] == pytest.approx(12.0 * slope, rel=1e-9)
    assert speed[24.0] == pytest.approx(5.36, abs=0.01) and speed[48.0] == pytest.approx(11.10, abs=0.01)
    for v, p in params.items():
        assert motor_steady(speed[v], 0.0, p).duty == pytest.approx(1.0, rel=1e-9)
    mesh = Mesh(4, 4, 2)
    for v in (24.0, 36.0):
        from fdm_awe.groundstation.source import resolve_ground_station

        st = resolve_ground_station(tmp_path / f"gs{v:g}.xml")
        by_file = get_nlp(CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=mesh,
                                       ground_station=st), cache=False)[0].reel_in_speed_max
        by_value = get_nlp(CycleProblem(scenario="physical", config="nominal", wind_speed=8.0, mesh=mesh,
                                        supply_voltage=v), cache=False)[0].reel_in_speed_max
        assert by_file == pytest.approx(speed[v], rel=1e-12) and by_value == pytest.approx(speed[v], rel=1e-12)


def test_the_search_never_falls_below_the_grid_and_finds_the_plateau_edge():
    """On a power that rises with the supply until the drive stops binding (a knee at 31.3 V),
    with a local optimum that falls short at 40 V: the best is the grid's best or better, the
    smallest voltage on the plateau lies in the range, above the knee, within a bisection step."""
    calls = []

    def power(v: float) -> float | None:
        calls.append(v)
        if v == 40.0:
            return 10.0  # a poorer local optimum
        return 20.0 + min(v, 31.3) - 31.3

    grid = (24.0, 36.0, 40.0, 48.0)
    res = supply_search(power, grid, 24.0, 48.0, tol_W=0.5, steps=4)
    grid_best = max(p for v in grid if (p := power(v)) is not None)
    assert res["best"]["P_W"] >= grid_best
    assert 24.0 <= res["needed"]["V"] <= 48.0
    assert 31.3 - 0.5 <= res["needed"]["V"] <= 31.3 + 12.0 / 2 ** 4 + 0.01
    assert res["needed"]["P_W"] >= res["best"]["P_W"] - 0.5
    assert len([e for e in res["evaluations"] if not e["grid"]]) == 4
    flat = supply_search(lambda v: 5.0, grid, 24.0, 48.0)  # never binds: the lowest voltage, no bisection
    assert flat["needed"]["V"] == 24.0 and len(flat["evaluations"]) == 4
    none = supply_search(lambda v: None, grid, 24.0, 48.0)
    assert none["best"] is None and none["needed"] is None


def test_a_short_sweep_and_co_design(tmp_path):
    """Two supplies x one folded span x one wind on a coarse mesh, and the co-design at that
    wind on the grid's voltages alone (no bisection step: the synthetic power above tests
    those): every point records its drive; at 24 V the recovery takes up its 50 m no faster
    than the drive's fastest reel-in; the co-design's best is not below the grid's best at that
    wind and its voltage lies in the range."""
    out = tmp_path / "drive"
    rc = drive_map.main(["--supply-voltage", "24,48", "--folded-span", "0.22", "--wind", "10", "--mesh", "12,8,3",
                         "--no-cold-check", "--codesign-wind", "10", "--codesign-steps", "0", "--out", str(out)])
    assert rc == 0
    doc = json.loads((out / "drive_map.json").read_text())
    assert sorted(doc["points"]) == ["24", "48"]
    for key, pts in doc["points"].items():
        assert len(pts) == 2 and {p["supply_voltage_V"] for p in pts} == {float(key)}
    v24 = doc["reel_in_max_mps"]["24"]
    for p in doc["points"]["24"]:
        if p["status"] == "ok":
            assert p["T2_s"] >= 50.0 / v24 * (1 - 1e-3)
    cd = doc["codesign"]
    grid = [p["P_avg_W"] for k in ("24", "48") for p in doc["points"][k]
            if p["config"] == "foldable" and p["status"] == "ok"]
    assert grid, "the grid has a converged foldable point at 10 m/s"
    assert cd["best"]["P_W"] >= max(grid)
    assert 24.0 <= cd["needed"]["V"] <= 48.0 and cd["needed"]["P_W"] >= cd["best"]["P_W"] - cd["tol_W"]
    assert [e["V"] for e in cd["evaluations"]] == [24.0, 48.0]  # the grid's voltages only
    md = (out / "drive_map.md").read_text()
    assert "| 24 | 5.36 | nominal |" in md and "Co-design of the supply voltage at 10 m/s" in md
