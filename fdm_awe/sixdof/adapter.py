"""JSBSim adapter: the glider as a 6-DOF block in SI units, NED frame with the winch at the origin.

The one place where the flight model meets JSBSim's English units (constants from
:mod:`fdm_awe.units`). Aircraft and engines load from the repository's ``aircraft/`` and
``engine/`` folders. Per-step reads and writes go through JSBSim property nodes (bound get/set
methods) rather than string look-ups.

Ground frame: the winch on the ground at geodetic latitude ``home_lat_deg``, longitude 0,
NED positions mapped to geodetic coordinates linearly (:mod:`.row_si`, which also converts the
raw rows to SI). A reset starts in flight from an air-path state (:mod:`.initial_condition`).

Tether hook. ``set_tether_force(F_ned)`` writes the NED force (N -> lbf) into the aircraft's
``external_reactions/tether`` force (frame LOCAL, magnitude 1); JSBSim applies it at the hook
point during the next :meth:`JSBSimGlider.step`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from ..definitions.aircraft import check_aircraft_file
from ..definitions.catalog import Aircraft, default_aircraft
from ..definitions.engine import engine_files, motor_constants
from ..errors import DefinitionError, InputError
from ..turbulence import Turbulence, TurbulenceSetting
from ..units import FT, IN, LBF, SLUG, SLUG_FT2
from .initial_condition import apply_initial_condition
from .row import FOLD_PROPERTY, PROPERTIES, ROW, hook_kinematics
from .row_si import convert_rows, ground_frame, row_si_factors
from .state import SixDofState, Surfaces


# Properties read after every step, in the order of the raw row (sixdof.row; the fold state,
# position ROW.fold, is read from FOLD_PROPERTY on the foldable aircraft, else a constant 0.0)
_READ = tuple(PROPERTIES[i] for i in range(ROW.fold))


class JSBSimGlider:
    """One JSBSim aircraft from ``aircraft/NAME`` as a steppable 6-DOF block.

    ``dt`` s (fixed), ``wind_ned`` steady wind m/s (NED, "from the south at 3 m/s" = (3, 0, 0)),
    ``turbulence`` None, ``(level, seed)`` with level "light" | "moderate" | "severe", or a
    :class:`~fdm_awe.turbulence.TurbulenceSetting` (JSBSim's MIL-F-8785C/Tustin model, seeded;
    :mod:`fdm_awe.turbulence`).
    """

    def __init__(self, name: str | None = None, dt: float = 1.0 / 120.0,
                 wind_ned: Sequence[float] = (0.0, 0.0, 0.0),
                 turbulence: TurbulenceSetting | tuple[str, int] | None = None,
                 root: str | Path | None = None, home_lat_deg: float = 0.0) -> None:
        if not (0.0 < dt <= 0.1):
            raise InputError(f"dt: {dt!r} out of range (allowed > 0 and <= 0.1 s)")
        if not (-80.0 <= home_lat_deg <= 80.0):
            raise InputError(f"home_lat_deg: {home_lat_deg!r} out of range (allowed -80 .. 80)")
        if name is None or root is None:  # the package's aircraft: its morphing form, its root
            ac = default_aircraft()
            name = ac.jsbsim_name("foldable") if name is None else name
            root = ac.root if root is None else root
        self.name = name
        self.root = Path(root)
        self.dt = float(dt)
        self._load()
        self._bind_properties()
        self.motor_volts = self._motor_volts()  #: the motor's voltage at full throttle, V (engine file)
        self._measure_airframe()
        self._set_ground_frame(home_lat_deg)
        self._hook: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        self.wind_ned = (0.0, 0.0, 0.0)
        self.set_wind(wind_ned)
        self.turbulence = None
        self.set_turbulence(turbulence)
        self._force = (0.0, 0.0, 0.0)
        self._raw: list[float] | None = None
        self._state: SixDofState | None = None
        self._controls = Surfaces()
        self._native: tuple[np.ndarray | None, str] | None = None

    @classmethod
    def of(cls, aircraft: Aircraft, **kwargs: Any) -> "JSBSimGlider":
        """The morphing form of ``aircraft`` (:class:`~fdm_awe.definitions.catalog.Aircraft`:
        its JSBSim root and name); ``kwargs`` as the constructor's."""
        return cls(aircraft.jsbsim_name("foldable"), root=aircraft.root, **kwargs)

    # ------------------------------------------------------------------ construction steps
    def _load(self) -> None:
        """Check ``aircraft/NAME/NAME.xml`` field by field, then load it into a new JSBSim
        instance stepping at ``dt``."""
        os.environ.setdefault("JSBSIM_DEBUG", "0")  # silence the banner (read at import)
        import jsbsim  # lazy: keeps ``import fdm_awe`` light

        self._xml = xml = self.root / "aircraft" / self.name / f"{self.name}.xml"
        if not xml.is_file():
            raise InputError(f"aircraft {self.name!r}: no definition {xml}")
        self._doc = check_aircraft_file(xml, root=self.root)  # every field checked before JSBSim reads the file
        fdm = jsbsim.FGFDMExec(str(self.root))
        fdm.set_debug_level(0)
        if not fdm.load_model(self.name):
            raise DefinitionError(xml, "fdm_config", "JSBSim could not load the aircraft")
        fdm.set_dt(self.dt)
        self.fdm = fdm
        self._pm = fdm.get_property_manager()

    def _node(self, prop: str):  # noqa: ANN202 - a JSBSim property node
        """The loaded aircraft's property node ``prop`` (DefinitionError when it has none)."""
        n = self._pm.get_node(prop, False)
        if n is None:
            raise DefinitionError(self._xml, prop, "property missing in the loaded aircraft")
        return n

    def _bind_properties(self) -> None:
        """Bound getters of the raw row (:data:`_READ`, then the fold state) and setters of the
        tether force and the commands: the per-step reads and writes."""
        node = self._node
        self._get = [node(p).get_double_value for p in _READ]
        pm = self._pm
        self._foldable = pm.hasNode(FOLD_PROPERTY) if hasattr(pm, "hasNode") else self._has(FOLD_PROPERTY)
        self._fold_get = node(FOLD_PROPERTY).get_double_value if self._foldable else (lambda: 0.0)
        self._get.append(self._fold_get)  # position FOLD: fold state
        self._read_raw = _list_of_calls(self._get)
        self._set_tx = node("external_reactions/tether/x").set_double_value
        self._set_ty = node("external_reactions/tether/y").set_double_value
        self._set_tz = node("external_reactions/tether/z").set_double_value
        self._set_tmag = node("external_reactions/tether/magnitude").set_double_value
        self._set_ail = node("fcs/aileron-cmd-norm").set_double_value
        self._set_elev = node("fcs/elevator-cmd-norm").set_double_value
        self._set_rud = node("fcs/rudder-cmd-norm").set_double_value
        self._set_thr = node("fcs/throttle-cmd-norm[0]").set_double_value
        self._set_fold = node("fcs/wing-fold-cmd-norm").set_double_value if self._foldable else (lambda v: None)

    def _measure_airframe(self) -> None:
        """What the adapter takes from the loaded aircraft once: the hook's offset from the CG in
        body axes (m; the CG does not move, the fold keeps it fixed), the surface deflection per
        unit command (rad, from the aircraft's own FCS) and the fold time (s, 0 when static)."""
        fdm = self.fdm
        mb = fdm.get_mass_balance()
        fdm["ic/h-agl-ft"] = 1000.0
        fdm.run_ic()
        cg = np.asarray(mb.get_xyz_cg()).ravel() * IN
        hook = np.array([fdm["external_reactions/tether/location-x-in"], fdm["external_reactions/tether/location-y-in"],
                         fdm["external_reactions/tether/location-z-in"]]) * IN
        d = hook - cg
        self.hook_offset_body = np.array([-d[0], d[1], -d[2]])  # structural (x aft, z up) -> body
        self._hook_off = tuple(float(v) for v in self.hook_offset_body)
        for cmd in ("fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm"):
            fdm[cmd] = 1.0
        fdm.run_ic()
        self.surface_limits_rad = {"elevator": fdm["fcs/pitch-cmd-rad"], "aileron": fdm["fcs/roll-cmd-rad"],
                                   "rudder": fdm["fcs/yaw-cmd-rad"]}
        for cmd in ("fcs/elevator-cmd-norm", "fcs/aileron-cmd-norm", "fcs/rudder-cmd-norm"):
            fdm[cmd] = 0.0
        self.fold_time_s = fdm["fcs/wing-fold-time-s"] if self._foldable else 0.0

    def _set_ground_frame(self, home_lat_deg: float) -> None:
        """The NED frame about the winch at ``home_lat_deg`` (:func:`.row_si.ground_frame`) and the
        conversion of a raw row to SI, ``v = raw * scale + offset`` (:func:`.row_si.row_si_factors`)."""
        self._lat0, self._M0, self._N0cos = lat0, m0, n0cos = ground_frame(home_lat_deg)
        #: arguments of row.hook_kinematics after the row: ground frame and hook offset
        self._hook_frame = (lat0, m0, n0cos, FT, *self._hook_off)
        scale, offset = row_si_factors(len(self._get), lat0, m0, n0cos)
        self._scale, self._offset = scale, offset
        self._scale_l, self._offset_l = scale.tolist(), offset.tolist()

    def native_handles(self) -> tuple[np.ndarray | None, str]:
        """Handles for the compiled co-simulation step (:mod:`fdm_awe.sim.kernel` layout:
        Run, getDoubleValue, setDoubleValue, FGFDMExec*, tether x/y/z nodes, then the nodes of
        :meth:`raw` in order) and ``""``, or ``(None, reason)`` where JSBSim cannot be called
        directly (see :mod:`.native`). Checked once per glider."""
        if self._native is None:
            from .native import native_jsbsim

            getters = list(_READ) + ([FOLD_PROPERTY] if self._foldable else [None])
            h, why = native_jsbsim(self.fdm, getters, ["external_reactions/tether/x", "external_reactions/tether/y",
                                                       "external_reactions/tether/z"])
            self._native = ((np.concatenate([h.calls, h.setters, h.getters]), "") if h is not None else (None, why))
        return self._native

    def native_constants(self) -> tuple[float, float, float, tuple[float, float, float]]:
        """Frame constants of the compiled step: home latitude rad, meridian radius M0 m,
        N0 cos(lat0) m, hook offset from the CG in body axes m."""
        return self._lat0, self._M0, self._N0cos, self._hook_off

    def sync_from_native(self, raw: list[float], hook: tuple, force: tuple[float, float, float],
                         state: SixDofState | None = None) -> None:
        """After compiled steps: the last raw row, hook kinematics and applied force, so that
        :meth:`raw`, :meth:`state` and :meth:`hook_kinematics` continue from there."""
        self._raw = raw
        self._hook = hook
        self._force = force
        self._state = state

    def si_factors(self) -> tuple[list[float], list[float]]:
        """Scale and offset of each position of the raw row: SI value = raw * scale + offset (as
        :class:`SixDofState` converts it)."""
        return list(self._scale_l), list(self._offset_l)

    def make_state(self, raw: list[float], hook: tuple, force: tuple[float, float, float]) -> SixDofState:
        """A :class:`SixDofState` of this glider from a raw row, hook kinematics and force."""
        return SixDofState(raw, self._scale_l, self._offset_l, hook, force, self.motor_volts)

    # ------------------------------------------------------------------ setup helpers
    def _has(self, prop: str) -> bool:
        return self._pm.get_node(prop, False) is not None

    def _motor_volts(self) -> float:
        """The motor's voltage at full throttle, V (its engine file, checked with the aircraft)."""
        motor, _ = engine_files(self._doc, self.root)
        return motor_constants(motor)["max_volts"]

    @property
    def foldable(self) -> bool:
        """True for the morphing aircraft (has a fold actuator)."""
        return self._foldable

    @property
    def tether_force_ned(self) -> tuple[float, float, float]:
        """The tether force applied at the hook during the next step (N, NED): the last
        :meth:`set_tether_force` (or, after compiled steps, :meth:`sync_from_native`)."""
        return self._force

    def set_wind(self, wind_ned: Sequence[float]) -> None:
        """Steady wind, NED m/s (the air moves with this velocity)."""
        w = [float(v) for v in wind_ned]
        if len(w) != 3 or not all(math.isfinite(v) for v in w):
            raise InputError(f"wind_ned: need 3 finite components (N, E, D), got {wind_ned!r}")
        self.wind_ned = (w[0], w[1], w[2])
        f = self.fdm
        f["atmosphere/wind-north-fps"] = w[0] / FT
        f["atmosphere/wind-east-fps"] = w[1] / FT
        f["atmosphere/wind-down-fps"] = w[2] / FT

    def set_turbulence(self, turbulence: TurbulenceSetting | tuple[str, int] | None) -> None:
        """``None`` (off), ``(level, seed)`` with level "light" | "moderate" | "severe", or a
        :class:`~fdm_awe.turbulence.TurbulenceSetting` (its severity index, wind at 20 ft and
        seed). Applied at once; every :meth:`reset` re-seeds, so a run repeats for the same seed.
        :attr:`turbulence` keeps the setting."""
        f = self.fdm
        if turbulence is None:
            f["atmosphere/turb-type"] = 0
            self.turbulence = None
            return
        if not isinstance(turbulence, TurbulenceSetting):
            form = Turbulence.of(turbulence)
            if form.form != "level":  # type: ignore[union-attr]
                raise InputError(f"turbulence: {form.text()} follows the flight's wind: pass its setting "  # type: ignore[union-attr]
                                 f"(Turbulence.setting with the wind and hub height)")
            turbulence = form.setting()  # type: ignore[union-attr]
        seed = turbulence.seed
        f["atmosphere/randomseed"] = int(seed)
        f["simulation/randomseed"] = int(seed)
        f["atmosphere/turb-type"] = 4  # Tustin form of the MIL-F-8785C spectra
        f["atmosphere/turbulence/milspec/windspeed_at_20ft_AGL-fps"] = turbulence.w20_mps / FT
        f["atmosphere/turbulence/milspec/severity"] = turbulence.severity
        self.turbulence = turbulence

    # ------------------------------------------------------------------ frames
    def ned_to_geodetic(self, pos_ned: Sequence[float]) -> tuple[float, float, float]:
        """NED (m, winch origin) -> (geodetic latitude rad, longitude rad, height ft)."""
        return (self._lat0 + pos_ned[0] / self._M0, pos_ned[1] / self._N0cos, -pos_ned[2] / FT)

    # ------------------------------------------------------------------ coefficients
    def coefficient(self, name: str) -> float:
        """Current value of a JSBSim aerodynamic property, e.g. ``aero/coef/Cm_de`` (blended
        with the fold state on the foldable aircraft)."""
        return self.fdm[name]

    def reference_geometry(self) -> tuple[float, float, float]:
        """Wing area m^2, span m and chord m the JSBSim coefficients are normalised with."""
        f = self.fdm
        return f["metrics/Sw-sqft"] * FT * FT, f["metrics/bw-ft"] * FT, f["metrics/cbarw-ft"] * FT

    def trim_alpha(self, airspeed: float, gamma: float = 0.0, phi: float = 0.0, rho: float | None = None) -> float:
        """Angle of attack (rad) whose point-mass lift carries the weight in steady flight at
        ``airspeed`` (m/s) on path angle ``gamma`` and bank ``phi`` (current fold state)."""
        f = self.fdm
        S, _, _ = self.reference_geometry()
        m = f["inertia/mass-slugs"] * SLUG
        g = f["accelerations/gravity-ft_sec2"] * FT
        r = f["atmosphere/rho-slugs_ft3"] * SLUG / FT**3 if rho is None else rho
        cl = m * g * math.cos(gamma) / (0.5 * r * airspeed * airspeed * S * max(math.cos(phi), 0.1))
        return (cl - f["aero/pm/CL0"]) / f["aero/pm/CLalpha"]

    def trim_elevator(self, alpha: float) -> float:
        """Normalised elevator command that zeroes the static pitching moment at ``alpha``
        (rad), q = 0 (current fold state)."""
        f = self.fdm
        de = -(f["aero/coef/Cm0"] + f["aero/coef/Cm_alpha"] * alpha) / f["aero/coef/Cm_de"]
        return max(-1.0, min(1.0, de / self.surface_limits_rad["elevator"]))

    # ------------------------------------------------------------------ reset / step
    def reset(self, pos_ned: Sequence[float], airspeed: float, gamma: float = 0.0, psi: float = 0.0,
              phi: float = 0.0, alpha: float | None = None, fold: float = 0.0,
              throttle: float = 0.0) -> SixDofState:
        """Start in flight: CG at ``pos_ned`` (m), air-relative speed ``airspeed`` (m/s) on air-path
        angles ``gamma`` (climb > 0), ``psi`` (heading of the air velocity) and bank ``phi``, rad;
        zero sideslip, zero body rates. ``alpha`` None: the steady-flight angle from
        :meth:`trim_alpha`. ``fold`` in [0, 1] (foldable aircraft: actuator starts there).
        The elevator command starts at :meth:`trim_elevator`; the tether force at zero."""
        vals = [float(v) for v in pos_ned] + [float(airspeed), float(gamma), float(psi), float(phi)]
        if len(vals) != 7 or not all(math.isfinite(v) for v in vals):
            raise InputError(f"reset: non-finite or malformed input pos={pos_ned!r} airspeed={airspeed!r}")
        if not (0.0 <= airspeed <= 100.0):
            raise InputError(f"airspeed: {airspeed!r} out of range (allowed 0 .. 100 m/s)")
        if not (0.0 <= fold <= 1.0):
            raise InputError(f"fold: {fold!r} out of range (allowed 0 .. 1)")
        if fold and not self._foldable:
            raise InputError(f"fold: aircraft {self.name!r} has no fold actuator")
        f = self.fdm
        self._set_fold(fold)
        self._set_thr(throttle)
        self._set_ail(0.0)
        self._set_rud(0.0)
        self._set_tmag(0.0)
        self._set_tx(0.0)
        self._set_ty(0.0)
        self._set_tz(0.0)
        if alpha is None:
            self._apply_ic(vals, 0.0)  # evaluates the blended coefficients for this fold state
            alpha = self.trim_alpha(airspeed, gamma, phi)
        self._set_elev(0.0)
        self._apply_ic(vals, 0.0)
        self._set_elev(self.trim_elevator(alpha))
        self._apply_ic(vals, float(alpha))
        self._force = (0.0, 0.0, 0.0)
        self._set_tmag(1.0)
        self._controls = Surfaces(elevator=self.trim_elevator(alpha), throttle=throttle, fold_cmd=fold)
        self._read()
        return self.state()

    def _apply_ic(self, vals: list[float], alpha: float) -> None:
        """JSBSim's initial condition from ``vals`` (x, y, z m NED, airspeed m/s, gamma, psi, phi
        rad) at ``alpha`` rad (:func:`.initial_condition.apply_initial_condition`), then the wind
        and the turbulence as set."""
        x, y, z, V, gam, psi, phi = vals
        w = self.wind_ned
        apply_initial_condition(self.fdm, self.ned_to_geodetic((x, y, z)), V, gam, psi, phi, alpha, w)
        self.set_wind(w)  # run_ic sets the wind from the IC (horizontal only): restore all three
        self.set_turbulence(self.turbulence)  # re-seeded: every reset repeats the same gusts

    def set_tether_force(self, force_ned: Sequence[float]) -> None:
        """Tether force on the glider (N, NED) applied at the hook during the next step."""
        if isinstance(force_ned, np.ndarray):
            force_ned = force_ned.tolist()  # Python floats: faster than numpy scalars below
        self._set_force(force_ned[0], force_ned[1], force_ned[2])

    def _set_force(self, fx: float, fy: float, fz: float) -> None:
        """:meth:`set_tether_force` from three floats (N, NED): three property sets."""
        self._force = (fx, fy, fz)
        self._set_tx(fx / LBF)
        self._set_ty(fy / LBF)
        self._set_tz(fz / LBF)

    def set_controls(self, s: Surfaces) -> None:
        """Surface, throttle and fold commands for the next step (see :class:`Surfaces`)."""
        if s is self._controls:
            return  # the same (immutable) commands are in the FCS already
        self._controls = s
        self._set_ail(s.aileron)
        self._set_elev(s.elevator)
        self._set_rud(s.rudder)
        self._set_thr(s.throttle)
        self._set_fold(s.fold_cmd)

    @property
    def controls(self) -> Surfaces:
        return self._controls

    def step(self) -> None:
        """Advance JSBSim by ``dt``."""
        self.fdm.run()
        self._read()

    def advance(self, fx: float, fy: float, fz: float) -> SixDofState:
        """The co-simulation's hot path in one call: :meth:`set_tether_force` from three floats
        (N, NED), :meth:`step`, and the new :meth:`state`."""
        self._force = (fx, fy, fz)
        self._set_tx(fx / LBF)
        self._set_ty(fy / LBF)
        self._set_tz(fz / LBF)
        self.fdm.run()
        self._read()
        st = self._state = SixDofState(self._raw, self._scale_l, self._offset_l, self._hook, self._force,
                                       self.motor_volts)
        return st

    def _read(self) -> None:
        r = self._raw = self._read_raw()
        self._state = None
        self._hook = hook_kinematics(r, *self._hook_frame)

    def raw(self) -> list[float]:
        """The property values of the last step in JSBSim units (order of ``_READ``)."""
        return self._raw  # type: ignore[return-value]

    def hook_kinematics(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """Tether attachment point position (m) and ground velocity (m/s), NED, as tuples."""
        return self._hook

    def state(self) -> SixDofState:
        """State after the last step or reset (SI, NED, winch origin); see :class:`SixDofState`."""
        st = self._state
        if st is None:
            if self._raw is None:
                raise InputError("state: call reset() first")
            st = self._state = SixDofState(self._raw, self._scale_l, self._offset_l, self._hook,
                                           self._force, self.motor_volts)
        return st

    def convert_raw(self, raw: np.ndarray) -> dict[str, np.ndarray]:
        """SI time series from stacked raw rows (n x len(raw)), as :class:`SixDofState` names
        (:func:`.row_si.convert_rows`)."""
        return convert_rows(raw, self._scale, self._offset, self.motor_volts)

    def inertia(self) -> np.ndarray:
        """Current inertia matrix about the CG in body axes, kg m^2 (Table 2 layout)."""
        return np.array(np.asarray(self.fdm.get_mass_balance().get_J()), dtype=float) * SLUG_FT2

    def cg_structural(self) -> np.ndarray:
        """CG in the aircraft's structural frame (x aft, y right, z up), m."""
        return np.array(np.asarray(self.fdm.get_mass_balance().get_xyz_cg()), dtype=float).ravel() * IN


def _list_of_calls(getters: list) -> Callable[[], list[float]]:
    """A function returning ``[getters[0](), getters[1](), ...]`` as one list display (generated
    once; no loop or comprehension frame per call: the per-step property reads)."""
    ns = {f"g{i}": g for i, g in enumerate(getters)}
    exec("def read():\n    return [" + ", ".join(f"g{i}()" for i in range(len(getters))) + "]\n", ns)  # noqa: S102
    return ns["read"]


__all__ = ["JSBSimGlider"]
