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
"""

from __future__ import annotations

from dataclasses import dataclass

from .adapter import JSBSimGlider
from .row import ALPHA, BETA, FOLD, P_RATE, Q_RATE, QBAR, R_RATE, VT
from .state import SixDofState


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


class AttitudeLaw:
    """``commands(s, alpha_cmd, e_phi, p_ref, q_ref, r_ref, dt) -> (aileron, elevator, rudder)``,
    normalised to [-1, 1]; holds the integrators and the derivative cache."""

    def __init__(self, glider: JSBSimGlider, gains: StabilizerGains, *, invert_free_moments: bool,
                 bank_integral: bool) -> None:
        self.glider = glider
        self.gains = gains
        self.invert_free_moments = invert_free_moments
        self.bank_integral = bank_integral
        self._S, self._b, self._c = glider.reference_geometry()
        lim = glider.surface_limits_rad
        self._lim_e, self._lim_a, self._lim_r = lim["elevator"], lim["aileron"], lim["rudder"]
        self._coef_fold = -1.0
        self.reset()

    def reset(self) -> None:
        """Zero the integrators (alpha, bank)."""
        self._int = 0.0  # rad s
        self._int_phi = 0.0  # rad s

    def invalidate(self) -> None:
        """Re-read derivatives, inertia and trim at the next command (e.g. a new alpha command
        for the trim feed-forward)."""
        self._coef_fold = -1.0

    def _refresh(self, fold: float, alpha_cmd: float) -> None:
        """Read derivatives and inertia at fold state ``fold`` and, without the inversion, the
        elevator's trim (rad) at ``alpha_cmd`` (rad)."""
        g = self.glider
        self._coef_fold = fold

        def coef(name: str) -> float:
            return float(g.coefficient("aero/coef/" + name))

        self._cm_de, self._cl_da, self._cn_dr = coef("Cm_de"), coef("Cl_da"), coef("Cn_dr")
        self._cn_beta = coef("Cn_beta")
        if self.invert_free_moments:  # the free moments' derivatives
            self._cm0, self._cm_a, self._cm_q = coef("Cm0"), coef("Cm_alpha"), coef("Cm_q")
            self._cl_b, self._cl_p, self._cl_r = coef("Cl_beta"), coef("Cl_p"), coef("Cl_r")
        else:
            self._de_trim = g.trim_elevator(alpha_cmd) * self._lim_e
        J = g.inertia()
        self._ixx, self._iyy, self._izz = float(J[0, 0]), float(J[1, 1]), float(J[2, 2])

    def commands(self, s: SixDofState, alpha_cmd: float, e_phi: float, p_ref: float, q_ref: float,
                 r_ref: float, dt: float) -> tuple[float, float, float]:
        """Surface commands for angle-of-attack command ``alpha_cmd`` and bank error ``e_phi``
        (rad), damping relative to body rates ``p_ref, q_ref, r_ref`` (rad/s); ``dt`` (s) the
        time since the last call (0: no integration). NaN deflections give 0."""
        # the co-simulation's hot path: the state's values straight from its raw row (the same
        # numbers as SixDofState's properties without a call each), max/min and clipping spelled out
        gn = self.gains
        rw, kk = s._r, s._k
        fold = rw[FOLD]
        if not abs(fold - self._coef_fold) < 1e-3:
            self._refresh(fold, alpha_cmd)
        qbar = rw[QBAR] * kk[QBAR]
        if 1.0 > qbar:
            qbar = 1.0
        alpha, beta = rw[ALPHA], rw[BETA]
        p, q, r = rw[P_RATE], rw[Q_RATE], rw[R_RATE]
        S, b, c = self._S, self._b, self._c
        # pitch
        e_a = alpha_cmd - alpha
        ia = self._int + e_a * dt
        self._int = ia = (ia if ia > -0.2 else -0.2) if ia < 0.2 else 0.2
        w = gn.w_alpha
        m_des = self._iyy * (w * w * (e_a + gn.ki_alpha * ia) - 2 * gn.z_alpha * w * (q - q_ref))
        # roll
        if self.bank_integral:
            ip = self._int_phi + e_phi * dt
            self._int_phi = ip = (ip if ip > -0.5 else -0.5) if ip < 0.5 else 0.5
            e_phi = e_phi + gn.ki_phi * ip
        w = gn.w_phi
        l_des = self._ixx * (w * w * e_phi - 2 * gn.z_phi * w * (p - p_ref))
        # yaw
        n_des = -self._izz * 2 * gn.w_r * (r - r_ref) + gn.k_beta * qbar * S * b * self._cn_beta * beta
        # moment demands -> deflections, rad
        qSb = qbar * S * b
        if self.invert_free_moments:
            v = rw[VT] * kk[VT]
            if 1.0 > v:
                v = 1.0
            cm_free = self._cm0 + self._cm_a * alpha + self._cm_q * q * c / (2 * v)
            de = (m_des / (qbar * S * c) - cm_free) / self._cm_de
            cl_free = self._cl_b * beta + (self._cl_p * p + self._cl_r * r) * b / (2 * v)
            da = (l_des / qSb - cl_free) / self._cl_da
        else:
            de = self._de_trim + m_des / (qbar * S * c * self._cm_de)
            da = l_des / (qSb * self._cl_da)
        dr = n_des / (qSb * self._cn_dr)
        a, e, rr = da / self._lim_a, de / self._lim_e, dr / self._lim_r
        return (-1.0 if a < -1.0 else 1.0 if a > 1.0 else (a if a == a else 0.0),
                -1.0 if e < -1.0 else 1.0 if e > 1.0 else (e if e == e else 0.0),
                -1.0 if rr < -1.0 else 1.0 if rr > 1.0 else (rr if rr == rr else 0.0))
