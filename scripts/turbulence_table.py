"""Target against measured turbulence of the ``--turbulence`` forms (docs/wind.md).

For each form and wind speed the glider is held at the hub height, crosswind at a constant
airspeed, while JSBSim's atmosphere steps on (:func:`fdm_awe.sixdof.turbulence_path.sample_turbulence`);
the wind it meets is measured as a flight's is (:func:`fdm_awe.turbulence.measure`). Each cell
has its own seed, so the table shows the record's sampling spread (relative standard error of
the longitudinal sigma about ``sqrt(L_u / (2 V T))``, 4 % for an hour at 100 m and 20 m/s).

    .venv/bin/python scripts/turbulence_table.py
    .venv/bin/python scripts/turbulence_table.py --profile log:0.1 --forms iec:A,milspec:light
    .venv/bin/python scripts/turbulence_table.py --forms light --winds 8 --swing 7:3 --dt 0.008333
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from fdm_awe.commands import _checks as chk
from fdm_awe.errors import InputError
from fdm_awe.sixdof.turbulence_path import sample_turbulence
from fdm_awe.turbulence import LOW_ALTITUDE_M, Turbulence, measure
from fdm_awe.wind import WindProfile


def _wind(text: str) -> float:
    """One wind speed of ``--winds`` [m/s], 0.5..30."""
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"--winds {text!r}: not a number (allowed 0.5..30 m/s, comma-separated)") from None
    return chk.number(v, "--winds", 0.5, 30.0, unit="m/s", what="wind speed")  # type: ignore[return-value]


def _swing(text: str | None) -> tuple[float, float] | None:
    """``--swing AMP:PERIOD`` -> (amplitude m/s, period s); None passes."""
    if text is None:
        return None
    amp, colon, period = text.partition(":")
    try:
        pair = (float(amp), float(period))
    except ValueError:
        raise InputError(f"--swing {text!r}: expected AMP:PERIOD, two numbers (allowed 0..15 m/s and 0.5..600 s)") from None
    if not colon:
        raise InputError(f"--swing {text!r}: expected AMP:PERIOD (allowed 0..15 m/s and 0.5..600 s)")
    chk.number(pair[0], "--swing", 0.0, 15.0, unit="m/s", what="amplitude")
    chk.number(pair[1], "--swing", 0.5, 600.0, unit="s", what="period")
    return pair


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--forms", default="light,milspec:light,iec:A,iec:B,iec:C", help="turbulence forms (no seed)")
    p.add_argument("--winds", default="8,10,12", help="wind speeds at the reference height, m/s")
    p.add_argument("--profile", default="uniform", help="wind profile (uniform, log:Z0, power:ALPHA; given at 10 m)")
    p.add_argument("--hub", type=float, default=100.0, help="hub height, m (the glider is held there)")
    p.add_argument("--airspeed", type=float, default=20.0, help="the glider's airspeed, m/s")
    p.add_argument("--duration", type=float, default=3600.0, help="simulated seconds per cell")
    p.add_argument("--dt", type=float, default=1.0 / 30.0, help="step, s")
    p.add_argument("--swing", metavar="AMP:PERIOD", default=None,
                   help="fly downwind with the wind speed, and so the airspeed, swinging by AMP m/s (0..15) "
                        "with PERIOD s (0.5..600) (default: crosswind, steady)")
    a = p.parse_args(argv)
    try:
        profile = WindProfile.parse(a.profile, option="--profile")
        forms = [Turbulence.parse(f, option="--forms") for f in a.forms.split(",")]
        winds = [_wind(w) for w in a.winds.split(",")]
        chk.number(a.hub, "--hub", 1.0, LOW_ALTITUDE_M[1], unit="m", what="hub height")
        chk.number(a.airspeed, "--airspeed", 5.0, 60.0, unit="m/s", what="airspeed")
        chk.number(a.duration, "--duration", 1.0, 86400.0, unit="s", what="simulated seconds per cell")
        chk.number(a.dt, "--dt", 0.0, 0.1, lo_open=True, unit="s", what="step")
        swing = _swing(a.swing)
    except InputError as exc:
        print(f"turbulence_table: error: {exc}", file=sys.stderr)
        return 2
    path = ("crosswind" if swing is None else
            f"downwind, the wind speed and airspeed swinging by {swing[0]:g} m/s every {swing[1]:g} s")
    print(f"hub {a.hub:g} m, {profile.describe()}, airspeed {a.airspeed:g} m/s {path}, "
          f"{a.duration:g} s per cell at dt {a.dt:.4g} s\n")
    print("| form | wind m/s | W20 m/s | V_hub m/s | target sigma_u m/s | measured sigma_u | target TI | measured TI "
          "| measured sigma_v | target sigma_w | measured sigma_w |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    seed = 0
    for form in forms:
        for w in winds:
            seed += 1
            st = Turbulence(form.form, form.name, seed).setting(w, None if profile.uniform else profile, a.hub)
            v_hub = st.wind_hub_mps
            t, wind, steady = sample_turbulence(st, (v_hub, 0.0, 0.0), a.hub, a.airspeed, a.duration, dt=a.dt,
                                                swing=swing)
            m = measure(t, wind, steady, (1.0, 0.0))
            tg = st.targets()
            label = form.name if form.form == "level" else f"{form.form}:{form.name}"
            print(f"| {label} (seed {seed}) | {w:g} | "
                  f"{st.w20_mps:.2f} | {v_hub:.2f} | {tg['sigma_u_mps']:.3f} | {m['sigma_u_mps']:.3f} | "
                  f"{tg['intensity']:.3f} | {m['intensity']:.3f} | {m['sigma_v_mps']:.3f} | {tg['sigma_w_mps']:.3f} | "
                  f"{m['sigma_w_mps']:.3f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
