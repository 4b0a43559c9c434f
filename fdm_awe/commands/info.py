"""``fdm-awe info``: what the definition files say, in SI, with the reference glide and the
sizing of every tether line (rated tension, safety factor, breaking load, diameter, mass per
length, EA, equivalent line drag coefficient at the shortest and longest working line).

``--aircraft NAME|DIR`` shows another aircraft (:mod:`fdm_awe.definitions.catalog`),
``--ground-station FILE`` another ground-station definition (:mod:`fdm_awe.groundstation.source`);
``--export DIR`` writes a copy of the aircraft's definition (and of the ground station's) to
start from: a new or empty folder, or with ``--force`` any folder (the copy's files replaced).

``--json`` is checked before the definitions are read and written atomically (NaN as null).
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from ._aircraft import add_aircraft_arg, aircraft_from_args
from ._station import add_station_arg, station_from_args

HELP = "show the airframe, propulsion and ground-station definitions and the reference glide"


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", metavar="FILE", help="also write the numbers as JSON (NaN written as null)")
    add_aircraft_arg(p, "the aircraft shown (and exported)")
    add_station_arg(p, "the ground station shown (and exported as tether/ground_station.xml)")
    p.add_argument("--export", metavar="DIR",
                   help="write a copy of the aircraft's definition (aircraft/, engine/) and of the ground station's "
                        "(tether/) into DIR, a new or empty folder, to start your own definitions from (--aircraft DIR "
                        "flies the copy); prints the files and nothing else")
    p.add_argument("--force", action="store_true",
                   help="with --export: write into a folder that is not empty (the copy's files are replaced, other "
                        "files kept)")


def export_definitions(dest: str, option: str = "--export", aircraft: Any = None, force: bool = False,
                       station: Any = None) -> list[str]:
    """Copy the definition of ``aircraft`` (:meth:`~fdm_awe.definitions.catalog.Aircraft.files`;
    None: the package's glider) and the ground station's folder ``tether/`` of
    :data:`fdm_awe.ROOT` (its ``ground_station.xml`` the file of ``station``,
    :func:`~fdm_awe.groundstation.source.resolve_ground_station`; None: the package's) into ``dest`` (a new or empty folder, or with ``force`` any folder;
    anything else is refused in one line naming ``option``, before anything is written). The copy
    is made in a temporary folder next to ``dest`` and renamed into place, so ``dest`` holds all
    of it or nothing; with ``force`` into a folder that is not empty, each file is replaced
    atomically. Returns the files written, relative to ``dest``."""
    import os
    import shutil
    import tempfile
    from pathlib import Path

    from .. import ROOT
    from ..definitions.catalog import resolve_aircraft
    from ..errors import InputError
    from ..fileio import check_name_length

    from ..groundstation.definitions import DEFAULT_PATH
    from ..groundstation.source import resolve_ground_station

    a = resolve_aircraft(aircraft)
    st = resolve_ground_station(station)
    skip = shutil.ignore_patterns("__pycache__", "*.py[cod]", "__init__.py")
    sources = [(p, p.relative_to(a.root)) for p in a.files()]
    sources += [(st.path if p == DEFAULT_PATH else p, p.relative_to(ROOT)) for p in sorted((ROOT / "tether").rglob("*"))
                if p.is_file() and not skip(str(p.parent), [p.name]) and "__pycache__" not in p.parts]

    d = Path(dest)
    if str(dest) == "":
        raise InputError(f"{option} '': not a folder name")
    check_name_length(d, option)
    if d.exists() or d.is_symlink():
        if not d.is_dir():
            raise InputError(f"{option} {d}: exists and is not a folder (allowed: a new or empty folder)")
        if any(d.iterdir()) and not force:
            raise InputError(f"{option} {d}: folder exists and is not empty (allowed: a new or empty folder, or add "
                             f"--force to replace the copy's files in it)")
    parent = d.absolute().parent
    if not parent.is_dir():
        raise InputError(f"{option} {d}: {parent} is not a folder (allowed: a new folder in an existing one)")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError(f"{option} {d}: {parent} is not writable")
    tmp = Path(tempfile.mkdtemp(prefix=f".{d.name}.", suffix=".part", dir=parent))
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o777 & ~umask)  # a folder as mkdir makes it (mkdtemp's is private)
        for src, rel in sources:
            (tmp / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, tmp / rel)
        files = sorted(p.relative_to(tmp).as_posix() for p in tmp.rglob("*") if p.is_file())
        if d.is_dir() and any(d.iterdir()):  # --force: each file of the copy replaced in place
            for rel in files:
                (d / rel).parent.mkdir(parents=True, exist_ok=True)
                os.replace(tmp / rel, d / rel)
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            if d.is_dir():
                d.rmdir()  # empty (checked above): replaced by the complete copy
            os.replace(tmp, d)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return files


def drive_info(gs: Any, aircraft: Any = None) -> dict[str, float]:
    """What the supply voltage and the machine's ratings of ground station ``gs`` allow: the
    largest reel-in speed [m/s] on a slack line and against the autopilot's lower line tension
    (WINCH_TLO), the line tensions [N] the rated and peak currents and the motor's current
    limit hold on the drum (``K i / r_w``, friction aside; the motor's pull less its Coulomb
    friction, the generator's largest brake at the current limit with it), the converter's
    tension limit and band [N] with the current [A] that holds the limit on a standing drum,
    the drive's design reel-in speed [m/s] and the supply it needs against WINCH_TLO [V] (NaN
    where the file gives no design speed); WINCH_TLO of ``aircraft``'s autopilot definition
    (None: the package's glider)."""
    from ..autopilot.config import autopilot_params
    from ..groundstation.steady import motor_max_reel_in_speed, motor_supply_needed

    w, m, c = gs.winch, gs.machine, gs.converter
    t_lo = float(autopilot_params(None if aircraft is None else aircraft.autopilot_file)["WINCH_TLO"])
    v_design = w.design_reel_in_speed
    return {"supply_voltage_V": c.supply_voltage, "reel_in_max_mps": float(motor_max_reel_in_speed(0.0, gs)),
            "lower_tension_N": t_lo, "reel_in_max_at_lower_tension_mps": float(motor_max_reel_in_speed(t_lo, gs)),
            "rated_current_A": m.rated_current, "rated_tension_N": m.k * m.rated_current / w.radius,
            "peak_current_A": m.peak_current, "peak_tension_N": m.k * m.peak_current / w.radius,
            "motor_current_limit_A": c.current_limit,
            "motor_pull_max_N": (m.k * c.current_limit - w.coulomb_friction) / w.radius,
            "generator_brake_max_N": (m.k * c.current_limit + w.coulomb_friction) / w.radius,
            "tension_limit_N": c.tension_limit, "tension_limit_band_N": c.tension_limit_band,
            "tension_limit_current_A": (w.radius * c.tension_limit - w.coulomb_friction) / m.k,
            "design_reel_in_speed_mps": v_design,
            "supply_needed_V": float(motor_supply_needed(v_design, t_lo, gs)) if v_design == v_design else math.nan}


def drive_text(d: dict[str, float]) -> str:
    """:func:`drive_info` as three or four lines."""
    text = (f"drive: supply {d['supply_voltage_V']:g} V: reel-in at most {d['reel_in_max_mps']:.2f} m/s "
            f"({d['reel_in_max_at_lower_tension_mps']:.2f} m/s against the lower line tension "
            f"{d['lower_tension_N']:g} N); rated {d['rated_current_A']:g} A = {d['rated_tension_N']:.1f} N of "
            f"line tension, peak {d['peak_current_A']:g} A = {d['peak_tension_N']:.1f} N, motor current limit "
            f"{d['motor_current_limit_A']:g} A pulls {d['motor_pull_max_N']:.1f} N")
    text += (f"\n       tension limit {d['tension_limit_N']:g} N: above it the converter's current limit falls from "
             f"{d['tension_limit_current_A']:.1f} A to 0 A over {d['tension_limit_band_N']:g} N (the drum pays out); "
             f"at the current limit the generator brakes at most {d['generator_brake_max_N']:.1f} N")
    v = d["design_reel_in_speed_mps"]
    if v == v:
        text += (f"\n       design reel-in speed {v:g} m/s (the glider's fall-back) needs "
                 f"{d['supply_needed_V']:.1f} V against {d['lower_tension_N']:g} N")
    return text


def ground_station_info(wing_area: float, aircraft: Any = None, station: Any = None) -> dict[str, object]:
    """Print the winch and the sizing of every tether line of the ground-station definition
    ``station`` (:func:`~fdm_awe.groundstation.source.resolve_ground_station`; None: the
    package's) (:func:`fdm_awe.groundstation.line.line_summary` at the optimiser's shortest and
    longest working line, drag coefficient on the unfolded wing area ``wing_area`` [m^2]); return
    them for the JSON (``ground_station`` with the file's record, ``lines`` by name,
    ``default_line`` per scenario)."""
    from ..groundstation.line import DEFAULT_LINE, LINES, line_summary
    from ..groundstation.source import resolve_ground_station
    from ..ocp.problem import PLANT_DEFAULTS, working_lengths

    st = resolve_ground_station(station)
    gs = st.load()
    w, m, c = gs.winch, gs.machine, gs.converter
    whose = "the package's" if st.builtin else "--ground-station"
    print(f"ground station: {gs.path}  ({whose}; sha256 {st.sha256[:12]})")
    print(f"                drum r {w.radius:g} m  DC machine k {m.k:.4g} V s/rad  R {m.resistance:g} ohm  "
          f"supply {c.supply_voltage:g} V  load {c.load_resistance:g} ohm")
    drive = drive_info(gs, aircraft)
    print(drive_text(drive))
    defaults = {scn: str(d["line"]) for scn, d in PLANT_DEFAULTS.items()}
    lines: dict[str, object] = {}
    for name in LINES:
        ls = line_summary(st.load(name), lengths=working_lengths(), wing_area=wing_area)
        users = [scn for scn, n in defaults.items() if n == name]
        print(ls.text() + (f"  [default of the {' and '.join(users)} scenario]" if users else ""))
        lines[name] = ls.as_dict()
    return {"ground_station": {**st.record(), "path": gs.path, "drum_radius_m": w.radius, "motor_constant_V_s_per_rad": m.k,
                               "armature_resistance_ohm": m.resistance, "supply_voltage_V": c.supply_voltage,
                               "load_resistance_ohm": c.load_resistance, "drive": drive},
            "lines": lines, "default_line": {"file": DEFAULT_LINE, **defaults}}


def run(args: argparse.Namespace) -> int:
    from . import _checks as chk

    if getattr(args, "export", None) is not None:
        if args.json:
            from ..errors import InputError

            raise InputError("--json: not with --export (the export writes the definition files only)")
        files = export_definitions(args.export, aircraft=aircraft_from_args(args), force=args.force,
                                   station=station_from_args(args))
        print(f"exported {len(files)} definition files to {args.export}: " + ", ".join(files))
        print(f"{args.export} has the layout of the package's definition root (a JSBSim root: aircraft/NAME/NAME.xml, "
              f"engine/*.xml, tether/ground_station.xml); --aircraft {args.export} flies it")
        return 0
    if args.force:
        from ..errors import InputError

        raise InputError("--force: only with --export (it lets the export write into a folder that is not empty)")
    chk.outputs(files=[("--json", args.json)])
    from ..pointmass.performance import steady_glide

    aircraft, station = aircraft_from_args(args), station_from_args(args)
    glider = aircraft.glider()
    print(f"aircraft: {aircraft.label()}  ({aircraft.root}, {aircraft.jsbsim_name('foldable')}; sha256 "
          f"{aircraft.sha256[:12]})")
    out: dict[str, object] = {"aircraft": {**aircraft.record(), "root": str(aircraft.root)}}
    for cfg in ("unfolded", "folded"):
        af = glider.config(cfg)
        a = af.aero
        sg = steady_glide(a, af.mass.mass)
        print(f"{cfg:>8}: {af.source.name}  S {a.S:.5f} m2  b {a.b:.3f} m  AR {a.aspect_ratio:.2f}  "
              f"CL = {a.CL0:.4f} + {a.CLalpha:.4f} a (max {a.CLmax:.2f})  "
              f"CD = {a.CD0:.4f} + {a.CDalpha1:.4f} a + {a.CDalpha2:.4f} a^2")
        v_stall = a.stall_speed(af.mass.mass)
        print(f"{'':>10}mass {af.mass.mass:.4g} kg  stall speed {v_stall:.3f} m/s (1 g, CLmax, sea level)")
        print(f"{'':>10}best glide: alpha {sg.alpha:.5f} rad  CL {sg.CL:.4f}  L/D {sg.L_over_D:.3f}  "
              f"V {sg.V:.3f} m/s  gamma {sg.gamma:.5f} rad  sink {sg.sink_rate:.3f} m/s")
        out[cfg] = {"S_m2": a.S, "span_m": a.b, "AR": a.aspect_ratio, "mass_kg": af.mass.mass, "stall_speed_mps": v_stall,
                    "glide": {"alpha_rad": sg.alpha, "CL": sg.CL, "L_over_D": sg.L_over_D, "V_mps": sg.V, "gamma_rad": sg.gamma}}
    p = glider.unfolded.propulsion
    print(f"propulsion: P = {p.P0:g} W + T (V + v_i) / ({p.eta_prop:g} * {p.eta_motor:g}), A_p {p.disk_area:.4f} m2, "
          f"T_max {p.T_max:g} N; paper: P = {p.PT0:g} + {p.PT1:g} T + {p.PT2:g} T^2")
    out["propulsion"] = {"P0_W": p.P0, "eta_prop": p.eta_prop, "eta_motor": p.eta_motor, "disk_area_m2": p.disk_area,
                         "T_max_N": p.T_max}
    out.update(ground_station_info(glider.unfolded.aero.S, aircraft, station))
    if args.json:
        from ..fileio import write_json

        write_json(args.json, out)
    return 0
