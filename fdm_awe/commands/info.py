"""``fdm-awe info``: what the definition files say, in SI, with the reference glide and the
sizing of every tether line (rated tension, safety factor, breaking load, diameter, mass per
length, EA, equivalent line drag coefficient at the shortest and longest working line).

``--json`` is checked before the definitions are read and written atomically (NaN as null).
"""

from __future__ import annotations

import argparse

HELP = "show the airframe, propulsion and ground-station definitions and the reference glide"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", metavar="FILE", help="also write the numbers as JSON (NaN written as null)")


def ground_station_info(wing_area: float) -> dict[str, object]:
    """Print the winch and the sizing of every tether line of the ground-station definition
    (:func:`fdm_awe.groundstation.line.line_summary` at the optimiser's shortest and longest
    working line, drag coefficient on the unfolded wing area ``wing_area`` [m^2]); return them
    for the JSON (``ground_station``, ``lines`` by name, ``default_line`` per scenario)."""
    from ..groundstation import load_ground_station
    from ..groundstation.line import DEFAULT_LINE, LINES, line_summary
    from ..ocp.problem import PLANT_DEFAULTS, working_lengths

    gs = load_ground_station()
    w, m, c = gs.winch, gs.machine, gs.converter
    print(f"ground station: {gs.path}  drum r {w.radius:g} m  DC machine k {m.k:.4g} V s/rad  R {m.resistance:g} ohm  "
          f"supply {c.supply_voltage:g} V  load {c.load_resistance:g} ohm")
    defaults = {scn: str(d["line"]) for scn, d in PLANT_DEFAULTS.items()}
    lines: dict[str, object] = {}
    for name in LINES:
        ls = line_summary(load_ground_station(line=name), lengths=working_lengths(), wing_area=wing_area)
        users = [scn for scn, n in defaults.items() if n == name]
        print(ls.text() + (f"  [default of the {' and '.join(users)} scenario]" if users else ""))
        lines[name] = ls.as_dict()
    return {"ground_station": {"path": gs.path, "drum_radius_m": w.radius, "motor_constant_V_s_per_rad": m.k,
                               "armature_resistance_ohm": m.resistance, "supply_voltage_V": c.supply_voltage,
                               "load_resistance_ohm": c.load_resistance},
            "lines": lines, "default_line": {"file": DEFAULT_LINE, **defaults}}


def run(args: argparse.Namespace) -> int:
    from . import _checks as chk

    chk.outputs(files=[("--json", args.json)])
    from ..definitions.aircraft import load_glider
    from ..pointmass.performance import steady_glide

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
    out["propulsion"] = {"P0_W": p.P0, "eta_prop": p.eta_prop, "eta_motor": p.eta_motor, "disk_area_m2": p.disk_area,
                         "T_max_N": p.T_max}
    out.update(ground_station_info(glider.unfolded.aero.S))
    if args.json:
        from ..fileio import write_json

        write_json(args.json, out)
    return 0
