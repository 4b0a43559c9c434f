"""The field-by-field checks of a reference trajectory (:func:`check_reference`) and of its
parsed file (:func:`check_reference_document`): one-line :class:`~fdm_awe.errors.InputError`
messages naming the source, the field and the allowed range or form."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from ..errors import InputError
from ..wind import WindProfile
from .reference import ReferenceTrajectory
from .schema import (COLUMN_RANGES, COLUMN_UNITS, CONFIGS, CONTINUITY_ATOL, CONTINUITY_FACTOR, FORMAT, GENERATORS,
                     OPTIONAL_COLUMN_UNITS, PERIODIC_TOL, PHASE_MAX_S, PHASE_NAMES, PROPELLERS, RECOVERY_AIRFRAME,
                     SCENARIOS, SLACK, TIME_RTOL, VERSION, WIND_MAX)


# Some checks take their allowed values from the optimiser's, the ground station's and the
# aircraft's modules, imported when a file is checked: importing them costs more than this whole
# package, which the recordings and the autopilot's tracking reference import for the sampler.

def _kind(v: Any) -> str:
    """JSON type name of a parsed value (for messages)."""
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, (int, float)):
        return "a number"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, list):
        return "a list"
    if isinstance(v, dict):
        return "an object"
    return type(v).__name__


def _show(v: Any) -> str:
    """A short one-line rendering of a metadata value."""
    text = repr(v) if isinstance(v, str) else (json.dumps(v) if isinstance(v, (bool, type(None))) else str(v))
    text = text.replace("\n", " ")
    return text if len(text) <= 40 else text[:37] + "..."


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def _column_from_json(src: str, name: str, v: Any) -> np.ndarray:
    """Column ``name`` of the file as a float array: a list of finite numbers."""
    if not isinstance(v, list):
        raise InputError(f"{src}: columns.{name}: {_kind(v)}, expected a list of numbers")
    for i, x in enumerate(v):
        if not _is_number(x):
            shown = "" if x is None else f" {_show(x)}"
            raise InputError(f"{src}: columns.{name}[{i}]: {_kind(x)}{shown}, expected a finite number")
    try:
        a = np.array(v, dtype=float)
    except OverflowError:
        i = next(i for i, x in enumerate(v) if isinstance(x, int) and abs(x) > 1e308)
        raise InputError(f"{src}: columns.{name}[{i}]: number too large, expected a finite number") from None
    return a


def _check_column(src: str, name: str, a: np.ndarray) -> np.ndarray:
    """``a`` as a 1-D float array of finite numbers within :data:`COLUMN_RANGES`."""
    try:
        a = np.asarray(a, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{src}: columns.{name}: not a list of numbers") from None
    if a.ndim != 1:
        raise InputError(f"{src}: columns.{name}: {a.ndim}-dimensional, expected a list of numbers")
    bad = np.flatnonzero(~np.isfinite(a))
    if len(bad):
        i = int(bad[0])
        raise InputError(f"{src}: columns.{name}[{i}]: {a[i]} is not a finite number ({len(bad)} such value(s))")
    rng = COLUMN_RANGES.get(name)
    if rng is not None and len(a):
        lo, hi, lo_open = rng
        slack = SLACK * max(1.0, float(np.max(np.abs(a))))
        below = (a <= lo) if lo_open else (a < lo - slack)
        out = np.flatnonzero(below | (a > hi + slack))
        if len(out):
            i = int(out[0])
            unit = COLUMN_UNITS.get(name, "-")
            unit = "" if unit == "-" else f" {unit}"
            allowed = f"> {lo:.6g} and <= {hi:.6g}{unit}" if lo_open else f"{lo:.6g} .. {hi:.6g}{unit}"
            raise InputError(f"{src}: columns.{name}[{i}]: {a[i]:.6g}{unit} out of range (allowed {allowed})")
    return a


def _meta_number(src: str, md: dict[str, Any], key: str, lo: float | None = None, hi: float | None = None,
                 lo_open: bool = False, unit: str = "") -> float | None:
    """Metadata number ``key`` (None when absent), finite and within ``lo .. hi``."""
    if key not in md or md[key] is None:
        return None
    v = md[key]
    u = f" {unit}" if unit else ""
    if lo is None and hi is None:
        allowed = "a finite number"
    elif hi is None:
        allowed = f"{'>' if lo_open else '>='} {lo:g}{u}"
    elif lo is None:
        allowed = f"<= {hi:g}{u}"
    elif lo_open:
        allowed = f"> {lo:g} and <= {hi:g}{u}"
    else:
        allowed = f"{lo:g} .. {hi:g}{u}"
    if not _is_number(v) or not math.isfinite(float(v)):
        raise InputError(f"{src}: metadata.{key}: {_show(v)} is not a finite number (allowed {allowed})")
    x = float(v)
    if (lo is not None and (x <= lo if lo_open else x < lo)) or (hi is not None and x > hi):
        raise InputError(f"{src}: metadata.{key}: {x:g}{u} out of range (allowed {allowed})")
    return x


def _meta_choice(src: str, md: dict[str, Any], key: str, allowed: tuple[str, ...], required: bool = True) -> str | None:
    v = md.get(key)
    if v is None and not required:
        return None
    if v is None:
        raise InputError(f"{src}: metadata.{key}: missing (allowed {', '.join(allowed)})")
    if v not in allowed or not isinstance(v, str):
        raise InputError(f"{src}: metadata.{key}: {_show(v)} not allowed (allowed {', '.join(allowed)})")
    return v


def _check_wind(src: str, md: dict[str, Any]) -> None:
    """Wind speed, direction and NED vector: in range and consistent; the missing ones filled in."""
    from ..pointmass.model import wind_vector

    speed = _meta_number(src, md, "wind_mps", 0.0, WIND_MAX, unit="m/s")
    from_deg = _meta_number(src, md, "wind_from_deg", -360.0, 360.0, unit="deg")
    ned = md.get("wind_ned_mps")
    if ned is not None:
        if not (isinstance(ned, (list, tuple)) and len(ned) == 3 and all(_is_number(v) and math.isfinite(float(v)) for v in ned)):
            raise InputError(f"{src}: metadata.wind_ned_mps: {_show(ned)}, expected 3 finite numbers [north, east, down] m/s")
        ned = [float(v) for v in ned]
        horiz = math.hypot(ned[0], ned[1])
        tol = SLACK * max(1.0, horiz)
        if abs(ned[2]) > tol:
            raise InputError(f"{src}: metadata.wind_ned_mps: down component {ned[2]:g} m/s, allowed 0 (a horizontal wind)")
        if horiz > WIND_MAX + tol:
            raise InputError(f"{src}: metadata.wind_ned_mps: horizontal speed {horiz:g} m/s out of range (allowed 0 .. {WIND_MAX:g} m/s)")
        if speed is not None and abs(horiz - speed) > tol:
            raise InputError(f"{src}: metadata.wind_mps: {speed:g} m/s disagrees with metadata.wind_ned_mps "
                             f"(horizontal speed {horiz:g} m/s; allowed difference {tol:.2g} m/s)")
        if speed is None:
            speed = horiz
        if from_deg is not None and speed > tol:
            expected = wind_vector(speed, from_deg)
            if math.hypot(expected[0] - ned[0], expected[1] - ned[1]) > tol:
                blows = math.degrees(math.atan2(-ned[1], -ned[0])) % 360.0
                raise InputError(f"{src}: metadata.wind_from_deg: {from_deg:g} deg disagrees with metadata.wind_ned_mps "
                                 f"(a wind from {blows:g} deg)")
        if from_deg is None:
            from_deg = math.degrees(math.atan2(-ned[1], -ned[0])) % 360.0 if speed > tol else 180.0
    else:
        if speed is None:
            raise InputError(f"{src}: metadata.wind_mps: missing, and no metadata.wind_ned_mps (allowed 0 .. {WIND_MAX:g} m/s)")
        if from_deg is None and speed > 0.0:
            raise InputError(f"{src}: metadata.wind_from_deg: missing, and no metadata.wind_ned_mps to give the wind's direction")
        from_deg = 180.0 if from_deg is None else from_deg
        ned = list(wind_vector(speed, from_deg))
    md["wind_mps"], md["wind_from_deg"], md["wind_ned_mps"] = float(speed), float(from_deg), ned


def _check_metadata(src: str, md: dict[str, Any]) -> dict[str, Any]:
    """The metadata, checked field by field (what the cycle is, its times, its wind, the plant it
    was optimised for, its geometry, its summaries; in this order); returns a copy with the
    derived fields filled in (``wind_*``, ``period_s``, ``tether_drag_scale``, ``fold_time_s``,
    ``motor_off``, ``wind_profile``, a physical cycle's ``generator``)."""
    md = dict(md)
    scenario, config = _check_cycle_kind(src, md)
    _check_times(src, md)
    _check_wind(src, md)
    _check_plant(src, md, scenario, config)
    _check_geometry(src, md)
    _check_summaries(src, md)
    return md


def _check_cycle_kind(src: str, md: dict[str, Any]) -> tuple[str, str]:
    """Scenario and configuration (returned), status, recovery airframe and phase names."""

    scenario = _meta_choice(src, md, "scenario", SCENARIOS)
    config = _meta_choice(src, md, "config", CONFIGS)
    status = md.get("status")
    if status is not None and status != "ok":
        raise InputError(f"{src}: metadata.status: {_show(status)}, a reference must be an 'ok' cycle (allowed ok)")
    ra = md.get("recovery_airframe")
    if ra is not None and ra != RECOVERY_AIRFRAME[config]:  # type: ignore[index]
        raise InputError(f"{src}: metadata.recovery_airframe: {_show(ra)} does not fit config {config!r} "
                         f"(allowed {RECOVERY_AIRFRAME[config]!r})")  # type: ignore[index]
    names = md.get("phase_names")
    if names is not None and names != list(PHASE_NAMES):
        raise InputError(f"{src}: metadata.phase_names: {_show(names)} not allowed (allowed {json.dumps(list(PHASE_NAMES))})")
    return scenario, config  # type: ignore[return-value]


def _check_times(src: str, md: dict[str, Any]) -> None:
    """Phase durations ``T1_s``, ``T2_s`` [s] (required) and ``period_s`` (their sum, filled in)."""
    T1 = _meta_number(src, md, "T1_s", 0.0, PHASE_MAX_S, lo_open=True, unit="s")
    T2 = _meta_number(src, md, "T2_s", 0.0, PHASE_MAX_S, lo_open=True, unit="s")
    for key, v in (("T1_s", T1), ("T2_s", T2)):
        if v is None:
            raise InputError(f"{src}: metadata.{key}: missing (allowed > 0 and <= {PHASE_MAX_S:g} s)")
    period = T1 + T2  # type: ignore[operator]
    tol = TIME_RTOL * max(1.0, period)
    P = _meta_number(src, md, "period_s", 0.0, 2 * PHASE_MAX_S, lo_open=True, unit="s")
    if P is not None and abs(P - period) > tol:
        raise InputError(f"{src}: metadata.period_s: {P:.9g} s, but T1_s + T2_s = {period:.9g} s (allowed difference {tol:.2g} s)")
    md["T1_s"], md["T2_s"], md["period_s"] = T1, T2, period


def _check_plant(src: str, md: dict[str, Any], scenario: str, config: str) -> None:
    """What the cycle was optimised for: line drag factor, propeller, line, fold time, motor-off
    mode, wind profile, generator and line weight (defaults of older files filled in)."""
    from ..definitions.aircraft import FOLD_TIME_MAX_S
    from ..groundstation.line import LINES
    from ..groundstation.tether import TETHER_DRAG_SCALE_MAX

    scale = _meta_number(src, md, "tether_drag_scale", 0.0, TETHER_DRAG_SCALE_MAX)
    md["tether_drag_scale"] = 1.0 if scale is None else scale  # files written before it existed: the defined line
    prop = md.get("propeller")
    if prop is not None:
        allowed = PROPELLERS if scenario == "physical" else ("paper",)
        if prop not in allowed or not isinstance(prop, str):
            raise InputError(f"{src}: metadata.propeller: {_show(prop)} not allowed for the {scenario} scenario "
                             f"(allowed {', '.join(allowed)})")
    line = md.get("line")  # absent: a file written before lines were named, flown on Table 1's line
    if line is not None and (not isinstance(line, str) or line not in LINES):
        raise InputError(f"{src}: metadata.line: {_show(line)} not allowed (allowed {', '.join(LINES)}; "
                         f"absent = paper, Table 1's line)")
    fold_time = _meta_number(src, md, "fold_time_s", 0.0, FOLD_TIME_MAX_S, unit="s")
    if fold_time is not None and fold_time > 0.0 and config == "nominal":
        raise InputError(f"{src}: metadata.fold_time_s: {fold_time:g} s, but metadata.config is 'nominal' (never folds; allowed 0)")
    md["fold_time_s"] = 0.0 if fold_time is None else fold_time  # older files: optimised with an instantaneous fold
    mo = md.get("motor_off")
    if mo is not None and not isinstance(mo, bool):
        raise InputError(f"{src}: metadata.motor_off: {_show(mo)} not allowed (allowed true or false; absent = false)")
    md["motor_off"] = bool(mo)
    prof = WindProfile.from_dict(md.get("wind_profile"), f"{src}: metadata.wind_profile")  # absent: uniform
    if scenario == "paper" and not prof.uniform:
        raise InputError(f"{src}: metadata.wind_profile: {prof.label()!r}, but the paper scenario's wind is uniform (allowed uniform)")
    md["wind_profile"] = prof.as_dict()
    gen = md.get("generator")
    if gen is not None and (not isinstance(gen, str) or gen not in GENERATORS or scenario != "physical"):
        raise InputError(f"{src}: metadata.generator: {_show(gen)} not allowed (allowed {', '.join(GENERATORS)}, "
                         f"physical scenario only; absent = passive)")
    if scenario == "physical":
        md["generator"] = "passive" if gen is None else gen
    from ..groundstation.line import LINE_MODELS

    lm = md.get("line_model")  # absent: the straight line model, that of every file written before it was named
    if lm is not None and (not isinstance(lm, str) or lm not in LINE_MODELS or (lm != "straight" and scenario != "physical")):
        raise InputError(f"{src}: metadata.line_model: {_show(lm)} not allowed (allowed {', '.join(LINE_MODELS)}; "
                         f"calibrated in the physical scenario only; absent = straight)")
    md["line_model"] = "straight" if lm is None else lm
    ac = md.get("aircraft")  # absent: a file written before it was recorded (the package's glider)
    if ac is not None and not (isinstance(ac, dict) and isinstance(ac.get("sha256"), str)
                               and sum(isinstance(ac.get(k), str) for k in ("name", "directory")) == 1):
        raise InputError(f"{src}: metadata.aircraft: {_show(ac)} not allowed (allowed an object with a name or a "
                         f"directory and its sha256; absent = the package's glider)")
    st = md.get("ground_station")  # absent: a file written before it was recorded (the package's station)
    if st is not None and not (isinstance(st, dict) and isinstance(st.get("sha256"), str) and isinstance(st.get("file"), str)):
        raise InputError(f"{src}: metadata.ground_station: {_show(st)} not allowed (allowed an object with a file "
                         f"(\"default\" or a path) and its sha256; absent = the package's ground station)")
    lw = md.get("line_weight")
    if lw is not None and (not isinstance(lw, bool) or (lw and scenario != "physical")):
        raise InputError(f"{src}: metadata.line_weight: {_show(lw)} not allowed (allowed true or false; true only in the physical scenario)")


def _check_geometry(src: str, md: dict[str, Any]) -> None:
    """Line lengths at the cycle's ends (``d0_m`` < ``d_tf_m``), start angles, loop count ``k_wrap``."""
    d0 = _meta_number(src, md, "d0_m", 0.0, 1e4, lo_open=True, unit="m")
    dtf = _meta_number(src, md, "d_tf_m", 0.0, 1e4, lo_open=True, unit="m")
    if d0 is not None and dtf is not None and dtf <= d0:
        raise InputError(f"{src}: metadata.d_tf_m: {dtf:g} m, allowed > d0_m = {d0:g} m (the line is reeled out in generation)")
    _meta_number(src, md, "elevation0_deg", -90.0, 90.0, unit="deg")
    _meta_number(src, md, "azimuth0_deg", -360.0, 360.0, unit="deg")
    kw = md.get("k_wrap")
    if kw is not None and not (isinstance(kw, int) and not isinstance(kw, bool)):
        raise InputError(f"{src}: metadata.k_wrap: {_show(kw)}, expected an integer")


#: the recorded margins (metadata ``margins``, :func:`fdm_awe.trajectory.files.margins_record`): field -> allowed range
MARGIN_RANGES = {"tension_rating_N": (0.0, 1e5), "tension_margin": (0.0, 4.0), "tension_bound_N": (0.0, 1e5),
                 "stall_margin": (0.0, 0.7), "cl_max_share": (0.3, 1.0), "reel_in_speed_max_m_s": (0.0, 100.0)}
#: recorded margins a file may leave out (a cycle without that margin)
OPTIONAL_MARGINS = frozenset({"reel_in_speed_max_m_s"})


def _check_summaries(src: str, md: dict[str, Any]) -> None:
    """The optimiser's summaries: ``mesh``, ``bounds``, ``energies`` objects (energies: named
    finite numbers or null)."""
    for key in ("mesh", "bounds", "energies", "margins"):
        if md.get(key) is not None and not isinstance(md[key], dict):
            raise InputError(f"{src}: metadata.{key}: {_kind(md[key])}, expected an object")
    for k, (lo, hi) in MARGIN_RANGES.items():  # shown by fly when it loads the reference
        if md.get("margins") is not None and (k in md["margins"] or k not in OPTIONAL_MARGINS):
            v = md["margins"].get(k)
            if not (_is_number(v) and math.isfinite(v) and lo <= v <= hi):
                raise InputError(f"{src}: metadata.margins.{k}: {_show(v)} not allowed (allowed a number {lo:g} .. {hi:g})")
    for k, v in (md.get("energies") or {}).items():  # shown in reports beside the other summary numbers
        if not (isinstance(k, str) and k.startswith(("E_", "P_"))) or not (v is None or (_is_number(v) and math.isfinite(v))):
            raise InputError(f"{src}: metadata.energies.{k}: {_show(v)} not allowed (allowed: E_*_J / P_*_W names "
                             f"with finite numbers or null)")


def check_reference(ref: ReferenceTrajectory) -> ReferenceTrajectory:
    """``ref`` checked field by field: the metadata (:func:`_check_metadata`), every column finite
    and within :data:`COLUMN_RANGES`, equal lengths, at least 2 rows, ``t`` from 0 strictly
    increasing (one repeated time at the phase switch) to ``T1_s + T2_s``, ``phase`` 0 then 1
    with the switch at ``T1_s``, ``fold`` 0 throughout for the nominal config.

    Returns a new :class:`ReferenceTrajectory` with float columns and the completed metadata;
    raises :class:`~fdm_awe.errors.InputError` (one line: source, field, allowed range/form).
    """
    src = ref.source
    if not isinstance(ref.metadata, dict):
        raise InputError(f"{src}: metadata: {_kind(ref.metadata)}, expected an object")
    if not isinstance(ref.columns, dict):
        raise InputError(f"{src}: columns: {_kind(ref.columns)}, expected an object of named lists")
    md = _check_metadata(src, ref.metadata)
    missing = [k for k in COLUMN_UNITS if k not in ref.columns]
    if missing:
        raise InputError(f"{src}: columns missing: {', '.join(missing)} (required: {', '.join(COLUMN_UNITS)})")
    cols = {k: _check_column(src, k, v) for k, v in ref.columns.items()}
    t, ph = cols["t"], cols["phase"]
    n = len(t)
    for k, a in cols.items():
        if len(a) != n:
            raise InputError(f"{src}: columns.{k}: {len(a)} values, expected {n} (the length of columns.t)")
    if n < 2:
        raise InputError(f"{src}: columns.t: {n} row(s), at least 2 needed (a cycle from t = 0 to T1 + T2)")
    if not np.all((ph == 0.0) | (ph == 1.0)):
        i = int(np.flatnonzero((ph != 0.0) & (ph != 1.0))[0])
        raise InputError(f"{src}: columns.phase[{i}]: {ph[i]:g} not allowed (allowed 0 = generation, 1 = recovery)")
    back = np.flatnonzero(np.diff(ph) < 0)
    if len(back):
        i = int(back[0]) + 1
        raise InputError(f"{src}: columns.phase[{i}]: generation (0) after recovery (1); allowed: the generation rows, then the recovery rows")
    dt = np.diff(t)
    switch = (ph[:-1] == 0.0) & (ph[1:] == 1.0)
    bad = np.flatnonzero((dt < 0.0) | ((dt == 0.0) & ~switch))
    if len(bad):
        i = int(bad[0]) + 1
        raise InputError(f"{src}: columns.t[{i}]: {t[i]:.9g} s after {t[i - 1]:.9g} s; allowed: strictly increasing "
                         f"times (one repeated time at the generation/recovery switch)")
    T1, period = md["T1_s"], md["period_s"]
    tol = TIME_RTOL * max(1.0, period)
    if abs(t[0]) > tol:
        raise InputError(f"{src}: columns.t[0]: {t[0]:.9g} s, allowed 0 (the cycle starts at t = 0)")
    if abs(t[-1] - period) > tol:
        raise InputError(f"{src}: columns.t: ends at {t[-1]:.9g} s, but metadata T1_s + T2_s = {period:.9g} s "
                         f"(allowed difference {tol:.2g} s)")
    if not (np.any(ph == 0.0) and np.any(ph == 1.0)):
        which = "generation (0)" if not np.any(ph == 0.0) else "recovery (1)"
        raise InputError(f"{src}: columns.phase: no {which} rows; allowed: both phases, generation first")
    t_gen_end, t_rec_start = float(t[ph == 0.0][-1]), float(t[ph == 1.0][0])
    if abs(t_gen_end - T1) > tol or abs(t_rec_start - T1) > tol:
        raise InputError(f"{src}: columns.phase: switches from generation (last at t = {t_gen_end:.9g} s) to recovery "
                         f"(first at {t_rec_start:.9g} s), but metadata.T1_s = {T1:.9g} s (allowed difference {tol:.2g} s)")
    if md["config"] == "nominal" and np.any(cols["fold"] != 0.0):
        i = int(np.flatnonzero(cols["fold"] != 0.0)[0])
        raise InputError(f"{src}: columns.fold[{i}]: {cols['fold'][i]:g}, but metadata.config is 'nominal' (never folds; allowed 0)")
    if "motor_on" in cols and not md["motor_off"] and np.any(cols["motor_on"] != 1.0):
        i = int(np.flatnonzero(cols["motor_on"] != 1.0)[0])
        raise InputError(f"{src}: columns.motor_on[{i}]: {cols['motor_on'][i]:g}, but metadata.motor_off is not true "
                         f"(the motor runs throughout; allowed 1)")
    if "boost_duty" in cols and md.get("generator") != "boost" and np.any(cols["boost_duty"] != 0.0):
        i = int(np.flatnonzero(cols["boost_duty"] != 0.0)[0])
        raise InputError(f"{src}: columns.boost_duty[{i}]: {cols['boost_duty'][i]:g}, but metadata.generator is "
                         f"{md.get('generator', 'passive')!r} (no T2 duty; allowed 0)")
    _check_periodic(src, md, cols)
    _check_continuity(src, md, cols)
    units = ref.units if isinstance(ref.units, dict) else {}
    return ReferenceTrajectory(md, cols, dict(units), source=src)


def _check_periodic(src: str, md: dict[str, Any], cols: dict[str, np.ndarray]) -> None:
    """The cycle ends where it starts: every state column's last row equals its first within
    :data:`PERIODIC_TOL` (the heading after ``2 pi k_wrap``; any whole number of turns when the
    metadata has no ``k_wrap``)."""
    last = len(cols["t"]) - 1
    for name, tol in PERIODIC_TOL.items():
        a = cols[name]
        diff = float(a[-1] - a[0])
        turns = ""
        if name == "psi":
            k = md.get("k_wrap")
            k = round(diff / (2 * math.pi)) if k is None else k
            diff -= 2 * math.pi * k
            turns = f" + 2 pi x {k} (k_wrap)"
        if not abs(diff) <= tol:
            unit = COLUMN_UNITS[name]
            raise InputError(f"{src}: columns.{name}[{last}]: the cycle ends at {a[-1]:.9g} {unit}, {diff:+.3g} {unit} "
                             f"from its start {a[0]:.9g} {unit}{turns}; a reference is one periodic cycle "
                             f"(allowed difference <= {tol:g} {unit})")


def _check_continuity(src: str, md: dict[str, Any], cols: dict[str, np.ndarray]) -> None:
    """No step of the position between consecutive rows larger than the fastest ground speed
    (largest airspeed + largest wind along the path) times the time step, with the margin of
    :data:`CONTINUITY_FACTOR` and :data:`CONTINUITY_ATOL`."""
    pos = np.stack([cols["x"], cols["y"], cols["z"]], axis=1)
    step = np.diff(pos, axis=0)
    dist = np.sqrt(np.sum(step * step, axis=1))
    dt = np.diff(cols["t"])
    prof = WindProfile.from_dict(md.get("wind_profile"), f"{src}: metadata.wind_profile")
    factor = max((float(prof.factor(float(h))) for h in -cols["z"]), default=1.0)
    wind = float(md["wind_mps"]) * max(1.0, factor)
    v_max = float(np.max(cols["V"]))
    allowed = CONTINUITY_FACTOR * (v_max + wind) * dt + CONTINUITY_ATOL
    bad = np.flatnonzero(~(dist <= allowed))
    if len(bad):
        i = int(bad[0])
        axis = ("x", "y", "z")[int(np.argmax(np.abs(step[i])))]
        raise InputError(f"{src}: columns.{axis}[{i + 1}]: the position moves {dist[i]:.4g} m from row {i} in "
                         f"{dt[i]:.4g} s (allowed <= {allowed[i]:.4g} m: {CONTINUITY_FACTOR:g} x (largest airspeed "
                         f"{v_max:.4g} m/s + wind {wind:.4g} m/s) x time step + {CONTINUITY_ATOL:g} m)")


def check_reference_document(doc: Any, source: str) -> ReferenceTrajectory:
    """The parsed JSON ``doc`` of a reference file (named ``source``) checked as a document
    (object, ``format``, ``version``, ``metadata``/``columns`` objects, columns lists of finite
    numbers) and then by :func:`check_reference`."""
    src = source
    if not isinstance(doc, dict):
        raise InputError(f"{src}: top level is {_kind(doc)}, expected a JSON object with format, version, metadata and columns")
    fmt = doc.get("format")
    if fmt != FORMAT:
        raise InputError(f"{src}: format: {_show(fmt)}, expected {FORMAT!r} (a file written by 'fdm-awe optimize')")
    ver = doc.get("version")
    if not (isinstance(ver, int) and not isinstance(ver, bool) and ver == VERSION):
        raise InputError(f"{src}: version: {_show(ver)} not supported (allowed {VERSION})")
    for key, what in (("metadata", "an object with scenario, config, wind_mps, T1_s, T2_s, ..."),
                      ("columns", "an object of named lists of numbers")):
        if key not in doc:
            raise InputError(f"{src}: {key}: missing (expected {what})")
        if not isinstance(doc[key], dict):
            raise InputError(f"{src}: {key}: {_kind(doc[key])}, expected {what}")
    if "units" not in doc:
        raise InputError(f"{src}: units: missing (expected an object of the columns' units, as 'fdm-awe optimize' "
                         f"writes them: t: s, x: m, V: m/s, ...)")
    units = doc["units"]
    if not (isinstance(units, dict) and all(isinstance(v, str) for v in units.values())):
        raise InputError(f"{src}: units: {_kind(units)}, expected an object of unit names")
    raw = doc["columns"]
    for k in raw:  # every column in the SI unit the package writes (no conversion: another unit is refused)
        expected = COLUMN_UNITS.get(k, OPTIONAL_COLUMN_UNITS.get(k))
        if expected is None:
            continue
        if k not in units:
            raise InputError(f"{src}: units.{k}: missing (expected {expected!r})")
        if units[k] != expected:
            raise InputError(f"{src}: units.{k}: {_show(units[k])} not allowed (expected {expected!r}, the unit "
                             f"'fdm-awe optimize' writes)")
    missing = [k for k in COLUMN_UNITS if k not in raw]
    if missing:
        raise InputError(f"{src}: columns missing: {', '.join(missing)} (required: {', '.join(COLUMN_UNITS)})")
    order = list(COLUMN_UNITS) + [k for k in raw if k not in COLUMN_UNITS]  # t first: its problems are named as t's
    cols = {k: _column_from_json(src, k, raw[k]) for k in order}
    for k, a in cols.items():
        _check_column(src, k, a)  # finite values named by column before any relation between columns
    return check_reference(ReferenceTrajectory(doc["metadata"], cols, units, source=src))
