"""The attitude control law of the 6-DOF glider: angle of attack, bank and yaw from moment
demands turned into surface deflections with the aircraft's own current derivatives and inertia.

One law serves the stabiliser (:class:`fdm_awe.sixdof.Stabilizer`: holds for tests, benchmarks
and hold modes) and the autopilot's attitude loops
(:class:`fdm_awe.autopilot.attitude.AttitudeLoops`). Moment demands, N m:

- pitch: ``I_yy (w_alpha^2 (e_alpha + ki_alpha int(e_alpha)) - 2 z_alpha w_alpha (q - q_ref))``,
  the integral limited to +-0.2 rad s;
- roll: ``I_xx (w_phi^2 (e_phi [+ ki_phi int(e_phi)]) - 2 z_phi w_phi (p - p_ref))``, the integral
  (limited to +-0.5 rad s) only with ``bank_integral``;
- yaw: ``-I_zz 2 w_r (r - r_ref) + k_beta qbar S b Cn_beta beta`` (damping and sideslip nulling).

Each demand is divided by ``qbar S c`` (pitch) or ``qbar S b`` (roll, yaw) and by the surface's
control derivative; the aircraft's own moment is met in one of two ways:

- ``invert_free_moments`` False: the elevator's trim at the commanded angle of attack (static
  pitching moment zero there at q = 0) is added, nothing in roll: holds near steady flight;
- ``invert_free_moments`` True: the free static and damping moments at the current state
  (``Cm0 + Cm_alpha alpha + Cm_q q c / 2V``, ``Cl_beta beta + (Cl_p p + Cl_r r) b / 2V``) are
  subtracted (dynamic inversion): manoeuvring flight far from trim.

The reference rates ``p_ref, q_ref, r_ref`` (rad/s, body axes) are what the rate damping acts
relative to: the caller's (the stabiliser: the coordinated-turn yaw rate; the autopilot: the
rotation of the air-velocity vector on its curved path). The bank error is the caller's too.
Derivatives and inertia are re-read when the fold state moves by 1e-3 or more, cached otherwise.

The arithmetic is one pure function, :func:`law_commands` (its moment demands turned into
deflections by :func:`surface_deflections`; floats and float64 vectors: numba
compiles it for the co-simulation kernel, Python runs the same source; so is the angle wrap
of the callers' bank and heading errors, :func:`wrap_angle`); :class:`AttitudeLaw`
holds its coefficient vector (layout :data:`COEF`), reads the state and keeps the integrators
(layout :data:`INTEG`); :meth:`StabilizerGains.vector` gives the gain vector (layout :data:`GAINS`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import slots
from ..units import SLUG_FT2
from .adapter import JSBSimGlider
from .row import ROW
from .state import SixDofState

#: layout of the coefficient vector ``c`` of :func:`law_commands`: control derivatives (1/rad),
#: weathercock stiffness Cn_beta (1/rad), the free moments' derivatives (Cm0; Cm_alpha, Cl_beta
#: 1/rad; Cm_q, Cl_p, Cl_r per normalised rate), the elevator's trim (rad), the inertia about the
#: body axes (kg m^2), wing area (m^2), span and chord (m), the surfaces' full deflections (rad).
#: Without the inversion cm0 .. cl_r are unused (NaN); with it the trim is (NaN).
COEF = slots.declare("LawCoefficients", ("cm_de", "cl_da", "cn_dr", "cn_beta", "cm0", "cm_alpha", "cm_q", "cl_beta",
                                         "cl_p", "cl_r", "de_trim", "ixx", "iyy", "izz", "s", "b", "c", "lim_e",
                                         "lim_a", "lim_r"))
#: layout of the gain vector (:meth:`StabilizerGains.vector`)
GAINS = slots.declare("LawGains", ("w_alpha", "z_alpha", "ki_alpha", "w_phi", "z_phi", "ki_phi", "w_r", "k_beta"))
#: layout of the integrator array (rad s): the alpha error's, the bank error's
INTEG = slots.declare("LawIntegrators", ("alpha", "phi"))
#: the raw row's values :meth:`AttitudeLaw.commands` reads, and their SI factors (Python path)
_LAW_ROW = slots.reader(ROW, "fold", "qbar", "vt", "alpha", "beta", "p_rate", "q_rate", "r_rate")
_LAW_SCALE = slots.reader(ROW, "qbar", "vt")
#: the JSBSim properties a refresh reads (:func:`law_refresh`): the derivatives of the control law
#: (blended with the fold state on the foldable aircraft), then the inertia's diagonal (slug ft^2)
LAW_PROPERTIES = tuple("aero/coef/" + n for n in ("Cm_de", "Cl_da", "Cn_dr", "Cn_beta", "Cm0", "Cm_alpha", "Cm_q",
                                                  "Cl_beta", "Cl_p", "Cl_r")) + (
    "inertia/ixx-slugs_ft2", "inertia/iyy-slugs_ft2", "inertia/izz-slugs_ft2")
N_LAW_PROPERTIES = len(LAW_PROPERTIES)
#: where each value of :data:`LAW_PROPERTIES` goes in the coefficient vector
_LAW_SLOTS = (COEF.cm_de, COEF.cl_da, COEF.cn_dr, COEF.cn_beta, COEF.cm0, COEF.cm_alpha, COEF.cm_q, COEF.cl_beta,
              COEF.cl_p, COEF.cl_r, COEF.ixx, COEF.iyy, COEF.izz)


def law_stale(fold: float, fold_at: float) -> bool:
    """Whether the law's derivatives read at fold state ``fold_at`` must be read again at
    ``fold``: the fold state moved by 1e-3 or more (or ``fold_at`` is -1: never read)."""
    return not abs(fold - fold_at) < 1e-3


def law_refresh(vals: Any, c: np.ndarray, slug_ft2: float, invert: bool) -> None:
    """The coefficient vector ``c`` (layout :data:`COEF`) from the values ``vals`` of
    :data:`LAW_PROPERTIES` (JSBSim units; the inertia times ``slug_ft2``, kg m^2 per slug ft^2);
    the free moments' derivatives only with ``invert`` (else they stay as they are)."""
    for j in range(10):
        if invert or j < 4:
            c[_LAW_SLOTS[j]] = vals[j]
    for j in range(10, 13):
        c[_LAW_SLOTS[j]] = vals[j] * slug_ft2


@dataclass
class StabilizerGains:
    """Gains of the attitude law; ``k_psi`` and ``phi_max`` are the stabiliser's heading loop."""

    w_alpha: float = 6.0  #: rad/s, alpha loop bandwidth
    z_alpha: float = 0.8
    ki_alpha: float = 0.0  #: 1/s, integral action on the alpha error (0: off; > ~0.3 couples with the phugoid)
    w_phi: float = 5.0  #: rad/s, bank loop bandwidth
    z_phi: float = 0.8
    ki_phi: float = 1.0  #: 1/s, integral action on the bank error (trims propeller torque), with bank_integral
    w_r: float = 3.0  #: rad/s, yaw damper
    k_beta: float = 1.0  #: rudder per sideslip, in units of the weathercock stiffness
    k_psi: float = 1.0  #: bank command per heading error, rad/rad
    phi_max: float = 0.6  #: rad, bank command limit

    def law_gains(self) -> tuple[float, ...]:
        """The attitude law's gains in the order of the layout :data:`GAINS` (the fields as they are:
        what the Python execution of :func:`law_commands` takes)."""
        return (self.w_alpha, self.z_alpha, self.ki_alpha, self.w_phi, self.z_phi, self.ki_phi, self.w_r,
                self.k_beta)

    def vector(self) -> np.ndarray:
        """The attitude law's gains as a float64 vector (layout :data:`GAINS`) for compiled callers."""
        return np.array(self.law_gains(), dtype=np.float64)


def wrap_angle(e: float) -> float:
    """The angle ``e`` (rad) wrapped to [-pi, pi]."""
    return math.atan2(math.sin(e), math.cos(e))


def law_commands(c: Any, gains: Any, qbar: float, vt: float, alpha: float, beta: float, p: float, q: float,
                 r: float, alpha_cmd: float, e_phi: float, p_ref: float, q_ref: float, r_ref: float, dt: float,
                 integ: Any, invert: bool, bank_integral: bool) -> tuple[float, float, float]:
    """Surface commands ``(aileron, elevator, rudder)`` normalised to [-1, 1] (NaN gives 0).

    ``c``: coefficient vector (layout :data:`COEF`), ``gains``: gain vector (:data:`GAINS`), both float64
    vectors (or, run by Python, any sequences of floats); ``qbar`` Pa and ``vt`` m/s the dynamic
    pressure and airspeed (each limited to >= 1 here); ``alpha``, ``beta`` rad; ``p, q, r`` body
    rates rad/s; ``alpha_cmd`` rad; ``e_phi`` the bank error rad; ``p_ref, q_ref, r_ref`` rad/s
    the rates the damping acts relative to; ``dt`` s since the last call (0: no integration);
    ``integ`` the integrators (layout :data:`INTEG`, rad s), updated in place (the bank's only with
    ``bank_integral``); ``invert``: subtract the free moments (else add the elevator's trim)."""
    # max/min and clipping spelled out: the same operations run by Python and compiled by numba
    if 1.0 > qbar:
        qbar = 1.0
    S, b = c[COEF.s], c[COEF.b]
    # pitch
    e_a = alpha_cmd - alpha
    ia = integ[INTEG.alpha] + e_a * dt
    ia = (ia if ia > -0.2 else -0.2) if ia < 0.2 else 0.2
    integ[INTEG.alpha] = ia
    w = gains[GAINS.w_alpha]
    m_des = c[COEF.iyy] * (w * w * (e_a + gains[GAINS.ki_alpha] * ia) - 2 * gains[GAINS.z_alpha] * w * (q - q_ref))
    # roll
    if bank_integral:
        ip = integ[INTEG.phi] + e_phi * dt
        ip = (ip if ip > -0.5 else -0.5) if ip < 0.5 else 0.5
        integ[INTEG.phi] = ip
        e_phi = e_phi + gains[GAINS.ki_phi] * ip
    w = gains[GAINS.w_phi]
    l_des = c[COEF.ixx] * (w * w * e_phi - 2 * gains[GAINS.z_phi] * w * (p - p_ref))
    # yaw
    n_des = (-c[COEF.izz] * 2 * gains[GAINS.w_r] * (r - r_ref)
             + gains[GAINS.k_beta] * qbar * S * b * c[COEF.cn_beta] * beta)
    return surface_deflections(c, qbar, vt, alpha, beta, p, q, r, m_des, l_des, n_des, invert)


def surface_deflections(c: Any, qbar: float, vt: float, alpha: float, beta: float, p: float, q: float, r: float,
                        m_des: float, l_des: float, n_des: float, invert: bool) -> tuple[float, float, float]:
    """Surface commands ``(aileron, elevator, rudder)`` normalised to [-1, 1] (NaN gives 0) that
    give the moment demands ``m_des`` (pitch), ``l_des`` (roll), ``n_des`` (yaw) [N m] with the
    coefficient vector ``c`` at dynamic pressure ``qbar`` [Pa, >= 1] and airspeed ``vt`` [m/s],
    ``alpha``, ``beta`` [rad], body rates ``p, q, r`` [rad/s]; ``invert``: the free moments are
    subtracted (else the elevator's trim is added) -- the second half of :func:`law_commands`."""
    S, b, cc = c[COEF.s], c[COEF.b], c[COEF.c]
    # moment demands -> deflections, rad
    qSb = qbar * S * b
    if invert:
        v = vt
        if 1.0 > v:
            v = 1.0
        cm_free = c[COEF.cm0] + c[COEF.cm_alpha] * alpha + c[COEF.cm_q] * q * cc / (2 * v)
        de = (m_des / (qbar * S * cc) - cm_free) / c[COEF.cm_de]
        cl_free = c[COEF.cl_beta] * beta + (c[COEF.cl_p] * p + c[COEF.cl_r] * r) * b / (2 * v)
        da = (l_des / qSb - cl_free) / c[COEF.cl_da]
    else:
        de = c[COEF.de_trim] + m_des / (qbar * S * cc * c[COEF.cm_de])
        da = l_des / (qSb * c[COEF.cl_da])
    dr = n_des / (qSb * c[COEF.cn_dr])
    a, e, rr = da / c[COEF.lim_a], de / c[COEF.lim_e], dr / c[COEF.lim_r]
    return (-1.0 if a < -1.0 else 1.0 if a > 1.0 else (a if a == a else 0.0),
            -1.0 if e < -1.0 else 1.0 if e > 1.0 else (e if e == e else 0.0),
            -1.0 if rr < -1.0 else 1.0 if rr > 1.0 else (rr if rr == rr else 0.0))


class AttitudeLaw:
    """``commands(s, alpha_cmd, e_phi, p_ref, q_ref, r_ref, dt) -> (aileron, elevator, rudder)``,
    normalised to [-1, 1]; holds the integrators ``integ`` (layout :data:`INTEG`, float64) and
    the coefficient vector ``coef`` (layout :data:`COEF`, float64, refreshed with the fold state)."""

    def __init__(self, glider: JSBSimGlider, gains: StabilizerGains, *, invert_free_moments: bool,
                 bank_integral: bool) -> None:
        self.glider = glider
        self.gains = gains
        self.invert_free_moments = invert_free_moments
        self.bank_integral = bank_integral
        self.coef = slots.new(COEF, np.nan)  #: the coefficient vector (layout COEF)
        lim = glider.surface_limits_rad
        self.coef[COEF.s], self.coef[COEF.b], self.coef[COEF.c] = glider.reference_geometry()
        self.coef[COEF.lim_e], self.coef[COEF.lim_a], self.coef[COEF.lim_r] = (lim["elevator"], lim["aileron"],
                                                                              lim["rudder"])
        #: the fold state of the last reading of the derivatives (-1: none yet)
        self.fold_at = np.array([-1.0])
        self.integ = slots.new(INTEG)  #: the integrators (layout INTEG), rad s

    def reset(self) -> None:
        """Zero the integrators (alpha, bank)."""
        self.integ[INTEG.alpha] = self.integ[INTEG.phi] = 0.0

    def invalidate(self) -> None:
        """Re-read derivatives, inertia and trim at the next command (e.g. a new alpha command
        for the trim feed-forward)."""
        self.fold_at[0] = -1.0

    def _refresh(self, fold: float, alpha_cmd: float) -> None:
        """Read derivatives and inertia at fold state ``fold`` (:func:`law_refresh`) and, without
        the inversion, the elevator's trim (rad) at ``alpha_cmd`` (rad), into :attr:`coef`."""
        g = self.glider
        self.fold_at[0] = fold
        c = self.coef
        law_refresh([float(g.coefficient(n)) for n in LAW_PROPERTIES], c, SLUG_FT2, self.invert_free_moments)
        if not self.invert_free_moments:
            c[COEF.de_trim] = g.trim_elevator(alpha_cmd) * c[COEF.lim_e]

    def coefficients(self, fold: float, alpha_cmd: float) -> np.ndarray:
        """The coefficient vector (layout :data:`COEF`) at fold state ``fold``, re-read when the fold
        state moved by 1e-3 or more since the last reading (:attr:`fold_at`; or after
        :meth:`invalidate`; the trim at ``alpha_cmd``, rad)."""
        if law_stale(fold, self.fold_at[0]):
            self._refresh(fold, alpha_cmd)
        return self.coef

    def commands(self, s: SixDofState, alpha_cmd: float, e_phi: float, p_ref: float, q_ref: float,
                 r_ref: float, dt: float) -> tuple[float, float, float]:
        """Surface commands for angle-of-attack command ``alpha_cmd`` and bank error ``e_phi``
        (rad), damping relative to body rates ``p_ref, q_ref, r_ref`` (rad/s); ``dt`` (s) the
        time since the last call (0: no integration). NaN deflections give 0."""
        # the co-simulation's hot path: the state's values straight from its raw row (the same
        # numbers as SixDofState's properties without a call each)
        fold, qbar, vt, alpha, beta, p, q, r = _LAW_ROW(s.raw)
        kq, kv = _LAW_SCALE(s.scale)
        return law_commands(self.coefficients(fold, alpha_cmd), self.gains.law_gains(), qbar * kq, vt * kv, alpha,
                            beta, p, q, r, alpha_cmd, e_phi, p_ref, q_ref, r_ref, dt,
                            self.integ, self.invert_free_moments, self.bank_integral)
