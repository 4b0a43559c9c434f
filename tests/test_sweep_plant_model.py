"""Sweeps and compare with the optimiser's plant-model options (--propeller, --line-weight):
the points carry them into their problems, their ids change only when the options do."""

from __future__ import annotations

import argparse

import pytest

from fdm_awe.commands import compare as compare_cmd
from fdm_awe.commands import sweep as sweep_cmd
from fdm_awe.errors import InputError
from fdm_awe.ocp.problem import Mesh
from fdm_awe.sweep.runner import base_record, point_problem
from fdm_awe.sweep.spec import Point, SweepSpec


def test_points_carry_the_plant_model_and_keep_their_ids_by_default():
    base = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), mesh=Mesh(10, 8, 3))
    plant = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), mesh=Mesh(10, 8, 3), propeller="engine", line_weight=True)
    momentum = SweepSpec(winds=(6.0, 8.0), configs=("nominal",), mesh=Mesh(10, 8, 3), propeller="momentum")
    pb, pp, pm = base.points(), plant.points(), momentum.points()
    # ids of default points are those of points built without the new fields (stored sweeps resume)
    assert [p.id for p in pb] == [Point(p.scenario, p.config, p.wind, p.d0, p.d_tf, mesh=p.mesh).id for p in pb]
    assert [p.id for p in pm] == [p.id for p in pb]  # "momentum" is the default model
    assert not {p.id for p in pp} & {p.id for p in pb}
    pr = point_problem(pp[0])
    assert pr.propeller == "engine" and pr.line_weight is True and pr.scenario_spec.propeller == "engine"
    rec = base_record(pp[0])
    assert rec["propeller"] == "engine" and rec["line_weight"] is True
    assert base_record(pb[0])["propeller"] == "momentum"


def test_plant_model_only_for_the_physical_scenario():
    with pytest.raises(InputError, match="only the physical scenario"):
        SweepSpec(winds=(3.0,), scenario="paper", line_weight=True).validate()
    with pytest.raises(InputError, match="propeller 'x' unknown"):
        SweepSpec(winds=(3.0,), propeller="x").validate()


def test_command_lines_take_the_options():
    p = argparse.ArgumentParser()
    sweep_cmd.add_arguments(p)
    args = p.parse_args(["--out", "x", "--wind", "8", "--config", "nominal", "--propeller", "engine", "--line-weight"])
    spec = sweep_cmd.build_spec(args)
    assert spec.propeller == "engine" and spec.line_weight is True
    c = argparse.ArgumentParser()
    compare_cmd.add_arguments(c)
    a = c.parse_args(["--propeller", "engine", "--line-weight"])
    assert a.propeller == "engine" and a.line_weight is True


def test_compare_report_names_the_plant_model():
    res = {c: {"status": "failed", "reason": "x", "T1_s": None, "T2_s": None, "E_generated_J": None, "E_thrust_J": None,
               "E_reel_in_J": None, "E_net_J": None, "P_avg_W": None} for c in ("nominal", "foldable")}
    text = compare_cmd.markdown("physical", 8.0, res, None, 1.0, "engine", True)
    assert "6-DOF glider's own drive" in text and "line's weight" in text
    assert "plant model" not in compare_cmd.markdown("physical", 8.0, res, None)
