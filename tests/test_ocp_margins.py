"""Margins in the optimum: the cycle's tension bound below the line's rating (``tension_margin``)
and the stall margin (``cl_margin = 1 - stall margin``), on the optimiser, the reference file
and the command line."""

from __future__ import annotations

import json
import time
from dataclasses import replace

import numpy as np
import pytest

from fdm_awe.cli import main
from fdm_awe.errors import InputError
from fdm_awe.ocp.problem import Bounds, CycleProblem, Mesh
from fdm_awe.ocp.solve import solve_cycle
from fdm_awe.ocp.build import structure_key
from fdm_awe.trajectory import read_reference, write_reference
from fdm_awe.trajectory.files import margins_text

#: the rating of the Table-3 bound and the margin tested: the cycle's bound 50 / 1.25 = 40 N
RATING_N, MARGIN = 50.0, 0.25


def test_bounds_cycle_tension_is_the_rating_over_one_plus_margin():
    assert Bounds().G_cycle_max == Bounds().G_max == RATING_N  # no margin: the whole rating, exactly
    assert Bounds(tension_margin=MARGIN).G_cycle_max == pytest.approx(40.0, rel=1e-15)
    assert Bounds(cl_margin=0.85).stall_margin == pytest.approx(0.15, rel=1e-12)
    assert structure_key(CycleProblem(bounds=Bounds(tension_margin=MARGIN))) != structure_key(CycleProblem())


@pytest.mark.parametrize("value", [-0.1, 4.5, float("nan"), float("inf")])
def test_bad_tension_margin_is_one_line(value):
    with pytest.raises(InputError, match=r"tension_margin = .* out of range \(allowed 0 \.\. 4"):
        Bounds(tension_margin=value).validate()


def test_reference_optimised_with_a_margin_stays_below_its_bound_and_records_it(tmp_path):
    # the nominal 12 m/s cycle uses the whole 50 N rating without a margin (measured on this
    # mesh: it peaks at 50.0 N): with the margin its tension stays at 40 N along the cycle
    flyable = Bounds(cl_margin=0.85, phi_max=0.8)
    pr = CycleProblem(scenario="physical", config="nominal", wind_speed=12.0, mesh=Mesh(20, 12, 3),
                      bounds=replace(flyable, tension_margin=MARGIN)).validate()
    res = solve_cycle(pr)
    assert res.ok, (res.status, res.reason)
    bound = RATING_N / (1 + MARGIN)
    tension = np.asarray(res.columns["tension"], float)
    assert tension.max() <= bound * (1 + 1e-6), tension.max()
    assert tension.max() > 0.8 * bound  # the bound is what limits the generation, not something else
    path = write_reference(res, tmp_path / "ref.json")
    md = read_reference(path).metadata
    assert md["margins"] == pytest.approx({"tension_rating_N": RATING_N, "tension_margin": MARGIN,
                                           "tension_bound_N": bound, "stall_margin": 0.15, "cl_max_share": 0.85})
    assert md["bounds"]["tension_margin"] == MARGIN and md["line_model"] == "straight"
    assert "tension <= 40 N (rating 50 N, margin 0.25), C_L <= 0.85 C_Lmax (stall margin 0.15)" == margins_text(md)
    import io

    from fdm_awe.commands.optimize import print_summary

    out = io.StringIO()
    print_summary(res, file=out)
    assert "  margins: tension <= 40 N (rating 50 N, margin 0.25), C_L <= 0.85 C_Lmax" in out.getvalue()
    # without the margin the same cycle pulls harder than the margin allows: the bound acts
    res0 = solve_cycle(replace(pr, bounds=flyable).validate())
    assert res0.ok and np.max(res0.columns["tension"]) > bound + 3.0


def test_files_without_margins_say_what_their_bounds_give():
    # a stored file optimised without margins (the sized-line references carry fly's margins)
    md = read_reference("tests/data/ref_physical_nominal_8mps.json").metadata
    assert "margins" not in md
    assert margins_text(md).startswith("tension <= 50 N (rating 50 N, margin 0), C_L <= 0.85 C_Lmax")


def test_a_recorded_margin_out_of_range_is_refused(tmp_path):
    doc = json.loads(open("tests/data/ref_physical_nominal_8mps_sized.json").read())
    doc["metadata"]["margins"] = {"tension_rating_N": 50.0, "tension_margin": -1.0, "tension_bound_N": 50.0,
                                  "stall_margin": 0.15, "cl_max_share": 0.85}
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(doc))
    with pytest.raises(InputError, match=r"metadata\.margins\.tension_margin: -1\.0 not allowed \(allowed a number 0 \.\. 4\)"):
        read_reference(p)


def _refused(capsys, argv: list[str], *words: str) -> None:
    t0 = time.monotonic()
    rc = main(argv)
    err = capsys.readouterr().err.strip()
    assert rc == 2 and time.monotonic() - t0 < 10.0, (argv, rc, err)
    assert "\n" not in err and "error:" in err, err
    for w in words:
        assert w in err, (w, err)


@pytest.mark.parametrize("cmd", ["optimize", "fly"])
def test_bad_margin_options_are_one_line_errors(capsys, cmd):
    _refused(capsys, [cmd, "--tension-margin", "-0.5"], "--tension-margin -0.5", "allowed 0..4")
    _refused(capsys, [cmd, "--tension-margin", "nan"], "--tension-margin nan")
    _refused(capsys, [cmd, "--stall-margin", "0.8"], "--stall-margin 0.8", "allowed 0..0.7")
    _refused(capsys, [cmd, "--reel-in-margin", "1.5"], "--reel-in-margin 1.5", "allowed 0..1")


def test_fly_optimises_its_reference_with_its_margins():
    from fdm_awe.commands._fly_optimise import FLY_REEL_IN_MARGIN, flyable_bounds
    from fdm_awe.commands._bound_options import drive_reel_in_speed

    b = flyable_bounds()
    assert (b.G_cycle_max, b.cl_margin) == (pytest.approx(40.0), 0.85)
    assert FLY_REEL_IN_MARGIN == 0.0 and b.reel_in_speed_max is None  # off: the folded recovery needs the speed
    assert 11.05 < drive_reel_in_speed() < 11.15  # the 48 V drive's fastest reel-in ('fdm-awe info': 11.10 m/s)
    from fdm_awe.cli import build_parser
    from fdm_awe.commands._fly_optimise import reference_problem

    sub = build_parser()._subparsers._group_actions[0].choices  # noqa: SLF001 - argparse has no public accessor
    args = sub["fly"].parse_args(["--reel-in-margin", "0.1", "--tension-margin", "0"])
    args.scenario, args.config = "physical", "nominal"
    b1 = reference_problem(args).bounds
    assert b1.reel_in_speed_max == pytest.approx(drive_reel_in_speed() / 1.1, rel=1e-12)
    assert (b1.G_cycle_max, b1.cl_margin) == (50.0, 0.85)


def test_the_reel_in_margin_is_taken_from_the_drive_the_cycle_is_optimised_for():
    """With ``--supply-voltage`` the reel-in margin stands below that supply's fastest reel-in,
    not the definition's: a higher supply reels in faster (the armature's back-EMF limit). The
    definition's 48 V against a 24 V supply (the one of before)."""
    from fdm_awe.cli import build_parser
    from fdm_awe.commands._bound_options import drive_reel_in_speed
    from fdm_awe.commands.optimize import problem_from_args

    assert drive_reel_in_speed() > 1.9 * drive_reel_in_speed(24.0)  # twice the volts, a little more than twice the speed
    sub = build_parser()._subparsers._group_actions[0].choices  # noqa: SLF001 - argparse has no public accessor
    b24 = problem_from_args(sub["optimize"].parse_args(["--reel-in-margin", "0.1", "--supply-voltage", "24"])).bounds
    assert b24.reel_in_speed_max == pytest.approx(drive_reel_in_speed(24.0) / 1.1, rel=1e-12)
    b = problem_from_args(sub["optimize"].parse_args(["--reel-in-margin", "0.1"])).bounds
    assert b.reel_in_speed_max == pytest.approx(drive_reel_in_speed() / 1.1, rel=1e-12)


def test_fly_refuses_margins_with_a_reference(capsys):
    _refused(capsys, ["fly", "--reference", "tests/data/ref_physical_nominal_8mps_sized.json", "--tension-margin", "0.2"],
             "--tension-margin", "fixes this")


@pytest.mark.parametrize("name, shown, recorded", [
    # optimised with fly's margins (``optimize --flyable``): they are recorded in the file
    ("ref_physical_nominal_8mps_sized.json", "tension <= 40 N (rating 50 N, margin 0.25), C_L <= 0.85 C_Lmax",
     {"tension_rating_N": RATING_N, "tension_margin": MARGIN, "tension_bound_N": RATING_N / (1 + MARGIN),
      "stall_margin": 0.15, "cl_max_share": 0.85}),
    # optimised without margins: what its bounds give, and no recorded margins
    ("ref_physical_nominal_8mps.json", "tension <= 50 N (rating 50 N, margin 0), C_L <= 0.85 C_Lmax", None),
], ids=["with-margins", "without-margins"])
def test_fly_shows_the_margins_of_the_reference_it_loads(capsys, tmp_path, name, shown, recorded):
    rc = main(["fly", "--reference", f"tests/data/{name}", "--cycles", "1", "--quiet",
               "--json", str(tmp_path / "run.json")])
    err = capsys.readouterr().err
    assert rc == 0, err
    assert f"{name}: {shown} (stall margin 0.15); line model straight" in err
    doc = json.loads((tmp_path / "run.json").read_text())
    if recorded is None:
        assert doc["reference_margins"] is None
    else:
        assert doc["reference_margins"] == pytest.approx(recorded)
    assert doc["reference_line_model"] == "straight"


def test_sweep_points_carry_margins_and_line_model_and_keep_their_ids_by_default():
    from fdm_awe.commands import sweep as sweep_cmd
    from fdm_awe.sweep.runner import base_record, point_problem
    from fdm_awe.sweep.spec import SweepSpec

    plain = SweepSpec(winds=(8.0,), configs=("nominal",), mesh=Mesh(10, 8, 3))
    assert plain.points()[0].id == SweepSpec(winds=(8.0,), configs=("nominal",), mesh=Mesh(10, 8, 3),
                                             tension_margin=0.0, stall_margin=0.0, line_model="straight").points()[0].id
    p = replace(plain, tension_margin=MARGIN, stall_margin=0.15, line_model="calibrated").points()[0]
    assert p.id != plain.points()[0].id and "margins=0.25/0.15" in p.label() and "line_model=calibrated" in p.label()
    pr = point_problem(p)
    assert (pr.bounds.G_cycle_max, pr.bounds.cl_margin, pr.line_model) == (pytest.approx(40.0), 0.85, "calibrated")
    rec = base_record(p)
    assert (rec["tension_margin"], rec["stall_margin"], rec["line_model"]) == (MARGIN, 0.15, "calibrated")
    with pytest.raises(InputError, match=r"tension_margin = -1 out of range \(allowed 0 \.\. 4\)"):
        replace(plain, tension_margin=-1).validate()
    parser = __import__("argparse").ArgumentParser()
    sweep_cmd.add_arguments(parser)
    spec = sweep_cmd.build_spec(parser.parse_args(["--out", "x", "--wind", "8", "--config", "nominal", "--tension-margin",
                                                   "0.25", "--stall-margin", "0.15", "--line-model", "calibrated"]))
    assert (spec.tension_margin, spec.stall_margin, spec.line_model) == (0.25, 0.15, "calibrated")
    with pytest.raises(InputError, match=r"--stall-margin 0\.9 .*out of range"):
        sweep_cmd.build_spec(parser.parse_args(["--out", "x", "--stall-margin", "0.9"]))
