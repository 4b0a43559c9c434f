"""Options of the command line: every number range-checked, seeds, MAVLink URLs and scheduler
addresses validated, list items never silently dropped, options a reference fixes refused, and
defaults that work. Each refusal is one line naming the option and the allowed range, exit 2,
before any work (the work functions are spies that fail the test when called)."""

from __future__ import annotations

import json
import socket
import time
from pathlib import Path

import pytest

from fdm_awe.cli import build_parser, main

DATA = Path(__file__).parent / "data"
REF = DATA / "ref_physical_nominal_8mps.json"
REF_FOLDABLE = DATA / "ref_physical_foldable_8mps_halfline.json"


def _refused(argv: list[str], capsys, *words: str) -> str:
    t0 = time.monotonic()
    rc = main(argv)
    wall = time.monotonic() - t0
    err = capsys.readouterr().err.strip()
    assert rc == 2, (argv, err)
    assert wall < 10.0, (argv, wall)
    assert "\n" not in err and "error:" in err, err
    for w in words:
        assert w in err, (argv, w, err)
    return err


NUMERIC = [
    # optimize: the reproducers (-1 and nan used to run ~40 s and exit 1) and every other number
    (["optimize", "--time-budget", "-1"], ("--time-budget", "> 0")),
    (["optimize", "--time-budget", "nan"], ("--time-budget", "> 0")),
    (["optimize", "--time-budget", "inf"], ("--time-budget", "86400")),
    (["optimize", "--starts", "0"], ("--starts", "1..100")),
    (["optimize", "--wind", "-2"], ("--wind", "wind speed", "0..25")),
    (["optimize", "--wind", "nan"], ("--wind", "0..25")),
    (["optimize", "--wind-from", "inf"], ("--wind-from", "-360..360")),
    (["optimize", "--d0", "0"], ("--d0", "> 0")),
    (["optimize", "--d-tf", "150"], ("--d-tf", "> 200")),
    (["optimize", "--v-min", "-5"], ("--v-min", "> 0")),
    (["optimize", "--v-max", "4"], ("--v-max", "> 5")),
    (["optimize", "--h-min", "-1"], ("--h-min", "0..100 m")),
    (["optimize", "--h-min", "150"], ("--h-min", "below the start altitude")),
    (["optimize", "--v-max", "80"], ("--v-max", "50 m/s")),
    (["optimize", "--t-max", "1e4"], ("--t-max", "600 s")),
    (["optimize", "--d-tf", "1e9"], ("--d-tf", "600 m")),
    (["optimize", "--t-max", "nan"], ("--t-max", "> 0")),
    (["optimize", "--tether-drag-scale", "11"], ("--tether-drag-scale", "0..10")),
    (["optimize", "--mesh", "2,20,4"], ("--mesh", "4..1000")),
    (["optimize", "--mesh", "60,20"], ("--mesh", "NG,NR,DEG")),
    (["optimize", "--reel-in-speed-max", "0"], ("--reel-in-speed-max", "> 0 and <= 50 m/s")),
    (["optimize", "--reel-in-speed-max", "nan"], ("--reel-in-speed-max", "> 0 and <= 50 m/s")),
    (["optimize", "--fold-time", "-1"], ("--fold-time", "0..60")),
    (["optimize", "--supply-voltage", "5"], ("--supply-voltage", "6..200")),
    (["optimize", "--supply-voltage", "48", "--scenario", "paper"], ("--supply-voltage", "physical scenario")),
    # compare
    (["compare", "--starts", "0"], ("--starts", "1..100")),
    (["compare", "--time-budget", "nan"], ("--time-budget", "> 0")),
    (["compare", "--wind", "26"], ("--wind", "0..25")),
    (["compare", "--tether-drag-scale", "-0.1"], ("--tether-drag-scale", "0..10")),
    (["compare", "--mesh", "60,20,0"], ("--mesh", "1..9")),
    # fly (with a reference: the checks come before the file is flown)
    (["fly", "--reference", str(REF), "--cycles", "0"], ("--cycles", "1..1000")),
    (["fly", "--reference", str(REF), "--dt", "nan"], ("--dt", "0.0001..0.05")),
    (["fly", "--reference", str(REF), "--dt", "0.1"], ("--dt", "0.0001..0.05")),
    (["fly", "--reference", str(REF), "--realtime", "0"], ("--realtime", "> 0")),
    (["fly", "--reference", str(REF), "--realtime", "inf"], ("--realtime", "1000")),
    (["fly", "--reference", str(REF), "--tether-drag-scale", "nan"], ("--tether-drag-scale", "0..10")),
    (["fly", "--wind", "30"], ("--wind", "0..25")),
    (["fly", "--wind-from", "nan"], ("--wind-from", "-360..360")),
    (["fly", "--gamma-max", "0"], ("--gamma-max", "0.1..1.5")),
    (["fly", "--bank-rate-max", "0"], ("--bank-rate-max", "0.01..10 rad/s")),
    (["fly", "--v-min", "0.5"], ("--v-min", "1..20 m/s")),
    (["fly", "--alpha-rate-max", "inf"], ("--alpha-rate-max", "0.01..10 rad/s")),
    (["fly", "--catch-speed-max", "-1"], ("--catch-speed-max", "0..30 m/s")),
    (["optimize", "--bank-rate-max", "11"], ("--bank-rate-max", "0.01..10 rad/s")),
    (["optimize", "--catch-speed-max", "nan"], ("--catch-speed-max", "0..30 m/s")),
    # sweep
    (["sweep", "--out", "{tmp}", "--max-iter", "5"], ("--max-iter", "10..100000")),
    (["sweep", "--out", "{tmp}", "--max-iter-total", "0"], ("--max-iter-total", "10..1000000")),
    (["sweep", "--out", "{tmp}", "--anchor-every", "-1"], ("--anchor-every", "0..1000")),
    (["sweep", "--out", "{tmp}", "--workers", "0"], ("--workers", "1..1024")),
    (["sweep", "--out", "{tmp}", "--stop-after", "0"], ("--stop-after", ">= 1")),
    (["sweep", "--out", "{tmp}", "--wind", "3,,5"], ("--wind", "empty list item")),
    (["sweep", "--out", "{tmp}", "--wind", "3,5,"], ("--wind", "empty list item")),
    (["sweep", "--out", "{tmp}", "--wind", "3,30"], ("--wind", "0..25")),
    (["sweep", "--out", "{tmp}", "--wind", "3:nan:1"], ("--wind", "START:STOP:STEP")),
    (["sweep", "--out", "{tmp}", "--config", "nominal,,foldable"], ("--config", "empty list item")),
    (["sweep", "--out", "{tmp}", "--config", "nominal,bogus"], ("--config", "bogus", "nominal, foldable")),
    (["sweep", "--out", "{tmp}", "--tether-range", "200:250,"], ("--tether-range", "empty list item")),
    (["sweep", "--out", "{tmp}", "--mesh", "6"], ("--mesh", "NGEN,NREC")),
    (["sweep", "--out", "{tmp}", "--scheduler", "bogus"], ("--scheduler", "HOST:PORT")),
    (["sweep", "--out", "{tmp}", "--scheduler", "tcp://127.0.0.1:0"], ("--scheduler", "1..65535")),
    (["sweep", "--out", "{tmp}", "--scheduler", "udp://127.0.0.1:8786"], ("--scheduler", "tcp")),
    (["sweep", "--out", "{tmp}", "--scheduler", "tcp://no-such-host.invalid:8786"], ("--scheduler", "does not resolve")),
    (["sweep", "--out", "{tmp}", "--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"], ("--workers", "--scheduler")),
    # the plant model: names, and choices only where the scenario has them
    (["optimize", "--line", "thin"], ("--line", "invalid choice", "sized", "paper")),
    (["optimize", "--scenario", "paper", "--line-weight"], ("--line-weight", "only the physical scenario")),
    (["optimize", "--scenario", "paper", "--propeller", "momentum"], ("--propeller momentum", "only the physical")),
    (["compare", "--scenario", "paper", "--propeller", "engine"], ("--propeller engine", "only the physical")),
    (["fly", "--scenario", "paper", "--line-weight"], ("--line-weight", "only the physical scenario")),
    (["fly", "--line", "thin"], ("--line", "invalid choice")),
    (["sweep", "--out", "{tmp}", "--line", "sized,,paper"], ("--line", "empty list item")),
    (["sweep", "--out", "{tmp}", "--line", "sized,thin"], ("--line", "'thin' unknown", "sized, paper")),
    (["sweep", "--out", "{tmp}", "--line-diameter", "0.0003,"], ("--line-diameter", "empty list item")),
    (["sweep", "--out", "{tmp}", "--line-diameter", "0.01"], ("--line-diameter", "1e-05..0.005 m")),
    (["sweep", "--out", "{tmp}", "--line-diameter", "0.0002"], ("--line-diameter", "below the rated tension 50 N",
                                                               ">= 0.212 mm")),
    (["sweep", "--out", "{tmp}", "--line", "paper", "--line-diameter", "0.0003"], ("only the sized line is resized",)),
    (["sweep", "--out", "{tmp}", "--scenario", "paper", "--no-line-weight", "--line-weight"],
     ("--line-weight", "only the physical scenario")),
    # argparse's own errors are one line too
    (["optimize", "--wind", "abc"], ("--wind", "invalid float")),
    (["fly", "--cycles", "1.5"], ("--cycles", "invalid int")),
]


@pytest.mark.parametrize("argv,words", NUMERIC, ids=[" ".join(a) for a, _ in NUMERIC])
def test_every_numeric_option_is_range_checked_before_work(argv, words, tmp_path, no_work, capsys):
    argv = [a.replace("{tmp}", str(tmp_path / "sweep")) for a in argv]
    _refused(argv, capsys, *words)
    assert not (tmp_path / "sweep").exists()  # nothing created


@pytest.mark.parametrize("spec,words", [
    ("light:0", ("seed 0", "1..2147483647")),
    ("light:-1", ("seed -1", "1..2147483647")),
    ("severe:2147483648", ("seed 2147483648", "1..2147483647")),
    ("moderate:", ("seed ''", "not an integer")),
    ("moderate:x", ("seed 'x'", "not an integer")),
    ("storm:3", ("form 'storm'", "light, moderate, severe", "milspec:SEVERITY", "iec:CLASS")),
    ("iec:D:2", ("class 'D'", "A, B, C", "milspec:SEVERITY")),
    ("iec", ("needs a class", "A, B, C")),
    ("milspec:gusty", ("severity 'gusty'", "light, moderate, severe")),
    ("iec:A:0", ("seed 0", "1..2147483647")),
])
def test_turbulence_seed_and_level_are_validated(spec, words, no_work, capsys):
    _refused(["fly", "--reference", str(REF), "--turbulence", spec], capsys, "--turbulence", *words)


def test_turbulence_parser_accepts_the_seed_range():
    from fdm_awe.commands._checks import turbulence
    from fdm_awe.turbulence import Turbulence

    assert turbulence("light") == Turbulence("level", "light", 1)
    assert turbulence("light:1") == Turbulence("level", "light", 1)
    assert turbulence("severe:2147483647") == Turbulence("level", "severe", 2**31 - 1)
    assert turbulence("milspec:moderate:2147483647") == Turbulence("milspec", "moderate", 2**31 - 1)
    assert turbulence("iec:B") == Turbulence("iec", "B", 1)
    assert turbulence(None) is None


@pytest.mark.parametrize("url,words", [
    ("udpout:no-such-host.invalid:14550", ("no-such-host.invalid", "does not resolve")),
    ("udpout:127.0.0.1:0", ("port 0", "1..65535")),
    ("udpout:127.0.0.1:65536", ("port 65536", "1..65535")),
    ("tcp:127.0.0.1:x", ("port 'x'", "not an integer")),
    ("udpout:127.0.0.1", ("KIND:HOST:PORT",)),
    ("udpout::14550", ("KIND:HOST:PORT",)),
    ("serial:/dev/ttyS0:57600", ("udpout, udpin, udp, tcp, tcpin",)),
    ("127.0.0.1:14550", ("KIND:HOST:PORT",)),
])
def test_mavlink_url_is_checked_before_the_flight(url, words, no_work, capsys):
    _refused(["fly", "--reference", str(REF), "--mavlink", url], capsys, "--mavlink", *words)


def _free_port(kind: int = socket.SOCK_STREAM) -> int:
    with socket.socket(socket.AF_INET, kind) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_mavlink_urls_of_every_kind_pass():
    from fdm_awe.commands._checks import MAVLINK_KINDS, mavlink_url, scheduler_address

    port = _free_port()  # the listening kinds bind it for a moment
    for kind in MAVLINK_KINDS:
        assert mavlink_url(f"{kind}:127.0.0.1:{port}") == f"{kind}:127.0.0.1:{port}"
    assert mavlink_url(f"udpin:0.0.0.0:{_free_port(socket.SOCK_DGRAM)}") and mavlink_url("udpout:localhost:65535")
    assert scheduler_address("tcp://127.0.0.1:8786") and scheduler_address("127.0.0.1:8786")


def test_options_a_reference_fixes_are_refused(tmp_path, no_work, capsys):
    """--wind, --wind-from, --gamma-max, --line, --propeller and --line-weight only shape an
    optimised reference: with --reference they are refused (they used to be silently ignored);
    the flight flies the line the reference names."""
    for extra, option in [(["--wind", "5"], "--wind"), (["--wind-from", "90"], "--wind-from"),
                          (["--gamma-max", "0.7"], "--gamma-max"), (["--propeller", "engine"], "--propeller"),
                          (["--line-weight"], "--line-weight"), (["--no-line-weight"], "--no-line-weight"),
                          (["--line", "paper"], "--line"), (["--line", "sized"], "--line"),
                          (["--bank-rate-max", "0.5"], "--bank-rate-max"), (["--alpha-rate-max", "0.2"], "--alpha-rate-max"),
                          (["--catch-speed-max", "1"], "--catch-speed-max"), (["--v-min", "10"], "--v-min")]:
        _refused(["fly", "--reference", str(REF), *extra], capsys, option, "fixes")
    _refused(["fly", "--allow-mismatch"], capsys, "--allow-mismatch", "--reference")


def test_config_or_scenario_other_than_the_reference_is_refused_unless_allowed(tmp_path, monkeypatch, capsys):
    """A nominal reference flown as foldable (and the reverse, and physical as paper) is
    refused; --allow-mismatch flies it with a warning line."""
    import fdm_awe.sim.flight as flight

    calls = []
    real = flight.fly

    def short(*a, **kw):
        calls.append(kw)
        return real(*a, **{**kw, "t_end": 2.0})

    monkeypatch.setattr(flight, "fly", short)
    _refused(["fly", "--reference", str(REF), "--config", "foldable"], capsys, "--config foldable", "'nominal'",
             "--allow-mismatch")
    _refused(["fly", "--reference", str(REF_FOLDABLE), "--config", "nominal"], capsys, "--config nominal", "'foldable'")
    _refused(["fly", "--reference", str(REF), "--scenario", "paper"], capsys, "--scenario paper", "'physical'")
    assert calls == []
    # the same options as the reference's: no complaint
    out = tmp_path / "run.json"
    assert main(["fly", "--reference", str(REF), "--config", "nominal", "--scenario", "physical", "--quiet",
                 "--json", str(out)]) == 0
    assert "warning" not in capsys.readouterr().err
    # overridden on purpose: flown as asked, with a warning
    assert main(["fly", "--reference", str(REF), "--config", "foldable", "--allow-mismatch", "--quiet",
                 "--json", str(out)]) in (0, 1)
    err = capsys.readouterr().err
    assert "warning:" in err and "'nominal'" in err and "--config foldable" in err
    assert calls[-1]["config"] == "foldable" and json.loads(out.read_text())["config"] == "foldable"


def test_defaults_optimise_the_nominal_glider_and_say_why():
    """The physical foldable cycle loses more than the nominal one on the sized line and does not
    exist on Table 1's line: fly and optimize default to the nominal glider, and their help says
    why."""
    p = build_parser()
    sub = p._subparsers._group_actions[0].choices  # noqa: SLF001 - argparse has no public accessor
    assert sub["optimize"].parse_args([]).config == "nominal"
    fly = sub["fly"]
    args = fly.parse_args([])
    assert args.config is None and args.wind is None and args.line_weight is None  # "not given"
    assert args.line is None and args.propeller is None
    from fdm_awe.commands._fly_optimise import DEFAULT_CONFIG, DEFAULT_WIND_MPS

    assert (DEFAULT_CONFIG, DEFAULT_WIND_MPS) == ("nominal", 8.0)
    for name in ("fly", "optimize"):
        text = " ".join(sub[name].format_help().split())
        assert "default nominal" in text and "loses more than the nominal one" in text, name
        assert "Table 1's line it has no periodic cycle" in text, name


def test_plant_options_reach_the_problem_and_default_to_the_scenarios_plant():
    """optimize/compare/fly build their problem with the scenario's plant unless told otherwise;
    --line paper --propeller momentum --no-line-weight is the earlier physical plant."""
    from fdm_awe.commands._fly_optimise import reference_problem
    from fdm_awe.commands.optimize import problem_from_args
    from fdm_awe.ocp.problem import LEGACY_PHYSICAL_PLANT

    p = build_parser()
    sub = p._subparsers._group_actions[0].choices  # noqa: SLF001 - argparse has no public accessor
    opt = sub["optimize"]
    pr = problem_from_args(opt.parse_args([]))
    assert (pr.scenario, pr.line, pr.propeller, pr.line_weight) == ("physical", "sized", "engine", True)
    legacy = problem_from_args(opt.parse_args(["--line", "paper", "--propeller", "momentum", "--no-line-weight",
                                               "--recovery-tension", "slack"]))
    assert pr.recovery_tension == "free"
    assert {k: getattr(legacy, k) for k in LEGACY_PHYSICAL_PLANT} == LEGACY_PHYSICAL_PLANT
    paper = problem_from_args(opt.parse_args(["--scenario", "paper", "--no-line-weight"]))
    assert (paper.line, paper.propeller, paper.line_weight) == ("paper", None, False)
    assert problem_from_args(opt.parse_args(["--scenario", "paper", "--line", "sized"])).line == "sized"
    fly_args = sub["fly"].parse_args(["--line", "paper"])
    fly_args.scenario, fly_args.config = "physical", "nominal"
    assert reference_problem(fly_args).line == "paper"
    for name in ("optimize", "compare", "fly", "sweep"):
        text = " ".join(sub[name].format_help().split())
        assert "--no-line-weight" in text and "--line" in text and "engine" in text, name


def test_smoothness_options_reach_the_problem_and_default_to_off():
    """--bank-rate-max, --alpha-rate-max and --catch-speed-max become the problem's bounds in
    optimize and in the reference fly optimises (next to its flyable margins); unset, none."""
    from fdm_awe.commands._fly_optimise import reference_problem
    from fdm_awe.commands.optimize import problem_from_args

    sub = build_parser()._subparsers._group_actions[0].choices  # noqa: SLF001 - argparse has no public accessor
    plain = problem_from_args(sub["optimize"].parse_args([])).bounds
    assert (plain.bank_rate_max, plain.alpha_rate_max, plain.catch_speed_max) == (None, None, None)
    given = ["--bank-rate-max", "0.5", "--alpha-rate-max", "0.2", "--catch-speed-max", "1.5"]
    b = problem_from_args(sub["optimize"].parse_args(given)).bounds
    assert (b.bank_rate_max, b.alpha_rate_max, b.catch_speed_max) == (0.5, 0.2, 1.5)
    fly_args = sub["fly"].parse_args(given + ["--v-min", "10"])
    fly_args.scenario, fly_args.config = "physical", "nominal"
    b = reference_problem(fly_args).bounds
    assert (b.bank_rate_max, b.alpha_rate_max, b.catch_speed_max, b.cl_margin, b.phi_max) == (0.5, 0.2, 1.5, 0.85, 0.8)
    assert b.V_min == 10.0
    fly_args = sub["fly"].parse_args([])
    fly_args.scenario, fly_args.config = "physical", "nominal"
    assert reference_problem(fly_args).bounds.V_min == 5.0


def _edited_reference(tmp_path: Path, name: str, edit) -> Path:
    doc = json.loads(REF.read_text())
    edit(doc)
    p = tmp_path / f"{name}.json"
    p.write_text(json.dumps(doc))
    return p


def _shift_last(col: str, by: float):
    def f(doc):
        doc["columns"][col][-1] += by
    return f


def _ramp_z(doc):
    t = doc["columns"]["t"]
    doc["columns"]["z"] = [z - 80.0 * ti / t[-1] for z, ti in zip(doc["columns"]["z"], t)]


def _jump(doc):
    doc["columns"]["x"][150] += 500.0


@pytest.mark.parametrize("name,edit,words", [
    ("last_x_moved", _shift_last("x", 100.0), ("columns.x[321]", "periodic", "allowed difference <= 0.0002 m")),
    ("z_ramp", _ramp_z, ("columns.z[321]", "periodic")),
    ("jump", _jump, ("columns.x[150]", "moves", "allowed <=")),
    ("t_in_ms", lambda d: d["units"].update(t="ms"), ("units.t", "expected 's'")),
    ("no_units", lambda d: d.pop("units"), ("units: missing",)),
])
def test_a_reference_that_is_not_one_continuous_periodic_cycle_in_si_units_is_not_flown(tmp_path, no_work, capsys, name,
                                                                                      edit, words):
    """Issue 28 item 13: each of these flew (status ok) before; now one line, exit 2, before the flight."""
    p = _edited_reference(tmp_path, name, edit)
    err = _refused(["fly", "--reference", str(p), "--cycles", "1"], capsys, str(p), *words)
    assert err.startswith("fdm-awe fly: error: "), err


SWEEP_DESIGN = [
    # issue 28 item 11: -1 was a traceback (math domain error); the others did not name their option
    (["--wing-area", "-1"], ("--wing-area '-1'", "-1 m2 out of range", "0.01..2 m2")),
    (["--wing-area", "3"], ("--wing-area", "0.01..2 m2")),
    (["--wing-area", "nan"], ("--wing-area",)),
    (["--folded-span", "-1"], ("--folded-span '-1'", "> 0 m")),
    (["--folded-span", "0"], ("--folded-span", "> 0 m")),
    (["--folded-span", "5"], ("--folded-span '5'", "the unfolded span", "the definition's wing area")),
    (["--wing-area", "0.05", "--folded-span", "0.9"], ("--folded-span '0.9'", "unfolded span", "--wing-area 0.05 m2")),
    (["--folded-drag-area", "-1"], ("--folded-drag-area '-1'", "> 0 and < 0.1 m2")),
    (["--folded-drag-area", "0.1"], ("--folded-drag-area", "> 0 and < 0.1 m2")),
    (["--tether-range", "300:200"], ("--tether-range '300:200'", "0 < D0 < DTF")),
    (["--tether-range", "0:250"], ("--tether-range", "0 < D0 < DTF")),
    (["--tether-range", "200:inf"], ("--tether-range", "0 < D0 < DTF")),
    (["--fold-time", "100"], ("--fold-time '100'", "0..60 s")),
    (["--fold-time", "-1"], ("--fold-time", "0..60 s")),
]


@pytest.mark.parametrize("argv,words", SWEEP_DESIGN, ids=[" ".join(a) for a, _ in SWEEP_DESIGN])
def test_sweep_design_values_name_their_option(argv, words, tmp_path, no_work, capsys):
    _refused(["sweep", "--out", str(tmp_path / "sweep"), "--wind", "8", *argv], capsys, *words)
    assert not (tmp_path / "sweep").exists()


def test_sweep_design_values_in_range_pass(tmp_path):
    from fdm_awe.commands.sweep import build_spec

    args = build_parser().parse_args(["sweep", "--out", str(tmp_path / "s"), "--wind", "8", "--wing-area", "0.3,2",
                                      "--folded-span", "0.4", "--folded-drag-area", "0.02", "--fold-time", "0,60",
                                      "--tether-range", "150:250"])
    spec = build_spec(args)
    assert spec.wing_areas == (0.3, 2.0) and spec.folded_spans == (0.4,) and spec.fold_times == (0.0, 60.0)
    assert spec.tether_ranges == ((150.0, 250.0),)


def test_mavlink_key_that_is_not_a_file_says_what_it_is(tmp_path, no_work, capsys):
    import os

    fifo = tmp_path / "key.fifo"
    os.mkfifo(fifo)
    base = ["fly", "--reference", str(REF), "--mavlink", "udpout:127.0.0.1:14550", "--mavlink-key"]
    _refused(base + [str(tmp_path)], capsys, f"--mavlink-key {tmp_path}", "is a folder")
    _refused(base + [str(fifo)], capsys, "--mavlink-key", "not a regular file")
    _refused(base + ["/dev/zero"], capsys, "--mavlink-key /dev/zero", "not a regular file")
    _refused(base + [str(tmp_path / "none")], capsys, "--mavlink-key", "no such file")


def test_params_errors_name_the_option(tmp_path, no_work, capsys):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    text = tmp_path / "text.json"
    text.write_text(json.dumps({"format": "fdm-awe-params-1", "params": {"WP_RADIUS": "far"}}))
    base = ["fly", "--reference", str(REF), "--params"]
    for path, words in ((bad, ("unreadable JSON",)), (text, ("parameter WP_RADIUS", "not a finite number")),
                        (tmp_path, ("is a folder",))):
        err = _refused(base + [str(path)], capsys, f"--params {path}", *words)
        assert "<params>" not in err and "<parameter" not in err, err


# ------------------------------------------------------------------ issue 28 item 12: late errors come first


@pytest.mark.parametrize("kind", ["udpin", "udp", "tcpin"])
def test_a_mavlink_address_this_machine_cannot_listen_on_is_refused_at_once(kind, no_work, capsys):
    """udpin:192.0.2.1 (a documentation address, not this machine's) exited 2 after 14 s."""
    t0 = time.monotonic()
    _refused(["fly", "--reference", str(REF), "--mavlink", f"{kind}:192.0.2.1:14550"], capsys, "--mavlink",
             "cannot listen on 192.0.2.1:14550")
    assert time.monotonic() - t0 < 5.0


def test_a_mavlink_port_in_use_is_refused_at_once(no_work, capsys):
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen(1)
        port = busy.getsockname()[1]
        _refused(["fly", "--reference", str(REF), "--mavlink", f"tcpin:127.0.0.1:{port}"], capsys,
                 f"cannot listen on 127.0.0.1:{port}")


def test_mavlink_host_without_ipv4_is_refused(no_work, capsys):
    _refused(["fly", "--reference", str(REF), "--mavlink", "udpout:[::1]:14550"], capsys, "--mavlink",
             "no IPv4 address")


def test_a_tcp_ground_station_that_is_not_there_is_tried_once_before_the_flight(no_work, capsys):
    """tcp:127.0.0.1:1 printed "Connection refused sleeping" for 19 s; now one attempt, one
    line, exit 2, before the flight (the flight is a spy that would fail the test)."""
    port = _free_port()  # nobody listens there
    t0 = time.monotonic()
    rc = main(["fly", "--reference", str(REF), "--cycles", "1", "--quiet", "--mavlink", f"tcp:127.0.0.1:{port}"])
    wall = time.monotonic() - t0
    cap = capsys.readouterr()
    assert rc == 2 and wall < 5.0, (rc, wall, cap.err)
    err = cap.err.strip()
    assert "\n" not in err and f"--mavlink 'tcp:127.0.0.1:{port}': cannot connect" in err and "one attempt" in err, err
    assert "sleeping" not in cap.out + cap.err
    from fdm_awe.mavlink.transport import TCP_CONNECT_TIMEOUT_S

    fly_help = next(a.help for a in build_parser()._subparsers._group_actions[0].choices["fly"]._actions
                    if "--mavlink" in a.option_strings)
    assert f"one attempt, {TCP_CONNECT_TIMEOUT_S:g} s" in fly_help  # the help says the bound the link keeps


def test_a_tcp_ground_station_is_connected_before_the_work_and_released(no_work):
    """With a listening ground station, the connection is made once before the flight starts
    (the flight spy is reached with the connection accepted; the vehicle's boot heartbeat may
    go out on it meanwhile) and closed when the run ends."""
    from conftest import WorkStarted

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as srv:
        srv.bind(("127.0.0.1", 0))
        srv.listen(4)
        srv.settimeout(5.0)
        port = srv.getsockname()[1]
        with pytest.raises(WorkStarted):
            main(["fly", "--reference", str(REF), "--cycles", "1", "--quiet", "--mavlink", f"tcp:127.0.0.1:{port}"])
        peer, _ = srv.accept()  # made before the flight was called
        with peer:
            peer.settimeout(5.0)
            got = b""
            while chunk := peer.recv(4096):  # the boot heartbeat, if any, then closed when the run ended
                got += chunk
            assert got == b"" or got[0] == 0xFD, got[:16]  # nothing but MAVLink 2 frames
        srv.settimeout(0.2)
        with pytest.raises(socket.timeout):
            srv.accept()  # exactly one connection


@pytest.mark.parametrize("argv,why", [
    (["--reference", str(DATA / "ref_paper_foldable_3mps.json"), "--tether", "lumped:200"],
     "the paper scenario of " + str(DATA / "ref_paper_foldable_3mps.json")),
    (["--scenario", "paper", "--tether", "lumped:20"], "--scenario paper"),
], ids=["paper_reference", "scenario_paper"])
def test_a_lumped_line_on_the_paper_plant_is_refused_before_the_work(argv, why, no_work, capsys):
    """With the paper reference, lumped:200 exited 2 after 10 s with two lines; now one line
    before the optimisation or the flight (both spies)."""
    _refused(["fly", "--cycles", "1", *argv], capsys, f"--tether {argv[-1]}", "physical plant", why)
