"""``fdm-awe info``: what the definition files say, in SI, with the reference glide.

``--json`` is checked before the definitions are read and written atomically (NaN as null).
"""

from __future__ import annotations

import argparse

HELP = "show the airframe, propulsion and ground-station definitions and the reference glide"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", metavar="FILE", help="also write the numbers as JSON (NaN written as null)")


def run(args: argparse.Namespace) -> int:
    from . import _checks as chk

    chk.outputs(files=[("--json", args.json)])
    from ..definitions.aircraft import load_glider
    from ..performance import steady_glide

    glider = load_glider()
    out: dict[str, object] = {}
    for cfg in ("unfolded", "folded"):
        af = glider.config(cfg)
        a = af.aero
        sg = steady_glide(a, af.mass.mass)
        print(f"{cfg:>8}: {af.source.name}  S {a.S:.5f} m2  b {a.b:.3f} m  AR {a.aspect_ratio:.2f}  "
              f"CL = {a.CL0:.4f} + {a.CLalpha:.4f} a (max {a.CLmax:.2f})  "
              f"CD = {a.CD0:.4f} + {a.CDalpha1:.4f} a + {a.CDalpha2:.4f} a^2")
        print(f"{'':>10}best glide: alpha {sg.alpha:.5f} rad  CL {sg.CL:.4f}  L/D {sg.L_over_D:.3f}  "
              f"V {sg.V:.3f} m/s  gamma {sg.gamma:.5f} rad  sink {sg.sink_rate:.3f} m/s")
        out[cfg] = {"S_m2": a.S, "span_m": a.b, "AR": a.aspect_ratio, "mass_kg": af.mass.mass,
                    "glide": {"alpha_rad": sg.alpha, "CL": sg.CL, "L_over_D": sg.L_over_D, "V_mps": sg.V, "gamma_rad": sg.gamma}}
    p = glider.unfolded.propulsion
    print(f"propulsion: P = {p.P0:g} W + T (V + v_i) / ({p.eta_prop:g} * {p.eta_motor:g}), A_p {p.disk_area:.4f} m2, "
          f"T_max {p.T_max:g} N; paper: P = {p.PT0:g} + {p.PT1:g} T + {p.PT2:g} T^2")
    try:
        from ..groundstation import load_ground_station
    except ImportError:
        pass
    else:
        gs = load_ground_station()
        print(f"ground station: {gs}")
    if args.json:
        from ..fileio import write_json

        write_json(args.json, out)
    return 0
