"""The guidance step as pure functions: compiled by numba it gives exactly the numbers of the
same functions run as Python, over random states covering every branch; the gains vector and
the polar keep the layout and the numbers of the dataclass and the 6-DOF model's blend."""

import dis
import itertools
import math
import sys
from dataclasses import fields, replace

import numpy as np
import pytest

from fdm_awe.autopilot import guidance as gm
from fdm_awe import slots
from fdm_awe.autopilot.guidance import (CALLED, GIN, GK, INTEGRAL, blended_polar, guidance_step, polar_arguments,
                                       polar_at)
from fdm_awe.autopilot.guidance_loop import Guidance, GuidanceGains
from fdm_awe.definitions.aircraft import load_glider
from fdm_awe.pointmass.aero import fold_blend

GAINS = GuidanceGains(kp=0.6, kd=1.4, ki=0.05, a_max=15.0, int_max=2.0, alpha_min=-0.2, alpha_max=0.35, phi_max=1.2,
                      thrust_max=8.0, overspeed_tension=8.0, overspeed_margin=3.0)
#: the flags and NaN sentinels of the gains: (negative_lift, curv_scale_max, phi_max_vertical, thrust_on_body_axis)
VARIANTS = list(itertools.product((False, True), (None, 2.25), (None, 2.2), (False, True)))


def _compiled():
    """``guidance_step`` and ``polar_at`` compiled by numba (their calls registered as for the
    compiled loop), or a skip without numba."""
    numba = pytest.importorskip("numba", reason="numba is not installed: nothing to compile")
    from numba.extending import register_jitable

    for f in CALLED:
        register_jitable(f)
    return numba.njit(guidance_step), numba.njit(polar_at)


def _gains(variant) -> GuidanceGains:
    """The variant's gains; the underspeed protection on with negative lift (its alpha margin),
    the bank's fade near zero lift with the curvature scaling."""
    neg, curv, pv, body = variant
    return replace(GAINS, negative_lift=neg, curv_scale_max=curv, phi_max_vertical=pv, thrust_on_body_axis=body,
                   us_enter=1.1 if neg else 0.0, bank_lift=0.4 if curv else 0.0)


def _cases(rng, n):
    """``n`` random pairs (integral, the step's input row of :func:`guidance_step`, layout ``GIN``), plus
    edge cases (integral zero): no force across the air velocity, no airspeed."""
    g = load_glider()
    m, s_u, s_f = g.unfolded.mass.mass, g.unfolded.aero.S, g.folded.aero.S
    for i in range(n):
        pos = rng.normal(0.0, 80.0, 3) + np.array([0.0, 0.0, -60.0])
        vel = rng.normal(0.0, 12.0, 3)
        wind = np.array([rng.uniform(0.0, 12.0), rng.normal(0.0, 1.0), 0.0])
        if i % 10 == 3:  # vertical flight (air velocity straight up or down)
            vel, wind = np.array([0.0, 0.0, rng.choice([-15.0, 15.0])]), np.zeros(3)
        rp = pos + rng.normal(0.0, 5.0 if i % 3 else 40.0, 3)  # every third: a saturated correction
        rv = vel + rng.normal(0.0, 3.0, 3)
        ra = rng.normal(0.0, 15.0, 3)
        tf = rng.normal(0.0, 30.0, 3)
        t_max = (0.0, 3.0, 8.0)[i % 3]
        yield rng.uniform(-2.0, 2.0, 3), (m, 1.225, 9.81, s_u, s_f, *rp, *rv, *ra, float(rng.uniform(0.0, 60.0)), *pos,
                                          *vel, *wind, *tf, float(rng.uniform(0.0, 1.0)) if i % 4 else 0.0,
                                          float(rng.uniform(0.005, 0.3)), bool(i % 2), t_max, bool(i % 5 in (1, 2)),
                                          float(i % 9 % 4))
    level = (0.0, 0.0, -100.0)
    # F = m (a - g) = 0 along a level air velocity: no lift asked (mu 0)
    yield np.zeros(3), (m, 1.225, 9.81, s_u, s_f, *level, 15.0, 0.0, 0.0, 0.0, 0.0, 9.81, 0.0, *level, 15.0, 0.0, 0.0,
                        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.5, 0.01, False, 8.0, False, 0.0)
    # no airspeed (V held at 1 m/s, any horizontal axis), reference at rest in the air
    yield np.zeros(3), (m, 1.225, 9.81, s_u, s_f, *level, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 20.0, *level, 3.0, 0.0, 0.0,
                        3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.01, True, 8.0, False, 0.0)


def _lines_run(fn, calls):
    """Lines of the pure functions of the guidance module executed by ``fn`` over ``calls``."""
    seen = set()
    code_names = {f.__code__ for f in (guidance_step, *CALLED) if f.__module__ == gm.__name__}

    def tracer(frame, event, arg):
        if frame.f_code in code_names:
            if event == "line":
                seen.add((frame.f_code, frame.f_lineno))
            return tracer
        return None

    old = sys.gettrace()
    sys.settrace(tracer)
    try:
        for args in calls:
            fn(*args)
    finally:
        sys.settrace(old)
    want = {(c, ln) for c in code_names for _, ln in dis.findlinestarts(c) if ln is not None and ln > c.co_firstlineno}
    return seen, want


def test_gains_vector_layout():
    """``GK`` names the fields in their order; None is NaN, the flags 0.0/1.0."""
    names = [f.name for f in fields(GuidanceGains)]
    k = replace(GAINS, energy_trade=0.7, negative_lift=True, curv_scale_max=2.25, phi_max_vertical=2.2)
    v = k.vector()
    assert v.dtype == np.float64 and v.shape == (len(names),) == (slots.size(GK),)
    for i, name in enumerate(names):
        assert v[i] == float(getattr(k, name)), name
    assert [GK.kp, GK.thrust_max, GK.etrade, GK.phi_max_vert] == \
           [names.index(n) for n in ("kp", "thrust_max", "energy_trade", "phi_max_vertical")]
    v = GAINS.vector()
    assert math.isnan(v[GK.curvmax]) and math.isnan(v[GK.phi_max_vert])
    assert v[GK.neglift] == 0.0 and v[GK.body_axis] == 1.0


def test_polar_at_compiled_is_python_and_the_fold_blend():
    step, polar = _compiled()
    g = load_glider()
    u, f = g.unfolded.aero, g.folded.aero
    args = polar_arguments(u, f)
    for fold in (0.0, 1.0, *np.random.default_rng(7).uniform(0.0, 1.0, 200).tolist()):
        a = fold_blend(u, f, fold)
        want = (a.S * a.CL0, a.S * a.CLalpha, a.S * a.CLmax, a.S * a.CD0, a.S * a.CDalpha1, a.S * a.CDalpha2)
        assert polar(*args, fold) == polar_at(*args, fold) == want == blended_polar(u, f, fold)


def test_guidance_step_compiled_is_python_bit_for_bit():
    """Every variant of the flags and sentinels (negative lift, curvature scaling, vertical bank
    limit, thrust axis) over random states (taut and slack line, saturated corrections, the
    integral at its limit, the energy trade both ways, vertical flight, the thrust limit 0, the
    underspeed protection off, on and on a slack line, its alpha margin on and off, the ground
    guard's pull-up): the compiled step equals the Python step, result and integral, and the
    Python step runs every line of the pure functions."""
    step, _ = _compiled()
    g = load_glider()
    pargs = polar_arguments(g.unfolded.aero, g.folded.aero)
    rng = np.random.default_rng(19)
    calls, clipped = [], 0
    for variant in VARIANTS:
        gk = _gains(variant).vector()
        for integral, args in _cases(rng, 30):
            assert len(args) == slots.size(GIN)
            polar = polar_at(*pargs, args[GIN.fold])  # at the row's fold state
            i_py, i_nb = integral.copy(), integral.copy()
            got_py = guidance_step(gk.tolist(), i_py, polar, list(args))  # as Guidance.update calls it
            got_nb = step(gk, i_nb, np.array(polar), np.array(args, float))
            assert got_nb == got_py, (variant, args, got_nb, got_py)
            assert i_nb.tolist() == i_py.tolist()
            assert guidance_step(gk, integral.copy(), np.array(polar), np.array(args, float)) == got_py  # arrays too
            clipped += int(np.any(np.abs(i_py) == 2.0))
            calls.append((gk.tolist(), integral.copy(), polar, list(args)))
    assert clipped > 20  # the integral limit acted
    seen, want = _lines_run(guidance_step, calls)
    missed = sorted((c.co_name, ln) for c, ln in want - seen)
    assert not missed, f"lines never run: {missed}"


def test_the_folded_bank_fades_to_level_near_zero_lift_within_its_force_bound():
    """``bank_lift`` (GUID_MU_LIFT): level flight, the force asked across the air velocity only
    (no along-path force, no energy trade), its lift ``L`` from a thousandth of ``L0`` to ten
    times it, banked 0.3, 0.9 and -1.1 rad. Off (0), or with the wing open (fold 0), the bank
    is the lift's direction, as before; folded (fold 1, and half as much at fold 0.5: ``L0`` is
    0.4 weights times the fold state) it is that bank times ``L^2 / (L^2 + L0^2)``: same sign,
    smaller, below 1e-5 of it at a thousandth of ``L0``, within 1 % at ten times; the force
    flown misses the one asked by at most ``|bank| L0 / 2`` (N)."""
    g = load_glider()
    m, s_u, s_f = g.unfolded.mass.mass, g.unfolded.aero.S, g.folded.aero.S
    pargs = polar_arguments(g.unfolded.aero, g.folded.aero)
    weight = m * 9.81
    off = replace(GAINS, energy_trade=0.0).vector()
    on = replace(GAINS, energy_trade=0.0, bank_lift=0.4).vector()
    for fold in (0.0, 0.5, 1.0):
        polar = polar_at(*pargs, fold)
        L0 = 0.4 * weight * fold
        for mu_raw in (0.3, 0.9, -1.1):
            for r in (1e-3, 0.01, 0.1, 0.5, 1.0, 2.0, 10.0):
                L = r * 0.4 * weight * max(fold, 0.5)
                F = (0.0, L * math.sin(mu_raw), -L * math.cos(mu_raw))  # NED, level air velocity north
                args = (polar, 1.225, *F, 15.0, 0.0, 0.0, fold, s_u, s_f, 8.0, 0.0, False, False, weight)
                mu0 = gm._command(off, *args)[1]
                mu1 = gm._command(on, *args)[1]
                assert mu0 == pytest.approx(mu_raw, abs=1e-12)
                if fold == 0.0:
                    assert mu1 == mu0  # the open wing: the bank as asked, bit for bit
                    continue
                assert mu1 == pytest.approx(mu_raw * L * L / (L * L + L0 * L0), rel=1e-12)
                assert abs(mu1) <= abs(mu0) and mu1 * mu0 > 0.0
                miss = 2.0 * L * abs(math.sin(0.5 * (mu0 - mu1)))  # the lift's turn, N
                assert miss <= abs(mu_raw) * L0 / 2.0 + 1e-12, (fold, mu_raw, r, miss)
                if r <= 1e-3:
                    assert abs(mu1) < 1e-5 * abs(mu_raw)
                if r >= 10.0:
                    assert abs(mu1 - mu_raw) <= 0.01 * abs(mu_raw)


def test_guidance_update_is_the_step_and_follows_new_gains():
    """:meth:`Guidance.update` returns :func:`guidance_step` on its state; a gains object
    replaced between steps (a parameter change) is used at the next step; reset zeroes the
    integral in place."""
    from fdm_awe.autopilot.tracking import RefPoint

    g = load_glider()
    gd = Guidance(GAINS, g.unfolded.mass.mass, g.unfolded.aero, g.folded.aero)
    integral = gd.integral
    pos, vel = np.array([100.0, 10.0, -100.0]), np.array([3.0, 14.0, -1.0])
    ref = RefPoint(0.0, 0, 0, pos + np.array([2.0, 6.0, 1.0]), np.array([0.0, 15.0, 0.0]), np.array([0.0, 0.0, 3.0]),
                   15.0, 0.1, 0.0, 1.0, 40.0, 150.0, 0.0)
    wind, tf = np.array([6.0, 0.0, 0.0]), np.array([-20.0, -2.0, 15.0])
    for k in (GAINS, replace(GAINS, kp=0.9, negative_lift=True, phi_max_vertical=2.0)):
        gd.k = k
        mine = integral.copy()
        want = guidance_step(k.vector().tolist(), mine, gd.polar(0.3), [
            gd.m, gd.rho, gd.g, gd.aero_u.S, gd.aero_f.S, *ref.pos.tolist(), *ref.vel.tolist(), *ref.acc.tolist(),
            ref.tension, *pos.tolist(), *vel.tolist(), *wind.tolist(), *tf.tolist(), 0.3, 0.01, True, k.thrust_max,
            False, 0.0])
        c = gd.update(ref, pos, vel, wind, tf, 0.3, 0.01, taut=True)
        assert (c.alpha, c.mu, c.thrust, c.roll, c.pitch, c.yaw, c.lift_coefficient, c.pos_error) == want
        assert gd.integral is integral and integral.tolist() == mine.tolist() and integral[INTEGRAL.x] != 0.0
    gd.reset()
    assert gd.integral is integral and integral[INTEGRAL.x] == integral[INTEGRAL.z] == 0.0
