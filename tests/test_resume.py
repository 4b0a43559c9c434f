"""After a lull: the glider parked by the lost-path failsafe goes back to its cycle when the
onboard wind estimate says the wind is back (FS_RESUME, FS_RESUME_SHR; :mod:`fdm_awe.sim.resume`),
and stays parked when the path was lost in a good wind or the return is off."""

from __future__ import annotations

import numpy as np

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly
from fdm_awe.turbulence import Turbulence

from flight_helpers import DATA

FOLD8 = DATA / "ref_physical_foldable_8mps_sized.json"
NOM8 = DATA / "ref_physical_nominal_8mps_sized.json"


def _fly(path, params: dict[str, float], **kw):
    ref = TrackingReference.from_ocp_file(path)
    h: dict = {}

    def setup(ap, sim):
        h["ap"] = ap
        for name, value in params.items():
            assert ap.params.try_set(name, value)[0]

    rep = fly(ref, config=ref.meta["config"], setup=setup, **kw)
    return rep, h["ap"]


def test_the_wind_back_after_a_lull_the_glider_flies_its_cycles_again():
    """Foldable, 8 m/s, IEC class A seed 10 (the one flight of the real-wind grid's 60 in IEC
    class A that parked): a lull of 4 m/s for 20 s throws the glider 66 m off its path in its
    third cycle and the failsafe parks it in the hold (the gusts forbid the landing). With the
    return off (FS_RESUME 0) the flight ends there, parked after 2 of 3 cycles, its message
    naming the lull. With the return on (the default) the hold's wind estimate over 20 s finds
    the wind back (at least 0.9 x 8 m/s), AUTO rejoins the cycle and all 3 cycles are flown,
    without ground contact. The estimate that sent it back is the wind the glider met: within
    15 % of JSBSim's true mean horizontal wind at the glider over the same 20 s (the estimate
    reads the pitot, the attitude and the GPS only; 15 %: a 20 s window is half a hold circle,
    and the hold is flown in the turbulence's gusts)."""
    turb = Turbulence.parse("iec:A:10")
    off, ap_off = _fly(FOLD8, {"FS_RESUME": 0.0}, cycles=3, turbulence=turb)
    assert off.status == "parked", off.message
    assert sum(c.complete for c in off.cycles) == 2
    assert "a lull:" in off.message and "FS_TRK_ERR" in off.message
    assert not any(m.startswith("wind back") for _, m in ap_off.log)

    rep, ap = _fly(FOLD8, {}, cycles=3, turbulence=turb)
    assert ap.params["FS_RESUME"] == 20.0 and ap.params["FS_RESUME_SHR"] == 0.9
    assert rep.status == "ok", rep.message
    assert sum(c.complete for c in rep.cycles) == 3
    notes = [(t, m) for t, m in ap.log]
    t_fs = [t for t, m in notes if m.startswith("failsafe")]
    back = [(t, m) for t, m in notes if m.startswith("wind back")]
    assert t_fs and back and back[0][0] > t_fs[0] + 20.0  # a whole window of the hold first
    assert any(abs(t - back[0][0]) < 0.05 and m == "mode RECOVER -> AUTO" for t, m in notes)
    est = ap.wind_estimate.speed
    assert est >= 0.9 * 8.0
    t = rep.result.t
    m = (t > back[0][0] - 20.0) & (t <= back[0][0])
    true = float(np.linalg.norm(np.mean(rep.result.wind[m, :2], axis=0)))
    assert abs(est - true) <= 0.15 * true, (est, true)
    assert float(np.min(-rep.result.pos[:, 2])) > 5.0


def test_a_path_lost_in_a_good_wind_stays_parked():
    """The calm nominal 8 m/s cycle with a lost-path bound it exceeds after 4 s (0.3 m for
    0.5 s) and the landing off (REC_LAND 0: RECOVER parks): the wind is the cycle's own 8 m/s
    all along, but the failsafe met no lull, so whatever the path was lost to, it was not the
    wind: the glider stays parked in the hold for the rest of the flight (80 s) and AUTO does
    not come back."""
    rep, ap = _fly(NOM8, {"FS_TRK_ERR": 0.3, "FS_TRK_TIME": 0.5, "REC_LAND": 0.0}, cycles=1, t_end=80.0)
    assert [m for _, m in ap.log if m.startswith("failsafe")]
    assert not any(m.startswith("wind back") for _, m in ap.log)
    assert ap.mode == "RECOVER" and ap.parked and rep.status == "parked", rep.message
