"""The command line: help lists the commands, errors exit non-zero with one line."""

import subprocess
import sys

from fdm_awe.cli import COMMANDS, main


def test_help_lists_existing_commands():
    out = subprocess.run([sys.executable, "-m", "fdm_awe", "--help"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    for name in COMMANDS:
        assert name in out.stdout


def test_no_command_prints_help_and_fails(capsys):
    assert main([]) == 2


def test_info_runs(tmp_path, capsys):
    assert main(["info", "--json", str(tmp_path / "i.json")]) == 0
    assert "best glide" in capsys.readouterr().out
    assert (tmp_path / "i.json").stat().st_size > 0


def test_fly_rejects_bad_input_with_one_line_and_exit_2(tmp_path, capsys):
    assert main(["fly", "--cycles", "0", "--reference", "x.json"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--cycles" in err and "1..1000" in err
    missing = tmp_path / "nope.json"
    assert main(["fly", "--reference", str(missing)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(missing) in err


def test_fly_command_writes_json_per_the_output_contract(tmp_path):
    """A short headless flight of the stored reference through the command line; scenario and
    configuration default to the reference file's."""
    from pathlib import Path
    import json

    ref = Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"
    out = tmp_path / "run.json"
    rc = main(["fly", "--reference", str(ref), "--cycles", "1", "--quiet", "--json", str(out)])
    doc = json.loads(out.read_text())
    assert rc == 0 and doc["status"] == "ok"
    assert (doc["scenario"], doc["config"]) == ("physical", "nominal")
    for key in ("scenario", "config", "wind_mps", "status", "sim_time_s", "wall_s", "realtime_factor",
                "ledger_residual_rel", "cycles"):
        assert key in doc
    c = doc["cycles"][0]
    for key in ("T1_s", "T2_s", "E_generated_J", "E_thrust_J", "E_reel_in_J", "E_net_J", "track_rms_m", "track_max_m"):
        assert key in c
    assert c["E_net_J"] == __import__("pytest").approx(c["E_generated_J"] - c["E_thrust_J"] - c["E_reel_in_J"], abs=1e-5)


def test_fly_command_streams_mavlink_paced_in_real_time(tmp_path):
    """`fdm-awe fly --mavlink URL --realtime 10` sends telemetry to a ground station on
    127.0.0.1 while flying a 20 s stretch of the stored reference (bounded: 60 s wall)."""
    import collections
    import socket
    import time
    from pathlib import Path

    from pymavlink import mavutil

    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    gcs = mavutil.mavlink_connection(f"udpin:127.0.0.1:{port}")
    ref = Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json"
    p = subprocess.Popen([sys.executable, "-m", "fdm_awe", "fly", "--reference", str(ref), "--config", "nominal",
                          "--cycles", "1", "--mavlink", f"udpout:127.0.0.1:{port}", "--realtime", "10", "--quiet",
                          "--json", str(tmp_path / "run.json")], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    seen = collections.Counter()
    t0 = time.monotonic()
    try:
        while p.poll() is None and time.monotonic() - t0 < 60:
            m = gcs.recv_match(blocking=True, timeout=0.5)
            if m is not None and m.get_srcComponent() == 1:  # the autopilot (the winch, 169, has its own heartbeat)
                if m.get_type() == "HEARTBEAT" and m.system_status == mavutil.mavlink.MAV_STATE_BOOT:
                    seen["boot"] += 1  # the heartbeat while the flight loads: not the flight's
                    continue
                seen[m.get_type()] += 1
    finally:
        if p.poll() is None:
            p.kill()
        p.communicate(timeout=30)
        gcs.close()
    assert p.returncode == 0
    wall = time.monotonic() - t0
    # 60 s of flight at 10x real time: about 6 s of wall time, one heartbeat per simulated second
    assert wall > 5.0
    assert 50 <= seen["HEARTBEAT"] <= 70
    for t in ("ATTITUDE", "GLOBAL_POSITION_INT", "VFR_HUD", "SYS_STATUS", "NAMED_VALUE_FLOAT"):
        assert seen[t] > 0, t


def test_fly_flies_the_line_drag_scale_of_the_reference(tmp_path, monkeypatch, capsys):
    """`fdm-awe fly` takes the line-drag factor from the reference's metadata (an info line, no
    warning), records it in the JSON, and warns only when --tether-drag-scale overrides it.
    Short flights (3 s) of the stored reference with its metadata set to 0.5."""
    import json
    from pathlib import Path

    import fdm_awe.sim.flight as flight

    doc = json.loads((Path(__file__).parent / "data" / "ref_physical_nominal_8mps.json").read_text())
    doc["metadata"]["tether_drag_scale"] = 0.5
    ref = tmp_path / "ref_scaled.json"
    ref.write_text(json.dumps(doc))
    seen = []
    real_fly = flight.fly

    def short_fly(*a, **kw):
        seen.append(kw["tether_drag_scale"])
        return real_fly(*a, **{**kw, "t_end": 3.0})

    monkeypatch.setattr(flight, "fly", short_fly)
    out = tmp_path / "run.json"
    assert main(["fly", "--reference", str(ref), "--quiet", "--json", str(out)]) == 0
    err = capsys.readouterr().err
    assert seen == [0.5] and json.loads(out.read_text())["tether_drag_scale"] == 0.5
    assert "line drag x 0.5" in err and "warning" not in err
    assert main(["fly", "--reference", str(ref), "--quiet", "--tether-drag-scale", "1", "--json", str(out)]) == 0
    err = capsys.readouterr().err
    assert seen == [0.5, 1.0] and json.loads(out.read_text())["tether_drag_scale"] == 1.0
    assert "warning" in err and "tether_drag_scale 0.5" in err
    assert main(["fly", "--reference", str(ref), "--tether-drag-scale", "-1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--tether-drag-scale" in err and "0..10" in err
    assert main(["fly", "--reference", str(ref), "--gamma-max", "2"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--gamma-max" in err and "0.1..1.5" in err


def test_info_shows_the_sizing_of_each_line(tmp_path, capsys):
    """`fdm-awe info` prints every tether line's sizing (rated tension, safety factor, breaking
    load, diameter, mass per length, EA, C_D,t at the shortest and longest working line) and its
    JSON carries the same numbers; the sized line breaks at 4-5 times the rated tension."""
    import json

    from fdm_awe.groundstation.line import LINES

    out = tmp_path / "i.json"
    assert main(["info", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    for name in LINES:
        assert f"line {name}: rated 50 N x SF" in text and "C_D,t" in text and "200 m" in text and "250 m" in text
    doc = json.loads(out.read_text())
    assert set(doc["lines"]) == set(LINES)
    assert doc["default_line"] == {"file": "sized", "physical": "sized", "paper": "paper"}
    sized, paper = doc["lines"]["sized"], doc["lines"]["paper"]
    assert 4.0 <= sized["breaking_load_N"] / sized["rated_tension_N"] <= 5.0
    assert sized["safety_factor"] == sized["breaking_load_N"] / sized["rated_tension_N"]
    assert paper["diameter_m"] == 0.72e-3 and paper["breaking_load_N"] == 700.0
    for line in (sized, paper):
        assert line["lengths_m"] == [200.0, 250.0]
        # C_D,t grows with the line length, and the thinner line drags less at every length
        assert line["cd_t"][0] < line["cd_t"][1]
    assert all(s < p for s, p in zip(sized["cd_t"], paper["cd_t"]))
    assert sized["mass_per_length_kg_per_m"] < paper["mass_per_length_kg_per_m"]
    assert sized["axial_stiffness_N"] > 0 and sized["diameter_m"] < paper["diameter_m"]


def test_info_shows_what_the_drive_allows(tmp_path, capsys):
    """`fdm-awe info` prints what the supply and the machine's ratings allow: the largest reel-in
    speed (11.10 m/s at the definition's 48 V on a slack line, the steady motor's at full duty;
    less against the lower line tension), the line tensions of the rated and peak currents
    (50 N, the line's rating, and twice that), and the supply the drive's design reel-in speed
    needs (40.8 V against 2 N: the 48 V supply is sized for it), in the JSON too."""
    import json

    import pytest

    from fdm_awe.groundstation import load_ground_station
    from fdm_awe.groundstation.steady import motor_max_reel_in_speed, motor_steady

    out = tmp_path / "i.json"
    assert main(["info", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "drive: supply 48 V: reel-in at most 11.10 m/s" in text and "needs" in text
    d = json.loads(out.read_text())["ground_station"]["drive"]
    gs = load_ground_station()
    # r_w (V_a - 2 U_d - R M_c / K) / (K + R B / K) = 0.03 (48 - 1 - 0.639) / 0.12527 = 11.103 m/s
    assert d["reel_in_max_at_lower_tension_mps"] < d["reel_in_max_mps"] == pytest.approx(11.103, abs=0.005)
    assert d["reel_in_max_mps"] == pytest.approx(motor_max_reel_in_speed(0.0, gs), rel=1e-12)
    assert d["rated_tension_N"] == pytest.approx(50.0, abs=0.5) and d["peak_tension_N"] == pytest.approx(
        2.0 * d["rated_tension_N"])
    # the supply the design speed needs is the one at which the steady motor runs at full duty
    full = motor_steady(d["design_reel_in_speed_mps"], d["lower_tension_N"], gs).duty * gs.converter.supply_voltage
    assert d["supply_needed_V"] == pytest.approx(full, rel=1e-12)
    assert (d["supply_needed_V"] > d["supply_voltage_V"]) == (d["design_reel_in_speed_mps"] > d[
        "reel_in_max_at_lower_tension_mps"])
    # the 48 V supply covers the design reel-in speed (9.3 m/s against 2 N takes 40.8 V)
    assert d["supply_needed_V"] == pytest.approx(40.8, abs=0.05) and d["supply_voltage_V"] == 48.0
    assert d["supply_needed_V"] < d["supply_voltage_V"]
    assert d["design_reel_in_speed_mps"] < d["reel_in_max_at_lower_tension_mps"]
    assert "needs 40.8 V against 2 N" in text
    # the converter's tension limit: the line's rating, and the current that holds it on the drum
    assert "tension limit 50 N" in text and d["tension_limit_N"] == gs.converter.tension_limit
    k, r, mc = gs.machine.k, gs.winch.radius, gs.winch.coulomb_friction
    assert k * d["tension_limit_current_A"] + mc == pytest.approx(r * d["tension_limit_N"], rel=1e-12)
    assert d["generator_brake_max_N"] > d["tension_limit_N"] + d["tension_limit_band_N"]
