"""The line-model registry (fdm_awe.groundstation.linemodels): every entry parses, builds a
station and flies the compiled co-simulation step as the Python loop does, bit for bit.

- ``--tether`` is parsed once into a :class:`TetherModel`; a station and a flight take the object
  or its form alike; one one-line error names the option and every form of every entry.
- the compiled kernel dispatches on the entry's code held in the station's constants (not on
  the length of an array): every entry, flown by a stabiliser for 2 s on 50 m of line in 14 m/s
  wind, gives the Python loop's rows, glider state and station state bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from fdm_awe.errors import InputError
from fdm_awe.jitcache import jit_off
from fdm_awe.groundstation import GroundStation, WinchCommand, load_ground_station
from fdm_awe.groundstation.linemodels import LINE_MODELS, TetherModel, allowed_forms, parse_tether
from fdm_awe import slots
from fdm_awe.groundstation.substeps import STATION, STEP
from fdm_awe.sim.loop import CoSim, Limits
from fdm_awe.sixdof import JSBSimGlider, Stabilizer

pytestmark = pytest.mark.filterwarnings("ignore::PendingDeprecationWarning")

EXAMPLES = [k.example for k in LINE_MODELS]
ALPHA = 0.10436  # rad, best glide of the unfolded glider
WIND = 14.0  # m/s
LINE = 50.0  # m
HOLD = WinchCommand(mode="motor", reel_speed_ref=0.0)


def test_registry_codes_names_and_forms() -> None:
    assert [k.code for k in LINE_MODELS] == list(range(len(LINE_MODELS)))
    assert len({k.name for k in LINE_MODELS}) == len(LINE_MODELS)
    for k in LINE_MODELS:
        m = parse_tether(k.example)
        assert isinstance(m, TetherModel) and m.kind is k and str(m) == k.example
        assert parse_tether(m) is m  # an object passes through: parsed once, handed down
        assert k.doc and "\n" not in k.doc


@pytest.mark.parametrize("bad", ["", "Straight", "straight:1", "lumped", "lumped:1", "lumped:201", "curved", 3, None,
                                 "rigid:2", "lumped:10 "])
def test_one_error_names_the_option_and_every_form(bad: object) -> None:
    with pytest.raises(InputError) as e:
        parse_tether(bad)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("--tether ") and allowed_forms() in msg
    assert all(k.forms in msg for k in LINE_MODELS)
    with pytest.raises(InputError, match="^--fly-tether "):
        parse_tether(bad, "--fly-tether")


@pytest.mark.parametrize("form", EXAMPLES)
def test_station_takes_the_model_or_its_form_alike(form: str) -> None:
    """The constants carry the entry's code, the state array the entry's block; a station built
    from the parsed object steps exactly as one built from the form."""
    gsp = load_ground_station(line="sized")
    model = parse_tether(form)
    out = []
    for tether in (model, form):
        gs = GroundStation(gsp, wind_ned=(6.0, 0.0, 0.0), tether=tether)
        assert gs.line == model and gs.tether == form
        assert gs._sc[STATION.line] == model.code and slots.size(STATION) == STATION.line + 1
        assert gs._s_all.shape[0] == slots.size(STEP) + model.state_size()
        d = 120.0
        gs.reset(gs.unstretched_length(d, 20.0), 0.0, "generator")
        rows = []
        for k in range(60):
            o = gs.step(1 / 120, (0.6 * d, 0.0, -0.8 * d - 0.01 * k), (0.0, 0.0, -1.2), WinchCommand("generator"))
            rows.append([o.tension, o.length, o.omega, o.current, *o.force_xyz])
        out.append(np.array(rows))
    assert np.array_equal(out[0], out[1])
    assert np.all(np.isfinite(out[0])) and out[0][-1, 0] > 0.0


def _numba_expected() -> bool:
    return jit_off() is None


@pytest.mark.parametrize("form", EXAMPLES)
def test_compiled_kernel_flies_every_model_as_the_python_loop(form: str) -> None:
    if not _numba_expected():
        pytest.skip(f"compiled loop not available here: {jit_off()}")
    out = []
    for compiled in (False, True):
        g = JSBSimGlider("glider_foldable", wind_ned=(WIND, 0.0, 0.0))
        el = math.radians(80.0)
        g.reset((LINE * math.cos(el), 0.0, -LINE * math.sin(el)), WIND, gamma=0.0, psi=math.pi, alpha=ALPHA)
        gs = GroundStation(load_ground_station(), wind_ned=(WIND, 0.0, 0.0), tether=parse_tether(form))
        gs.reset(tether_length=LINE, reel_speed=0.0, mode="motor")
        sim = CoSim(g, gs, Stabilizer(g, alpha_cmd=ALPHA, psi_cmd=math.pi, winch=HOLD),
                    limits=Limits(max_tension=400.0), compiled=compiled)
        res = sim.run(2.0)
        if compiled and sim.loop != "compiled":
            if _numba_expected():
                pytest.fail(f"numba is installed but the compiled loop does not run: {sim.loop_reason}")
            pytest.skip(f"compiled loop not available here: {sim.loop_reason}")
        out.append((res, g, gs))
    (ra, ga, gsa), (rb, gb, gsb) = out
    assert ra.status == rb.status == "ok" and ra.steps == rb.steps == 240
    assert np.array_equal(ra.data, rb.data, equal_nan=True)
    assert ga.raw() == gb.raw()
    assert np.array_equal(gsa._s_all, gsb._s_all)
    assert float(np.nanmax(ra.tension)) > 1.0  # the line carried the kite
