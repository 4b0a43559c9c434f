#!/usr/bin/env python
"""The control-activity floor of a reference: what a perfect autopilot's surfaces must do to fly it.

A flight's control activity (:mod:`fdm_awe.sim.activity`: the RMS of each surface command above
0.5 Hz) has two parts: the loops' own work against errors and disturbances, and the surface
motion the reference's manoeuvres need even when everything is perfect. This script measures
the second part, a floor no autopilot can go below on this reference:

- the reference is shaped as the autopilot flies it (:func:`fdm_awe.autopilot.shaping.flyable_reference`)
  and sampled every step (120 Hz) for ``--cycles`` periods;
- at each sample the guidance (:func:`fdm_awe.autopilot.guidance.guidance_step`) inverts the
  reference's own state: no position or velocity error, the line at the reference's tension
  (taut in generation after the catch window, the reference's pull elsewhere); its attitude
  (Euler roll and pitch) and angle of attack are what the glider must fly there;
- the surfaces follow from the moments ``I_xx d2(roll)/dt2`` and ``I_yy d2(pitch)/dt2``
  through the attitude law's own inversion (:func:`fdm_awe.sixdof.attitude_law.surface_deflections`:
  the free roll damping and the static and damping pitching moments subtracted), with the
  aircraft's derivatives and inertia read from the JSBSim model at the open and the folded
  wing and blended linearly in the fold state of the fold law, as the model blends them; the
  rudder cancels the aileron's adverse yaw (``Cn_da``) at the deflection flown; each is limited
  to full deflection;
- the activity of these three series, measured as a flight's.

Left out, so the number is a floor: sideslip and its moments, the yaw the path's turn rate
needs, gusts, the line's own dynamics, and any tracking error.

Usage::

    python scripts/activity_floor.py --reference tests/data/ref_physical_nominal_8mps_sized.json \
        --config nominal [--cycles 3] [--json floor.json]

Prints the floor (aileron, elevator, rudder, total); writes it as JSON atomically. Exit 0, 2 on
bad input.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

os.environ.setdefault("JSBSIM_DEBUG", "0")

from fdm_awe.errors import InputError  # noqa: E402


def _autopilot(reference: Any, config: str) -> Any:
    """The autopilot a flight of ``reference`` builds (a 0.1 s flight constructs it)."""
    from fdm_awe.sim.flight import fly

    held: dict[str, Any] = {}
    fly(reference, config=config, cycles=1, setup=lambda ap, sim: held.setdefault("ap", ap), t_end=0.1)
    return held["ap"]


def _coefficients(ap: Any) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The attitude law's coefficient vectors (``C_*`` layout) of the open and the folded wing
    and the aileron's yaw derivative ``Cn_da`` [1/rad] of each (the glider is put at rest in
    the air at each fold state; a glider without a fold gives the open one twice)."""
    g = ap.glider
    out = []
    for fold in (0.0, 1.0) if g.foldable else (0.0,):
        g.reset([0.0, 0.0, -100.0], 15.0, fold=fold)
        out.append((ap.att.law.coefficients(fold, 0.0).copy(), float(g.coefficient("aero/coef/Cn_da"))))
    if len(out) == 1:
        out.append(out[0])
    return out[0][0], out[1][0], out[0][1], out[1][1]


def floor(reference: Any, config: str, cycles: int) -> dict[str, Any]:
    """The floor (see the module doc) of ``reference`` (a :class:`TrackingReference`, as the
    optimiser wrote it) flown as ``config`` for ``cycles`` periods: the surface series' band RMS
    above 0.5 Hz and their total, full deflections."""
    from fdm_awe.autopilot.auto_step import reference_pull
    from fdm_awe.autopilot.fold import fold_command, reference_fold_time
    from fdm_awe.autopilot.guidance import GK, guidance_step
    from fdm_awe.autopilot.shaping import flyable_reference
    from fdm_awe.sim.activity import control_activity
    from fdm_awe.sixdof import attitude_law as L

    ap = _autopilot(reference, config)
    c0, c1, n0, n1 = _coefficients(ap)
    g, p = ap.guidance, ap.params
    ref = flyable_reference(reference)
    wind = np.asarray(ref.meta["wind_ned_mps"], float)
    fold_time = reference_fold_time(ref.meta, ap.glider.fold_time_s) if config == "foldable" else 0.0
    dt = 1.0 / 120.0
    n = int(cycles * ref.period / dt)
    roll, pitch, alpha, V, fold = (np.zeros(n) for _ in range(5))
    gk = g.gains_vector()
    for k in range(n):
        tc = (k * dt) % ref.period
        r = ref.sample(tc)
        f = 0.0
        if config == "foldable":
            f = fold_command(tc, ref.T1, ref.period, fold_time, p["FOLD_LEAD"], p["UNFOLD_LEAD"])
        pos, vel, acc = (np.asarray(x, float) for x in (r.pos, r.vel, r.acc))
        e_r = pos / max(float(np.linalg.norm(pos)), 1e-6)
        pull = reference_pull(True, r.phase, tc, p["GUID_CATCH_T"])
        taut = r.phase == 0 and not pull  # generation's line, taut once caught
        tf = -r.tension * e_r if taut else np.zeros(3)
        cmd = guidance_step(gk, np.zeros(3), g.polar(f), [g.m, g.rho, g.g, g.aero_u.S, g.aero_f.S, *pos, *vel, *acc,
                                                          r.tension, *pos, *vel, *wind, *tf, f, 0.0, taut,
                                                          gk[GK.thrust_max], pull, 0.0])
        alpha[k], roll[k], pitch[k] = cmd[0], cmd[3], cmd[4]
        V[k], fold[k] = float(np.linalg.norm(vel - wind)), f
    c = (1.0 - fold)[:, None] * c0[None, :] + fold[:, None] * c1[None, :]
    cn_da = (1.0 - fold) * n0 + fold * n1
    rate = np.gradient(np.unwrap(roll), dt)
    q = np.gradient(pitch, dt)
    l_des = c[:, L.COEF.ixx] * np.gradient(rate, dt)
    m_des = c[:, L.COEF.iyy] * np.gradient(q, dt)
    qbar = np.maximum(0.5 * g.rho * V * V, 1.0)
    surfaces = np.zeros((n, 3))
    for k in range(n):
        ck = c[k]
        # the attitude law's own inversion (free moments subtracted; no sideslip, no yaw rate),
        # then the rudder's yaw against the aileron's adverse yaw at the deflection flown
        a, e, _ = L.surface_deflections(ck, qbar[k], V[k], alpha[k], 0.0, rate[k], q[k], 0.0, m_des[k], l_des[k],
                                        0.0, True)
        n_des = -qbar[k] * ck[L.COEF.s] * ck[L.COEF.b] * cn_da[k] * a * ck[L.COEF.lim_a]
        surfaces[k] = a, e, L.surface_deflections(ck, qbar[k], V[k], alpha[k], 0.0, rate[k], q[k], 0.0, m_des[k],
                                                  l_des[k], n_des, True)[2]
    act = control_activity(*surfaces.T, dt)
    return {"config": config, "cycles": cycles, "period_s": ref.period, **act.as_dict()}


def main(argv: list[str] | None = None) -> int:
    from fdm_awe.autopilot.tracking import TrackingReference
    from fdm_awe.fileio import check_output_file, write_json

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference", required=True, help="an optimiser's reference trajectory (JSON)")
    ap.add_argument("--config", required=True, help="nominal or foldable")
    ap.add_argument("--cycles", type=int, default=3, help="periods measured, 1..20 (default 3, the demo's)")
    ap.add_argument("--json", default=None, help="write the floor as JSON")
    args = ap.parse_args(argv)
    try:
        if args.config not in ("nominal", "foldable"):
            raise InputError(f"--config {args.config!r}: allowed nominal, foldable")
        if not 1 <= args.cycles <= 20:
            raise InputError(f"--cycles {args.cycles}: out of range (allowed 1..20)")
        if args.json is not None:
            check_output_file(args.json, "--json")
        ref = TrackingReference.from_ocp_file(args.reference)
    except InputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    out = floor(ref, args.config, args.cycles)
    out["reference"] = str(args.reference)
    print(f"{args.config}: activity floor above 0.5 Hz (full deflections): aileron {out['aileron_rms']:.3f} "
          f"elevator {out['elevator_rms']:.3f} rudder {out['rudder_rms']:.3f} total {out['total_rms']:.3f}")
    if args.json is not None:
        write_json(Path(args.json), out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
