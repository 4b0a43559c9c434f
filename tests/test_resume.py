"""After a lull: the glider parked by the lost-path failsafe goes back to its cycle when the
onboard wind estimate says the wind is back (FS_RESUME, FS_RESUME_SHR; :mod:`fdm_awe.sim.resume`),
and stays parked when the path was lost in a good wind or the return is off.

The lull is made by the test, so it does not hang on a turbulence seed: the nominal 10 m/s cycle
is flown in still air (a lull as long as the flight), and once the glider holds, the test gives
JSBSim and the line the cycle's 10 m/s again."""

from __future__ import annotations

import re

import numpy as np

from fdm_awe.autopilot.tracking import TrackingReference
from fdm_awe.sim.flight import fly

from flight_helpers import DATA

NOM10 = DATA / "ref_physical_nominal_10mps_sized.json"
NOM8 = DATA / "ref_physical_nominal_8mps_sized.json"


def _fly(path, params: dict[str, float], wind: float | None = None, back: float | None = None, **kw):
    """Fly ``path``'s reference with autopilot ``params``, in a uniform ``wind`` [m/s] along the
    reference's wind (None: the reference's own); with ``back`` [m/s], the wind is set to that
    once the glider holds in RECOVER's park. The report, the autopilot and the step of the change."""
    ref = TrackingReference.from_ocp_file(path)
    fw = None
    v = np.asarray(ref.meta["wind_ned_mps"], float)
    u = v / np.hypot(v[0], v[1])
    if wind is not None:
        fw = {**ref.meta, "wind_ned_mps": list(u * wind), "wind_mps": wind}
    h: dict = {}

    def setup(ap, sim):
        h["ap"], h["sim"] = ap, sim
        for name, value in params.items():
            assert ap.params.try_set(name, value)[0]

    def on_step(k, s, o):
        if back is not None and "back" not in h and h["ap"].parked:
            h["back"] = (k, float(s.t))
            h["sim"].glider.set_wind(tuple(u * back))
            h["sim"].gs.set_wind(tuple(u * back))

    rep = fly(ref, config=ref.meta["config"], setup=setup, on_step=on_step, flight_wind=fw, **kw)
    return rep, h["ap"], h.get("back")


def test_the_wind_back_after_a_lull_the_glider_flies_its_cycles_again():
    """The nominal 10 m/s cycle in still air, RECOVER parking (REC_LAND 0): the glider loses its
    path in its second cycle and the failsafe parks it, its message naming the lull. With the
    cycle's wind back once it holds: after a whole FS_RESUME window (20 s) of the hold the
    estimate finds the wind (within 5 % of the 10 m/s given: calm air, the hold circle turns the
    heading through every direction), AUTO rejoins the cycle and all 3 cycles are flown, without
    ground contact. With the return off (FS_RESUME 0) and the same wind back, it stays parked."""
    rep, ap, back = _fly(NOM10, {"REC_LAND": 0.0}, wind=0.0, back=10.0, cycles=3)
    notes = [(t, m) for t, m in ap.log]
    t_fs = [t for t, m in notes if m.startswith("failsafe") and "FS_TRK_ERR" in m]
    again = [(t, m) for t, m in notes if m.startswith("wind back")]
    assert ap.params["FS_RESUME"] == 20.0 and ap.params["FS_RESUME_SHR"] == 0.9
    assert t_fs and back is not None and back[1] > t_fs[0]
    assert len(again) == 1 and back[1] + 20.0 <= again[0][0] <= back[1] + 22.0, (back, again)
    assert any(abs(t - again[0][0]) < 0.05 and m == "mode RECOVER -> AUTO" for t, m in notes)
    est = float(re.match(r"wind back: ([0-9.]+) m/s", again[0][1]).group(1))
    assert abs(est - 10.0) <= 0.5, again
    assert rep.status == "ok", rep.message
    assert sum(c.complete for c in rep.cycles) == 3
    assert float(np.min(-rep.result.pos[:, 2])) > 5.0

    off, ap_off, back_off = _fly(NOM10, {"REC_LAND": 0.0, "FS_RESUME": 0.0}, wind=0.0, back=10.0, cycles=3)
    assert back_off is not None
    assert off.status == "parked", off.message
    assert "a lull:" in off.message and "FS_TRK_ERR" in off.message
    assert not any(m.startswith("wind back") for _, m in ap_off.log)
    assert sum(c.complete for c in off.cycles) < 3


def test_a_path_lost_in_a_good_wind_stays_parked():
    """The calm nominal 8 m/s cycle with a lost-path bound it exceeds after 4 s (0.3 m for
    0.5 s) and the landing off (REC_LAND 0: RECOVER parks): the wind is the cycle's own 8 m/s
    all along, but the failsafe met no lull, so whatever the path was lost to, it was not the
    wind: the glider stays parked in the hold for the rest of the flight (80 s) and AUTO does
    not come back."""
    rep, ap, _ = _fly(NOM8, {"FS_TRK_ERR": 0.3, "FS_TRK_TIME": 0.5, "REC_LAND": 0.0}, cycles=1, t_end=80.0)
    assert [m for _, m in ap.log if m.startswith("failsafe")]
    assert not any(m.startswith("wind back") for _, m in ap.log)
    assert ap.mode == "RECOVER" and ap.parked and rep.status == "parked", rep.message
