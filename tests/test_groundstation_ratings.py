"""The machine's and the converter's current ratings: the motor mode's current limit (a plugging
switch held at it, the braking path below duty 0, the PI without wind-up), the generator mode
against the peak rating, the ledger, the compiled and Python steps alike, the definition's
checks and the flight's rating numbers."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station
from fdm_awe.sim.events import EVENTS, machine_current
import test_groundstation_definitions as definitions
from test_groundstation_substeps import _pair, _run

P = load_ground_station(line="paper")
#: the station without the converter's force limit (a prescribed tension above it is braked by
#: the generator's law, not paid out: the motor mode's current limit under a steady pull)
NOFORCE = dataclasses.replace(P, converter=dataclasses.replace(P.converter, tension_limit=math.inf))
#: the same station without a converter current limit either (the behaviour before the ratings)
UNLIMITED = dataclasses.replace(NOFORCE, converter=dataclasses.replace(NOFORCE.converter, current_limit=math.inf))
GEN = WinchCommand("generator")
REEL_IN = WinchCommand("motor", reel_speed_ref=-3.0)


def _plugging(params, tension: float, dt: float = 1e-3):
    """Generation under a prescribed ``tension`` (N) for 3 s, then motor mode with the PI
    reeling in at 3 m/s under the same tension for 1 s (a step of 1 ms is one sub-step: every
    sub-step's current is seen). Returns the station, the pay-out speed at the switch (m/s) and
    the motor mode's currents (A) and duties."""
    gs = GroundStation(params)
    gs.reset(200.0, 0.0, "generator")
    for _ in range(int(round(3.0 / dt))):
        out = gs.step_with_tension(dt, tension, GEN)
    v_switch = out.reel_speed
    outs = [gs.step_with_tension(dt, tension, REEL_IN) for _ in range(int(round(1.0 / dt)))]
    return gs, v_switch, np.array([o.current for o in outs]), np.array([o.duty for o in outs])


def test_plugging_switch_at_fast_pay_out_is_held_at_the_limit():
    # 70 N: the drum pays out at 8.5 m/s when the PI takes over; without the limit the full
    # duty plus the back-EMF drive about 54 A through the armature
    _, v_switch, i_free, _ = _plugging(UNLIMITED, 70.0)
    gs, _, i, duty = _plugging(NOFORCE, 70.0)
    limit = P.converter.current_limit
    print(f"\nplugging at {v_switch:.2f} m/s pay-out: peak {i_free.max():.1f} A without the limit, "
          f"{i.max():.2f} A with it ({limit:g} A); duty down to {duty.min():.3f}, brake {gs.ledger.brake:.2f} J")
    assert v_switch > 8.0 and i_free.max() > 50.0
    assert i.max() <= limit * (1.0 + 1e-12)
    assert i.max() == pytest.approx(limit, rel=1e-12)  # held at it, not merely below
    assert limit < P.machine.peak_current
    # the EMF alone drives more than the limit: T2 opens too (duty < 0), the brake chopper burns it
    assert duty.min() < 0.0 and gs.ledger.brake > 0.0
    assert np.all(duty >= -1.0) and np.all(duty <= 1.0)
    assert gs.drivetrain.omega < 0.0  # and the drum reels in


def test_the_braking_path_has_its_bound():
    # 100 N pulls the drum out faster than even both switches open (-V_a) can hold at the limit:
    # the current is the EMF's, above the limit (the flight logs the rating)
    gs, _, i, duty = _plugging(NOFORCE, 100.0)
    assert duty.min() == -1.0 and i.max() > P.converter.current_limit
    assert gs.ledger.supply == 0.0 and gs.ledger.brake > 0.0


@pytest.mark.parametrize("tension", [50.0, 70.0, 100.0])
def test_ledger_closes_with_the_current_limit(tension):
    gs, _, _, _ = _plugging(NOFORCE, tension, dt=1 / 120)
    L = gs.ledger
    assert abs(L.residual()) <= 1e-9 * L.largest_term()
    assert L.numerical <= 5e-3 * L.largest_term()  # as the mode switch of the dynamics tests
    assert min(L.supply, L.brake, L.load, L.copper, L.semiconductor) >= 0.0


def test_pi_does_not_wind_up_against_the_current_limit():
    # reel-in commanded against 90 N: 22 A x K = 2.73 N m holds the drum with the Coulomb
    # friction (stuck at 0 rad/s) while the PI asks for more (error +100 rad/s); a wound-up
    # integrator would reach the duty limit (Ki x error x 1 s = 10). Then 5 N: reel-in at 3 m/s.
    gs, dt = GroundStation(P), 1 / 120
    gs.reset(200.0, 0.0, "motor")
    held = [(o.current, o.omega, o.duty, gs.drivetrain.integ)
            for o in (gs.step_with_tension(dt, 90.0, REEL_IN) for _ in range(120))]
    current, omega, duty, integ = np.array(held[60:]).T
    assert np.all(current == pytest.approx(P.converter.current_limit, rel=1e-12)) and np.all(omega == 0.0)
    assert np.all((duty > 0.0) & (duty < 1.0))  # the limit, not the duty range, holds the duty
    assert np.all(integ == integ[0]) and integ[0] < P.controller.duty_max  # the integrator stopped
    v = np.array([gs.step_with_tension(dt, 5.0, REEL_IN).reel_speed for _ in range(360)])
    overshoot = (np.max(-v) - 3.0) / 3.0
    settled = np.nonzero(np.abs(v + 3.0) > 0.06)[0]
    print(f"\nrelease after 1 s at the current limit: overshoot {100 * overshoot:.1f} %, "
          f"within 2 % after {(settled[-1] + 1) * dt:.3f} s")
    assert overshoot < 0.15
    assert (settled[-1] + 1) * dt < 0.5
    assert v[-1] == pytest.approx(-3.0, rel=1e-6)


@pytest.mark.parametrize("RL,d2", [(1.5, 0.0), (0.2, 0.8)])
def test_generator_passes_the_peak_current_only_beyond_twice_the_rated_tension(RL, d2):
    # steady generation: K i = r_w T - M_c - B omega whatever the load, so the passive
    # rectifier's current passes the peak rating only above about 105 N (the rated 50 N: 12 A);
    # with the converter's current limit in generator mode it stays at the limit there
    K, r, Mc, B = P.machine.k, P.winch.radius, P.winch.coulomb_friction, P.winch.viscous_friction
    cmd = WinchCommand("generator", load_resistance=RL, boost_duty=d2)
    currents, limited = {}, {}
    for T in (50.0, 100.0, 110.0):
        for params, into in ((UNLIMITED, currents), (NOFORCE, limited)):
            gs = GroundStation(params)
            gs.reset(200.0, 0.0, "generator")
            for _ in range(360):
                out = gs.step_with_tension(1 / 120, T, cmd)
            if params is UNLIMITED:
                assert K * out.current == pytest.approx(r * T - Mc - B * out.omega, rel=1e-6)
            into[T] = (out.current, out.reel_speed)
            assert abs(gs.ledger.residual()) <= 1e-9 * gs.ledger.largest_term()
    assert currents[50.0][0] < P.machine.rated_current
    assert currents[100.0][0] < P.machine.peak_current < currents[110.0][0]
    # below the converter's limit the same; above it (from about 95 N: K i_lim / r_w + M_c / r_w)
    # the converter holds the limit, the drum turns faster (pays out faster), the current stays
    # below the peak rating
    assert limited[50.0] == currents[50.0]
    for T in (100.0, 110.0):
        assert currents[T][0] > P.converter.current_limit
        assert limited[T][0] == pytest.approx(P.converter.current_limit, rel=1e-9)
        assert limited[T][1] > currents[T][1]


def _catch(params, v_out: float = 12.0, dt: float = 1 / 120):
    """A catch: the glider runs out along the line at ``v_out`` m/s, 0.3 m of slack on a standing
    drum in generator mode (default load), for 1.5 s. Returns the station and the step outputs'
    tensions (N) and currents (A)."""
    gs = GroundStation(params)
    gs.reset(200.3, 0.0, "generator")
    u = np.array([math.cos(math.radians(30.0)), 0.0, -math.sin(math.radians(30.0))])
    outs = [gs.step(dt, tuple(u * (200.0 + v_out * k * dt)), tuple(u * v_out), GEN) for k in range(int(1.5 / dt))]
    return gs, np.array([o.tension for o in outs]), np.array([o.current for o in outs])


def test_the_force_limit_pays_out_a_catch_instead_of_braking_it():
    # the upper-force controller (converter/tension_limit, 50 N, the line's rating) lowers the
    # generator's current limit above the tension limit every sub-step: the snatch of a catch at
    # 12 m/s on a standing drum is paid out, not braked (the rest is the drum's inertia and
    # friction); the same catch without it passes the peak current
    gs0, t0, i0 = _catch(NOFORCE)
    gs, t, i = _catch(P)
    print(f"\ncatch at 12 m/s: peak tension {t0.max():.1f} -> {t.max():.1f} N, current {i0.max():.1f} -> "
          f"{i.max():.1f} A, steady {t0[-1]:.1f} -> {t[-1]:.1f} N")
    limit = P.converter.tension_limit
    assert t0[-1] > limit + P.converter.tension_limit_band  # the generator's law alone brakes above the band
    assert t[-1] <= limit + P.converter.tension_limit_band  # the limit holds the steady pull in its band
    assert t.max() < t0.max() - 5.0
    assert i.max() <= P.converter.current_limit * (1.0 + 1e-12) < P.machine.peak_current
    for g in (gs0, gs):
        assert abs(g.ledger.residual()) <= 1e-9 * g.ledger.largest_term()
        assert min(g.ledger.load, g.ledger.copper, g.ledger.semiconductor) >= 0.0


def test_compiled_and_python_steps_alike_under_the_force_limit():
    dt = 1 / 120
    st = _pair()
    for g in st:
        g.reset(200.3, 0.0, "generator")
    u = np.array([math.cos(math.radians(30.0)), 0.0, -math.sin(math.radians(30.0))])
    steps = [(dt, tuple((u * (200.0 + 12.0 * k * dt)).tolist()), tuple((u * 12.0).tolist()), GEN) for k in range(180)]
    steps += [(dt, 110.0, GEN)] * 60  # held at the current limit under a prescribed pull
    assert _run(st, steps) == len(steps)
    assert st[1].drivetrain.current <= P.converter.current_limit


def test_compiled_and_python_steps_alike_under_the_limit():
    dt = 1 / 120
    st = _pair()
    for g in st:
        g.reset(200.0, 0.0, "generator")
    steps = [(dt, 70.0, GEN)] * 240 + [(dt, 70.0, REEL_IN)] * 120  # plugging, braking below duty 0
    steps += [(dt, 100.0, REEL_IN)] * 60 + [(dt, 90.0, REEL_IN)] * 60  # beyond the braking path; held
    steps += [(dt, 5.0, WinchCommand("motor", duty=1.0))] * 60  # open-loop duty, limited spin-up
    assert _run(st, steps) == len(steps)
    assert st[1].ledger.brake > 0.0
    st = _pair()
    for g in st:
        g.reset(3.0, 0.0, "motor")  # a limited spin-up into the end stop
    steps = [(dt, (0.5, 0.0, -0.5), (0.0, 0.0, 0.0), WinchCommand("motor", duty=1.0))] * 120
    assert _run(st, steps) == len(steps)
    st = _pair()
    for g in st:
        g.reset(200.0, 0.0, "generator")
    u = np.array([math.cos(math.radians(30.0)), 0.0, -math.sin(math.radians(30.0))])
    steps = []
    for k in range(480):  # through the line: the glider runs away at 9 m/s, then the PI reels in
        pos = u * (200.0 + 9.0 * min(k, 240) * dt)
        steps.append((dt, tuple(pos.tolist()), tuple((u * (9.0 if k < 240 else 0.0)).tolist()),
                      GEN if k < 240 else REEL_IN))
    assert _run(st, steps) == len(steps)


@pytest.mark.parametrize(
    "old,new,element,words",
    [
        ('<rated_current unit="A"> 12.1 </rated_current>', '<rated_current unit="A"> 0 </rated_current>',
         "dc_machine/rated_current", "> 0"),
        ('<rated_current unit="A"> 12.1 </rated_current>', '<rated_current unit="A"> 30 </rated_current>',
         "dc_machine/peak_current", ">= dc_machine/rated_current 30 A"),
        ('<peak_current unit="A"> 24.2 </peak_current>', '<peak_current unit="A"> 20 </peak_current>',
         "converter/current_limit", "<= dc_machine/peak_current 20 A"),
        ('<current_limit unit="A"> 22.0 </current_limit>', '<current_limit unit="A"> -1 </current_limit>',
         "converter/current_limit", "> 0"),
        ('<current_limit unit="A"> 22.0 </current_limit>', '<current_limit unit="A"> inf </current_limit>',
         "converter/current_limit", "finite"),
        ('<peak_current unit="A"> 24.2 </peak_current>', '<peak_current unit="MA"> 24.2 </peak_current>',
         "dc_machine/peak_current", "unit"),
        ('<current_limit unit="A"> 22.0 </current_limit>', '', "converter/current_limit", "missing"),
    ],
)
def test_a_bad_rating_is_refused_in_one_line(tmp_path, old, new, element, words):
    definitions.test_bad_file_gives_one_line_error(tmp_path, old, new, element, words)  # file, element, range


def test_ratings_follow_the_rated_tension():
    # rated current: the rated line tension on the drum (Table 3's 50 N, Table 1's r_w and K)
    assert P.machine.rated_current == pytest.approx(50.0 * P.winch.radius / P.machine.k, abs=0.05)
    assert P.machine.peak_current == pytest.approx(2.0 * P.machine.rated_current)
    assert P.machine.rated_current < P.converter.current_limit <= P.machine.peak_current


def test_machine_current_of_a_log():
    t = np.arange(8) * 0.5
    i = np.array([np.nan, 5.0, 13.0, 30.0, 26.0, 10.0, 25.0, 12.0])
    peak, above, events = machine_current(t, i, 12.1, 24.2)
    assert peak == 30.0
    assert above == pytest.approx(4 * 0.5)  # the steps ending at 13, 30, 26 and 25 A
    assert [e[0] for e in events] == [1.5, 3.0]  # one event per excursion above the peak, at its start
    assert events[0][1] == EVENTS[12].message.format(current=30.0, peak_current=24.2)
    assert "30.0 A above the machine's peak rating 24.2 A" in events[0][1]
    assert EVENTS[12].name == "machine_current" and EVENTS[12].status == "ok"  # logged, the flight goes on
    peak, above, events = machine_current(t, np.full(8, np.nan), 12.1, 24.2)  # no current logged
    assert math.isnan(peak) and above == 0.0 and events == []
