"""Co-simulation loop: tethered equilibrium against the point-mass equilibrium, the events that end
a run (each returns its status and the data so far), and the loop with the real ground station."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import fsolve

from sim_helpers import FixedLengthLine, LineOutput
from fdm_awe import ROOT
from fdm_awe.sim.result import COLUMNS
from fdm_awe.sim.loop import CoSim, Limits
from fdm_awe.definitions.xmlutil import XmlDoc
from fdm_awe.groundstation import WinchCommand
from fdm_awe.sixdof import JSBSimGlider, Stabilizer, Surfaces
from fdm_awe.units import FT, SLUG

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

ALPHA = 0.10436  # rad, best glide ratio of the unfolded glider
WIND = 14.0  # m/s from the south: a 0.738 kg kite needs more than its ~9 m/s minimum speed
LINE = 50.0  # m


class KiteHold(Stabilizer):
    """Stabilizer plus pendulum damping: the alpha command drops with the glider's velocity
    along the direction of increasing elevation (zero at equilibrium, so it does not move it)."""

    k_el = 0.03  # rad per m/s

    def __init__(self, glider, alpha0, **kw):
        super().__init__(glider, alpha_cmd=alpha0, psi_cmd=math.pi, **kw)
        self.alpha0 = alpha0

    def update(self, t, s, gs_output):
        x, y, z = s.x, s.y, s.z
        d = math.sqrt(x * x + y * y + z * z)
        h = math.hypot(x, y)
        e_up = np.array((x / h * z / d, y / h * z / d, -h / d))
        self.set_alpha_cmd(self.alpha0 - self.k_el * float(s.vel_ned @ e_up))
        return super().update(t, s, gs_output)


def _kite(name="glider_unfolded", elevation_deg=75.0, wind=WIND):
    g = JSBSimGlider(name, wind_ned=(wind, 0.0, 0.0))
    el = math.radians(elevation_deg)
    g.reset((LINE * math.cos(el), 0.0, -LINE * math.sin(el)), wind, gamma=0.0, psi=math.pi, alpha=ALPHA)
    return g


def _check_partial(res, t_start=0.0):
    """The data so far: one row per step plus the initial row, ending at the event."""
    assert len(res.t) == res.steps + 1 == res.data.shape[0]
    assert res.data.shape[1] == len(COLUMNS)
    assert np.all(np.diff(res.t) > 0)
    if res.event is not None:
        assert res.t[-1] == pytest.approx(res.event.t, abs=1e-9)
        assert res.status == res.event.kind and res.event.message


# ---------------------------------------------------------------------------------------------
def test_tethered_equilibrium_matches_the_point_mass_equilibrium():
    g = _kite()
    line = FixedLengthLine(LINE)
    res = CoSim(g, line, KiteHold(g, ALPHA)).run(40.0)
    assert res.status == "ok" and res.event is None
    _check_partial(res)
    last = slice(-120 * 5, None)
    x6, y6, z6 = res.x[last].mean(), res.y[last].mean(), res.z[last].mean()
    t6 = res.tension[last].mean()
    assert res.x[last].std() < 0.05 and res.tension[last].std() < 0.05  # settled
    # point-mass equilibrium at the same alpha: the glider is at rest, the air passes at the wind
    # speed; lift up, drag downwind, weight, and the line tension toward the winch balance.
    doc = XmlDoc.load(ROOT / "aircraft" / "glider_unfolded" / "glider_unfolded.xml")
    pm = {k: doc.property_value(f"aero/pm/{k}") for k in ("CL0", "CLalpha", "CD0", "CDalpha1", "CDalpha2")}
    S, m = doc.number("metrics/wingarea"), doc.number("mass_balance/emptywt")
    rho = g.fdm["atmosphere/rho-slugs_ft3"] * SLUG / FT**3
    grav = g.fdm["accelerations/gravity-ft_sec2"] * FT
    q = 0.5 * rho * WIND**2 * S
    L = q * (pm["CL0"] + pm["CLalpha"] * ALPHA)
    D = q * (pm["CD0"] + pm["CDalpha1"] * ALPHA + pm["CDalpha2"] * ALPHA**2)

    def residual(v):
        el, T = v
        return [D - T * math.cos(el), -L + m * grav + T * math.sin(el)]

    el, T = fsolve(residual, [1.3, 5.0], xtol=1e-12)
    d = LINE + T / line.k
    x_pm, z_pm = d * math.cos(el), -d * math.sin(el)
    # acceptance: position and tension within 5 %
    assert t6 == pytest.approx(T, rel=0.05)
    assert x6 == pytest.approx(x_pm, rel=0.05)
    assert z6 == pytest.approx(z_pm, rel=0.05)
    assert abs(y6) < 0.05 * d


def test_real_ground_station_holds_the_kite():
    gsmod = pytest.importorskip("fdm_awe.groundstation")
    g = _kite(elevation_deg=80.0)
    gs = gsmod.GroundStation(gsmod.load_ground_station(), wind_ned=(WIND, 0.0, 0.0))
    gs.reset(tether_length=LINE, reel_speed=0.0, mode="motor")
    hold = gsmod.WinchCommand(mode="motor", reel_speed_ref=0.0)
    res = CoSim(g, gs, KiteHold(g, ALPHA, winch=hold)).run(10.0)
    assert res.status == "ok"
    _check_partial(res)
    assert np.isfinite(res.tension[1:]).all() and res.tension[-120:].mean() > 1.0
    assert abs(res.length[-1] - LINE) < 0.5  # the speed loop holds the drum
    f = res.tether_force[-1]
    r = res.pos[-1]
    assert float(f @ r) < 0  # the line pulls toward the winch


# ---------------------------------------------------------------------------------------------
class Scripted:
    """Fixed surfaces; optionally raises KeyboardInterrupt after ``interrupt_at`` s."""

    def __init__(self, surfaces: Surfaces, interrupt_at: float | None = None):
        self.surfaces = surfaces
        self.interrupt_at = interrupt_at
        self.phase = "scripted"

    def update(self, t, s, o):
        if self.interrupt_at is not None and t >= self.interrupt_at:
            raise KeyboardInterrupt
        return self.surfaces, None


class NoLine:
    """A ground station that never pulls (slack line of any length)."""

    def step(self, dt, pos, vel, cmd):
        return LineOutput(np.zeros(3), 0.0, 1000.0)


class NaNLine(NoLine):
    def __init__(self, after_steps: int):
        self.n = after_steps

    def step(self, dt, pos, vel, cmd):
        self.n -= 1
        if self.n < 0:
            return LineOutput(np.array([math.nan, 0.0, 0.0]), math.nan, 1000.0)
        return super().step(dt, pos, vel, cmd)


def _glider(h=30.0, V=12.0, gamma=-0.07):
    g = JSBSimGlider("glider_unfolded")
    g.reset((0.0, 0.0, -h), V, gamma=gamma, psi=0.0)
    return g


def test_run_to_the_end_reports_ok_and_every_step():
    g = _glider()
    res = CoSim(g, NoLine(), Stabilizer(g, alpha_cmd=ALPHA)).run(1.0)
    assert res.status == "ok" and res.steps == 120
    _check_partial(res)
    assert res.t[-1] - res.t[0] == pytest.approx(1.0, abs=1e-9)
    assert res.phase[-1] == "hold"


def test_ground_contact_ends_the_run():
    g = _glider(h=3.0, gamma=-0.2)
    res = CoSim(g, NoLine(), Scripted(Surfaces(elevator=0.1))).run(20.0)
    assert res.status == "ground_contact"
    _check_partial(res)
    assert res.t[-1] < 10.0
    assert -res.z[-1] < 0.6  # CG within the contact geometry of the ground (wing tip half span)


def test_tether_break_ends_the_run():
    g = _kite()
    line = FixedLengthLine(LINE, break_at=3.0)  # below the ~5.7 N equilibrium tension
    res = CoSim(g, line, KiteHold(g, ALPHA)).run(20.0)
    assert res.status == "tether_break"
    _check_partial(res)
    assert res.tension[-1] > 3.0


def test_nonfinite_line_force_ends_the_run():
    g = _glider()
    res = CoSim(g, NaNLine(after_steps=30), Stabilizer(g, alpha_cmd=ALPHA)).run(5.0)
    assert res.status == "nonfinite"
    _check_partial(res)
    assert res.steps == 30 and np.isfinite(res.pos).all()


def test_airspeed_limit_ends_the_run():
    g = _glider(h=200.0)
    res = CoSim(g, NoLine(), Scripted(Surfaces(elevator=0.6)), limits=Limits(airspeed_max=16.0)).run(30.0)
    assert res.status == "airspeed_limit"
    _check_partial(res)
    assert res.airspeed[-1] > 16.0 and res.airspeed[-2] <= 16.0


def test_low_airspeed_limit_ends_the_run():
    g = _glider(h=200.0)
    res = CoSim(g, NoLine(), Scripted(Surfaces(elevator=-0.8)), limits=Limits(airspeed_min=8.0)).run(30.0)
    assert res.status == "airspeed_limit"
    assert res.airspeed[-1] < 8.0


def test_tension_load_limit_ends_the_run():
    g = _kite()
    res = CoSim(g, FixedLengthLine(LINE), KiteHold(g, ALPHA), limits=Limits(max_tension=4.0)).run(20.0)
    assert res.status == "load_limit" and "tension" in res.event.message
    _check_partial(res)
    assert res.tension[-1] > 4.0


def test_load_factor_limit_ends_the_run():
    g = _glider(h=200.0, V=20.0, gamma=0.0)
    res = CoSim(g, NoLine(), Scripted(Surfaces(elevator=-1.0)), limits=Limits(max_load_factor=2.5)).run(10.0)
    assert res.status == "load_limit" and "load factor" in res.event.message
    _check_partial(res)
    assert abs(res.load_factor[-1]) > 2.5


def test_interrupt_ends_the_run_with_the_data_so_far():
    g = _glider()
    res = CoSim(g, NoLine(), Scripted(Surfaces(), interrupt_at=0.5)).run(5.0)
    assert res.status == "interrupted"
    assert res.t[-1] == pytest.approx(0.5, abs=1.5 / 120)
    assert len(res.t) == res.steps + 1


def test_dt_must_match_the_glider():
    g = _glider()
    with pytest.raises(Exception, match="dt"):
        CoSim(g, NoLine(), Stabilizer(g, alpha_cmd=ALPHA), dt=0.01)


class PhaseInterrupted(Stabilizer):
    """A stabiliser whose phase read raises KeyboardInterrupt once after ``at`` s: Ctrl-C
    landing between a step's commands and its phase being logged."""

    def __init__(self, glider, at: float, **kw):
        super().__init__(glider, **kw)
        self.at, self.t, self.fired = at, 0.0, False

    @property
    def phase(self):
        if self.t >= self.at and not self.fired:
            self.fired = True
            raise KeyboardInterrupt
        return "hold"

    @phase.setter
    def phase(self, value):
        pass

    def update(self, t, s, gs_output):
        self.t = t
        surf, _ = super().update(t, s, gs_output)
        return surf, WinchCommand(mode="motor", reel_speed_ref=0.0)


def test_interrupt_between_the_records_of_a_step_keeps_whole_rows_in_both_loops():
    """Ctrl-C after a step was counted but before all its records were kept: both loops end
    with the rows every record has (every row with its phase), and alike."""
    from fdm_awe.groundstation import GroundStation, load_ground_station

    out = []
    for compiled in (False, True):
        g = _kite()
        gs = GroundStation(load_ground_station(), wind_ned=(WIND, 0.0, 0.0))
        gs.reset(tether_length=LINE, reel_speed=0.0, mode="motor")
        sim = CoSim(g, gs, PhaseInterrupted(g, 0.5, alpha_cmd=ALPHA, psi_cmd=math.pi),
                    limits=Limits(max_tension=200.0), compiled=None if compiled else False)
        res = sim.run(2.0, on_step=lambda k, s, o: None)
        assert res.status == "interrupted"
        _check_partial(res)
        assert res.t[-1] == pytest.approx(0.5, abs=1.5 / 120)
        assert all(p == "hold" for p in res.phase)  # no row without its phase
        out.append((sim.loop, res))
    (_, a), (loop, b) = out
    if loop == "compiled":
        assert a.steps == b.steps and np.array_equal(a.data, b.data, equal_nan=True)
