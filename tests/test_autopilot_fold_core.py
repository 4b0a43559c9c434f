"""The fold command's pure function (:func:`fdm_awe.autopilot.fold.fold_command`, with the fold
law :func:`fdm_awe.pointmass.fold.fold_fraction`): compiled by numba it gives the Python call's
bits under both laws (the reference's fold time, the FOLD_LEAD/UNFOLD_LEAD switch); the fold
law is the one the optimiser's model calls."""

from __future__ import annotations

import math
import random

from jit_helpers import compiled, same_bits

from fdm_awe.autopilot.fold import fold_command
from fdm_awe.ocp import model
from fdm_awe.pointmass.fold import fold_fraction


def _cases(rnd: random.Random):
    """(t_cycle, T1, period, fold_time_s, fold_lead_s, unfold_lead_s): random cycles with and
    without a fold time, at and one ulp around every switch of both laws."""
    for k in range(600):
        T1 = rnd.uniform(5.0, 40.0)
        period = T1 + rnd.uniform(6.0, 30.0)
        ft = 0.0 if k % 3 == 0 else rnd.choice((rnd.uniform(0.3, 3.0), 2.0))
        lead, unlead = rnd.uniform(0.0, 2.0), rnd.uniform(0.0, 3.0)
        edges = [T1, T1 - lead, period - unlead, T1 + ft, period - ft, period, 0.0]
        for x in [rnd.uniform(-1.0, period + 1.0), *edges[k % 7: k % 7 + 1]]:
            for y in (x, math.nextafter(x, -math.inf), math.nextafter(x, math.inf)):
                yield y, T1, period, ft, lead, unlead


def test_fold_command_compiled_equals_python_both_laws():
    jit = compiled(fold_command, fold_fraction)
    rnd = random.Random(23)
    seen = set()
    for args in _cases(rnd):
        py = fold_command(*args)
        assert same_bits(jit(*args), py), (args, py)
        seen.add((args[3] > 0.0, py if py in (0.0, 1.0) else "ramp"))
    # both laws, each with its open and folded commands, and the ramp of the fold time's law
    assert seen == {(False, 0.0), (False, 1.0), (True, 0.0), (True, 1.0), (True, "ramp")}


def test_fold_fraction_compiled_equals_python_and_is_the_models():
    assert vars(model)["fold_fraction"] is fold_fraction  # one law: the optimiser's model calls this one
    jit = compiled(fold_fraction)
    rnd = random.Random(29)
    for k in range(400):
        T2, ft = rnd.uniform(4.0, 30.0), (0.0, -1.0, 2.0, rnd.uniform(0.1, 2.0))[k % 4]
        t = rnd.choice((rnd.uniform(-1.0, T2 + 1.0), 0.0, ft, T2 - ft, T2))
        py = fold_fraction(t, T2, ft)
        assert same_bits(jit(t, T2, ft), py) and 0.0 <= py <= 1.0, (t, T2, ft)
        assert type(py) is float and py == float(min(1.0, max(0.0, min(t, T2 - t) / ft)) if ft > 0.0 else 1.0)
