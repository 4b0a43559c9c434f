"""The attitude law as one source: :func:`law_commands` compiled by numba gives exactly the
numbers Python gives (inversion on and off, bank integral on and off, saturations, NaN,
integrator clipping), and :class:`AttitudeLaw` delegates to it (its coefficient vector refreshed
with the fold state)."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from fdm_awe.sixdof import attitude_law as L
from fdm_awe.sixdof.attitude_law import AttitudeLaw, StabilizerGains, law_commands

from attitude_helpers import Glider, random_coef, state


def _random_inputs(rnd: random.Random, k: int) -> list[float]:
    """(qbar, vt, alpha, beta, p, q, r, alpha_cmd, e_phi, p_ref, q_ref, r_ref, dt): flight
    values, some below the limits of 1 (qbar, vt), some far off (saturating), some NaN."""
    v = [rnd.uniform(0.0, 500.0) if k % 7 else rnd.uniform(-1.0, 1.5), rnd.uniform(0.0, 45.0) if k % 5 else 0.5,
         rnd.uniform(-0.2, 0.4), rnd.uniform(-0.2, 0.2), rnd.uniform(-2, 2), rnd.uniform(-2, 2), rnd.uniform(-2, 2),
         rnd.uniform(0.0, 0.3), rnd.uniform(-3.0, 3.0), rnd.uniform(-1, 1), rnd.uniform(-1, 1), rnd.uniform(-1, 1),
         rnd.choice((0.0, 1 / 120, rnd.uniform(0.0, 1.0)))]
    if k % 4 == 0:  # small errors: deflections inside the limits
        v[7], v[8] = v[2] + rnd.uniform(-0.01, 0.01), rnd.uniform(-0.02, 0.02)
        v[4:7] = [rnd.uniform(-0.05, 0.05) for _ in range(3)]
        v[9:12] = v[4:7]
    if k % 31 == 0:
        v[rnd.choice((2, 3, 4, 6))] = math.nan
    return v


def _gains(rnd: random.Random) -> tuple[float, ...]:
    g = StabilizerGains(w_alpha=rnd.uniform(3, 8), z_alpha=rnd.uniform(0.5, 1.0), ki_alpha=rnd.choice((0.0, 0.3)),
                        w_phi=rnd.uniform(3, 7), z_phi=rnd.uniform(0.5, 1.0), ki_phi=rnd.uniform(0.0, 2.0),
                        w_r=rnd.uniform(1, 4), k_beta=rnd.uniform(0.0, 1.5))
    assert np.array_equal(g.vector(), np.array(g.law_gains())) and g.vector().dtype == np.float64
    return g.law_gains()


def test_law_commands_compiled_equals_python_on_every_branch():
    """Bit for bit on random inputs: commands and the updated integrators; every saturation,
    NaN -> 0, the integrators' limits and both flags reached."""
    numba = pytest.importorskip("numba", reason="numba is not installed: nothing compiled to compare")
    from numba.extending import register_jitable

    from fdm_awe.sixdof.attitude_law import surface_deflections

    register_jitable(surface_deflections)
    jit = numba.njit(law_commands)
    rnd = random.Random(3)
    seen = set()
    for k in range(800):
        invert, bank_integral = k % 2 == 0, (k // 2) % 2 == 0
        c, gains, x = random_coef(rnd, invert), _gains(rnd), _random_inputs(rnd, k)
        integ = [rnd.uniform(-0.6, 0.6), rnd.uniform(-0.6, 0.6)]
        py_integ = list(integ)
        py = law_commands(c, gains, *x, py_integ, invert, bank_integral)
        jit_integ = np.array(integ)
        out = jit(np.array(c), np.array(gains), *x, jit_integ, invert, bank_integral)
        assert out == py and type(out[0]) is float
        assert jit_integ.tolist() == py_integ
        if not bank_integral:
            assert py_integ[L.INTEG.phi] == integ[L.INTEG.phi]
        for v in py:
            seen.add("+1" if v == 1.0 else "-1" if v == -1.0 else "0" if v == 0.0 else "in")
        if any(v != v for v in x):
            assert all(-1.0 <= v <= 1.0 for v in py)  # NaN became 0 (or a limit)
            seen.add("nan")
        seen.update(f"ia{v:+}" for v in (py_integ[L.INTEG.alpha],) if abs(v) == 0.2)
        seen.update(f"ip{v:+}" for v in (py_integ[L.INTEG.phi],) if abs(v) == 0.5 and bank_integral)
    assert seen >= {"+1", "-1", "0", "in", "nan", "ia+0.2", "ia-0.2", "ip+0.5", "ip-0.5"}, seen


@pytest.mark.parametrize("invert, bank_integral", [(False, True), (True, False)])
def test_the_law_class_delegates_and_refreshes_with_the_foldstate(invert, bank_integral):
    """``AttitudeLaw.commands`` gives :func:`law_commands` of its coefficient vector and the
    state's SI values; the vector is re-read when the fold state moves by 1e-3, after
    ``invalidate``; ``reset`` zeroes the integrators."""
    rnd = random.Random(9)
    gl = Glider()
    law = AttitudeLaw(gl, StabilizerGains(), invert_free_moments=invert, bank_integral=bank_integral)
    integ = [0.0, 0.0]
    reads = 0
    for k, fold in enumerate((0.0, 0.0005, 0.0012, 0.5, 0.5004, 1.0)):
        gl.fold = fold
        s = state(fold, rnd)
        out = law.commands(s, 0.1, 0.2, 0.01, 0.02, 0.03, 1 / 120)
        c = law.coef.tolist()
        assert out == law_commands(c, StabilizerGains().law_gains(), s.qbar, s.airspeed, s.alpha, s.beta, s.p, s.q,
                                   s.r, 0.1, 0.2, 0.01, 0.02, 0.03, 1 / 120, integ, invert, bank_integral)
        assert law.integ.tolist() == integ
        refreshed = gl.reads > reads
        reads = gl.reads
        assert refreshed == (k in (0, 2, 3, 5))
        assert c[L.COEF.cm_de] == -1.1 * (1.0 + 0.3 * law.fold_at[0])
        assert math.isnan(c[L.COEF.cm0]) != invert and math.isnan(c[L.COEF.de_trim]) == invert
    law.invalidate()
    law.commands(s, 0.1, 0.2, 0.0, 0.0, 0.0, 0.0)
    assert gl.reads > reads
    law.reset()
    assert law.integ.tolist() == [0.0, 0.0]
