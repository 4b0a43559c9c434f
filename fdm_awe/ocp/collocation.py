"""Direct collocation of the two-phase periodic cycle (Radau IIA, CasADi SX + IPOPT/MUMPS).

Each phase ``p`` has ``N_p`` intervals of equal length ``h_p = T_p / N_p`` (free durations
``T_1``, ``T_2``), Radau collocation of degree ``d`` (the last collocation point is the next
mesh node), and piecewise-constant controls (one value per interval, so the optimal controls
are exactly defined for re-integration). Decision variables are scaled (``value = scale *
variable``); collocation residuals are divided by the state scales.

Fold transitions: when the wing takes time to fold
(:attr:`fdm_awe.ocp.model.CycleModel.fold_time` > 0), the recovery's first and last
:func:`fold_intervals` intervals span exactly the fold and the unfold (each ``fold_time /
n_fold`` long) and the others share the rest, ``(T_2 - 2 fold_time) / (N_2 - 2 n_fold)``
(:func:`interval_lengths`). The fold state is linear in time inside a transition interval and
1 outside, so every collocation point has a fixed fold state (:func:`interval_fold`, the law of
:func:`fdm_awe.ocp.model.fold_fraction` at that point's time), the dynamics stay smooth within
each interval, and ``T_2 >= 2 fold_time``. A transition interval's angle of attack is bounded
by the stall limits of every wing it passes through.

Constraints (docs/design.md section 4, Table 3):
- variable bounds: airspeed, |gamma|, ground clearance (``z <= -h_min``), controls (alpha with
  the stall limit, bank, thrust, tension, reel-in speed), phase durations;
- path constraints at the phase start and every collocation point: ``ddot >= 0`` and, where
  tension follows the generator, ``G <= G_max`` in generation; ``d <= l`` in recovery; in the
  ``physical`` scenario the thrust at most what the propeller gives at the airspeed
  (``T <= T_avail(V)`` from the aircraft definition);
- boundaries: start position fixed, ``d(T_1) = d_tf``, continuity between the phases
  (position, airspeed, angles; tether length ``l = d_tf``), periodicity back to the start
  (airspeed, flight-path angle, heading + ``2 pi k``; ``l = d0``), ``T_1 + T_2 <= t_max``.

Objective: maximise the average net power ``(E_gen - E_thr - E_rw)/(T_1 + T_2)`` (energies by
Radau quadrature), plus a small penalty on control changes between intervals that keeps the
reference smooth for the autopilot (``REG_WEIGHT``; reported energies never include it).

Parameters of the NLP (changeable without rebuilding): wind north/east [m/s], the tether-drag
homotopy factor (0..1), the heading wrap count ``k``, the recovery-aerodynamics morph
(0 = unfolded, 1 = the configuration's recovery form; a homotopy path for the foldable glider),
the weight of the elastic penalty and the thrust-bound blend (1 = ``T <= T_avail(V)``, 0 = the
static ``T_max``; used to show where the foldable cycle's infeasibility comes from).

Elastic mode (a feasibility aid): every recovery interval carries fictitious accelerations on
the airspeed, flight-path-angle and heading equations, each the difference of two non-negative
variables with an exact L1 penalty. Their bounds are [0, 0] (the strict problem, the only one
whose solutions are reported) unless :meth:`CycleNLP.solve` is called with ``elastic=True``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from .energy import ideal_generator_current
from .model import GEN_STATES, ON_FRACTION, REC_STATES, CycleModel
from .problem import CycleProblem

#: Weight of the control-smoothing penalty (per interval, on scaled control changes) relative
#: to the scaled objective (average power / 10 W). Small enough to change P_avg by well
#: under 1 %; checked by tests that compare it with the reported physics energies.
REG_WEIGHT = 1e-3
P_SCALE = 10.0  #: objective scale [W]

STATE_SCALE = {"x": 100.0, "y": 100.0, "z": 100.0, "V": 10.0, "gamma": 1.0, "psi": 1.0, "l": 100.0}
CONTROL_SCALE = {"alpha": 0.3, "phi": 1.0, "T": 5.0, "G": 30.0, "v_reel": 5.0, "s": 1.0, "D2": 0.5}
TIME_SCALE = 10.0
NP = 7  #: number of NLP parameters
#: elastic slacks of the recovery dynamics: fictitious accelerations added to the airspeed
#: [m/s^2], flight-path-angle and heading [rad/s] equations, one value per interval, each split
#: into a positive and a negative part (scale of the variables)
SLACK_SCALE = {"V": 1.0, "gamma": 0.1, "psi": 0.1}
#: IPOPT defaults of every solve: iterations per solve (the deterministic limit) and a CPU-time
#: safety net [s]
DEFAULT_MAX_ITER = 500
DEFAULT_MAX_CPU_S = 900.0
#: upper bound of a scaled elastic slack when the elastic mode is on (0 when off)
SLACK_MAX = 100.0


#: longest mesh interval of a fold transition [s]: the fold and the unfold each get
#: ``ceil(fold_time / FOLD_INTERVAL_S)`` intervals (at most a quarter of the recovery's each)
FOLD_INTERVAL_S = 1.0


def fold_intervals(n: int, fold_time: float) -> int:
    """Mesh intervals of each fold transition in a recovery of ``n`` intervals (0 without one)."""
    if fold_time <= 0.0:
        return 0
    return max(1, min(math.ceil(fold_time / FOLD_INTERVAL_S - 1e-9), n // 4))


def interval_lengths(T: Any, n: int, fold_time: float = 0.0, n_fold: int = 0) -> list[Any]:
    """Length [s] of each of the ``n`` intervals of a phase lasting ``T`` [s] (a number or a
    symbol): equal, or with ``n_fold`` intervals spanning each fold transition of ``fold_time``."""
    if n_fold == 0:
        return [T / n] * n
    hf = fold_time / n_fold
    hm = (T - 2.0 * fold_time) / (n - 2 * n_fold)
    return [hf] * n_fold + [hm] * (n - 2 * n_fold) + [hf] * n_fold


def interval_fold(k: int, tau: float, n: int, n_fold: int) -> float | None:
    """Fold state at local time ``tau`` in [0, 1] of interval ``k`` of the recovery's ``n``
    (:func:`interval_lengths`): rising over the first ``n_fold`` intervals, falling over the
    last ``n_fold``; None in between (folded, the recovery form itself)."""
    if k < n_fold:
        return (k + tau) / n_fold
    if k >= n - n_fold:
        return 1.0 - (k - (n - n_fold) + tau) / n_fold
    return None


def radau_coefficients(d: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Radau points ``tau`` (with 0 prepended), derivative matrix ``C``, continuity ``D`` and
    quadrature weights ``B`` of the Lagrange basis on [0, 1]."""
    tau = np.append(0.0, ca.collocation_points(d, "radau"))
    C = np.zeros((d + 1, d + 1))
    D = np.zeros(d + 1)
    B = np.zeros(d + 1)
    for j in range(d + 1):
        p = np.poly1d([1.0])
        for r in range(d + 1):
            if r != j:
                p *= np.poly1d([1.0, -tau[r]]) / (tau[j] - tau[r])
        D[j] = p(1.0)
        dp = np.polyder(p)
        for r in range(d + 1):
            C[j, r] = dp(tau[r])
        B[j] = np.polyint(p)(1.0)
    return tau, C, D, B


@dataclass
class PhaseLayout:
    """Where one phase's variables live in the decision vector."""

    states: tuple[str, ...]
    controls: tuple[str, ...]
    n: int
    X: list[list[Any]] = field(default_factory=list)  #: X[k][j] symbols (value units), j = 0..d
    U: list[Any] = field(default_factory=list)  #: U[k] symbols (value units)
    T: Any = None
    idx_X: np.ndarray | None = None  #: (n, d+1, nx) indices into w (j = d of k is node k+1)
    idx_U: np.ndarray | None = None  #: (n, nu)
    idx_T: int = -1
    n_fold: int = 0  #: intervals of each fold transition (recovery of a folding wing), else 0
    fold_time: float = 0.0  #: [s]

    def lengths(self, T: Any) -> list[Any]:
        """Interval lengths [s] for phase duration ``T`` (:func:`interval_lengths`)."""
        return interval_lengths(T, self.n, self.fold_time, self.n_fold)

    def node_times(self, T: float) -> np.ndarray:
        """Interval bounds [s] (``n + 1`` values from 0 to ``T``) for phase duration ``T``."""
        if self.n_fold == 0:
            return np.arange(self.n + 1) * (T / self.n)
        return np.concatenate(([0.0], np.cumsum(self.lengths(T))))

    def time(self, t_nodes: np.ndarray, k: int, tau: float) -> float:
        """Time [s] at local time ``tau`` in [0, 1] of interval ``k`` (bounds ``t_nodes``)."""
        if self.n_fold == 0:
            return (k + tau) * t_nodes[1]
        return t_nodes[k] + tau * (t_nodes[k + 1] - t_nodes[k])

    def fold(self, k: int, tau: float) -> float | None:
        """Fold state in interval ``k`` at local time ``tau`` (None: the phase's own wing)."""
        return interval_fold(k, tau, self.n, self.n_fold) if self.n_fold else None


#: IPOPT interface option -> name of the function it replaces inside CasADi's IPOPT instance
_DERIVATIVES = (("grad_f", "nlp_grad_f"), ("jac_g", "nlp_jac_g"), ("hess_lag", "nlp_hess_l"))


@dataclass
class RawSolution:
    """What IPOPT returned, unscaled and unpacked."""

    status: str  #: "ok" or "failed"
    reason: str  #: IPOPT return status text
    iterations: int
    solve_s: float
    w: np.ndarray  #: scaled decision vector
    lam_x: np.ndarray
    lam_g: np.ndarray
    objective: float
    params: np.ndarray


class CycleNLP:
    """The transcribed NLP for one problem structure (scenario, configuration, mesh).

    Build once, then :meth:`solve` with any wind, drag factor and heading wrap.
    """

    def __init__(self, problem: CycleProblem, model: CycleModel, ipopt_options: dict | None = None) -> None:
        t0 = time.perf_counter()
        self.problem = problem.validate()
        self.model = model
        mesh = problem.mesh
        self.d = mesh.degree
        self.tau, self.C, self.D, self.B = radau_coefficients(self.d)
        self.phases = [
            PhaseLayout(GEN_STATES, model.gen_controls, mesh.n_gen),
            PhaseLayout(REC_STATES, model.rec_controls, mesh.n_rec),
        ]
        if model.folds:
            rec = self.phases[1]
            rec.n_fold, rec.fold_time = fold_intervals(rec.n, model.fold_time), model.fold_time
        self._build()
        self._extra = dict(ipopt_options or {})
        self._solvers: dict[tuple, Any] = {}
        self._derivatives: dict[str, Any] = {}  # IPOPT option -> derivative function (see _solver)
        #: wall time [s] spent creating IPOPT instances so far (one per option set, created on
        #: first use, so a caller that always passes options, like a sweep, does not pay for the
        #: default instance)
        self.solvers_build_s = 0.0
        self.build_s = time.perf_counter() - t0

    @property
    def solver(self) -> Any:
        """The IPOPT instance with the default options."""
        return self._solver(None)

    # ------------------------------------------------------------------ build
    def _build(self) -> None:
        pr, m = self.problem, self.model
        bnd = pr.bounds
        d, C, B = self.d, self.C, self.B
        p_sym = ca.SX.sym("p", NP)  # wind north, wind east, tether-drag factor, heading wrap k, morph, penalty
        wind = (p_sym[0], p_sym[1])
        drag = p_sym[2]
        kwrap = p_sym[3]

        w_parts: list[Any] = []
        lbw: list[float] = []
        ubw: list[float] = []
        g: list[Any] = []
        lbg: list[float] = []
        ubg: list[float] = []
        self.g_names: list[str] = []
        nw = 0

        def new_var(name: str, scale: float, lo: float, hi: float) -> tuple[Any, int]:
            nonlocal nw
            v = ca.SX.sym(name)
            w_parts.append(v)
            lbw.append(lo / scale)
            ubw.append(hi / scale)
            nw += 1
            return v * scale, nw - 1

        def add(expr: Any, lo: float, hi: float, name: str) -> None:
            g.append(expr)
            lbg.append(lo)
            ubg.append(hi)
            self.g_names.append(name)

        T_max = bnd.T_max if bnd.T_max is not None else m.gen_airframe.propulsion.T_max
        v_in = bnd.reel_in_speed_max if bnd.reel_in_speed_max is not None else m.winch.reel_in_speed_max()
        self.reel_in_speed_max = v_in
        self.T_max = T_max
        G_lo = bnd.G_min
        state_bounds = {
            "x": (-10 * pr.d_tf, 10 * pr.d_tf), "y": (-10 * pr.d_tf, 10 * pr.d_tf), "z": (-10 * pr.d_tf, -bnd.h_min),
            "V": (bnd.V_min, bnd.V_max), "gamma": (-bnd.gamma_max, bnd.gamma_max), "psi": (-60.0, 60.0),
            "l": (0.0, 10 * pr.d_tf),
        }
        P0 = pr.start_position
        E_gen = E_thr = E_rw = 0.0
        reg = 0.0
        slack_sum = 0.0
        self.idx_slack: list[int] = []
        for ip, ph in enumerate(self.phases):
            a_hi = m.alpha_upper(ip, bnd.alpha_max, bnd.cl_margin)
            a_lo = m.alpha_lower(ip, bnd.alpha_max, bnd.cl_margin)
            ctrl_bounds = {"alpha": (a_lo, a_hi), "phi": (-bnd.phi_max, bnd.phi_max), "T": (0.0, T_max),
                           "G": (G_lo, bnd.G_max), "v_reel": (-v_in, 0.0), "s": (0.0, 1.0),
                           "D2": (0.0, m.winch.boost_duty_max)}
            # a folding wing needs the whole fold and unfold inside the recovery
            ph.T, ph.idx_T = new_var(f"T{ip + 1}", TIME_SCALE, max(bnd.T_phase_min, 2.0 * ph.fold_time), bnd.t_max)
            nx, nu = len(ph.states), len(ph.controls)
            ph.idx_X = np.zeros((ph.n, d + 1, nx), dtype=int)
            ph.idx_U = np.zeros((ph.n, nu), dtype=int)
            F = self._point_function(ip, nx, len(ph.controls))
            F_fold = self._point_function(ip, nx, len(ph.controls), fold=True) if ph.n_fold else None
            hs = ph.lengths(ph.T)
            xs = [STATE_SCALE[s] for s in ph.states]

            def state_vars(tag: str) -> tuple[list[Any], list[int]]:
                vals, ids = [], []
                for s in ph.states:
                    lo, hi = state_bounds[s]
                    v, i = new_var(f"{s}_{tag}", STATE_SCALE[s], lo, hi)
                    vals.append(v)
                    ids.append(i)
                return vals, ids

            node, node_ids = state_vars(f"p{ip}_0")
            ph.X = []
            ph.U = []
            prev_u = None
            for k in range(ph.n):
                h = hs[k]
                folds = [ph.fold(k, self.tau[j]) for j in range(d + 1)]
                bounds_k = dict(ctrl_bounds)
                if folds[0] is not None:
                    # stall limits of the wing at every fold state this interval passes through
                    wings = [m.fold_aero(f) for f in folds]
                    bounds_k["alpha"] = (max(m.alpha_lower(ip, bnd.alpha_max, bnd.cl_margin, a) for a in wings),
                                         min(m.alpha_upper(ip, bnd.alpha_max, bnd.cl_margin, a) for a in wings))
                u, u_ids = [], []
                for c in ph.controls:
                    lo, hi = bounds_k[c]
                    v, i = new_var(f"{c}_p{ip}_{k}", CONTROL_SCALE[c], lo, hi)
                    u.append(v)
                    u_ids.append(i)
                ph.idx_U[k] = u_ids
                ph.U.append(u)
                extra = [0.0] * nx
                if ip == 1:  # elastic slacks (bounds [0, 0] unless the elastic mode opens them)
                    for i_s, s_name in enumerate(ph.states):
                        if s_name not in SLACK_SCALE:
                            continue
                        sp, i_p = new_var(f"slack+_{s_name}_p1_{k}", SLACK_SCALE[s_name], 0.0, 0.0)
                        sn, i_n = new_var(f"slack-_{s_name}_p1_{k}", SLACK_SCALE[s_name], 0.0, 0.0)
                        self.idx_slack += [i_p, i_n]
                        extra[i_s] = sp - sn
                        slack_sum = slack_sum + (sp + sn) / SLACK_SCALE[s_name]
                pts = [node]
                ph.idx_X[k, 0] = node_ids
                for j in range(1, d + 1):
                    vals, ids = state_vars(f"p{ip}_{k}_{j}")
                    pts.append(vals)
                    ph.idx_X[k, j] = ids
                ph.X.append(pts)
                # path constraints at the phase start
                uv = ca.vertcat(*u)

                def point(j: int) -> Any:
                    args = (ca.vertcat(*pts[j]), uv, p_sym)
                    return F(*args) if folds[j] is None else F_fold(*args, folds[j])

                if k == 0:
                    out = point(0)
                    self._path(ip, out[2], add, f"p{ip}_start")
                for j in range(1, d + 1):
                    fj, pw, path = point(j)
                    for i_s in range(nx):
                        xp = sum(C[r, j] * pts[r][i_s] for r in range(d + 1))
                        add((xp - h * (fj[i_s] + extra[i_s])) / xs[i_s], 0.0, 0.0, f"coll_p{ip}_{k}_{j}_{ph.states[i_s]}")
                    self._path(ip, path, add, f"p{ip}_{k}_{j}")
                    E_gen = E_gen + B[j] * h * pw[0]
                    E_thr = E_thr + B[j] * h * pw[1]
                    E_rw = E_rw + B[j] * h * pw[2]
                if prev_u is not None:
                    reg = reg + sum(((u[i] - prev_u[i]) / CONTROL_SCALE[c]) ** 2 for i, c in enumerate(ph.controls))
                prev_u = u
                node, node_ids = pts[d], list(ph.idx_X[k, d])
        gen, rec = self.phases
        x0 = gen.X[0][0]
        xe1 = gen.X[-1][d]
        x20 = rec.X[0][0]
        xe2 = rec.X[-1][d]
        for i in range(3):
            add((x0[i] - P0[i]) / 100.0, 0.0, 0.0, f"start_{GEN_STATES[i]}")
        d_end = ca.sqrt(xe1[0] ** 2 + xe1[1] ** 2 + xe1[2] ** 2)
        add((d_end - pr.d_tf) / 100.0, 0.0, 0.0, "d_tf")
        for i, s in enumerate(GEN_STATES):
            add((x20[i] - xe1[i]) / STATE_SCALE[s], 0.0, 0.0, f"continuity_{s}")
        add((x20[6] - pr.d_tf) / 100.0, 0.0, 0.0, "continuity_l")
        for i in range(3):
            add((xe2[i] - P0[i]) / 100.0, 0.0, 0.0, f"periodic_{GEN_STATES[i]}")
        add((xe2[3] - x0[3]) / 10.0, 0.0, 0.0, "periodic_V")
        add(xe2[4] - x0[4], 0.0, 0.0, "periodic_gamma")
        add(xe2[5] - x0[5] - 2 * math.pi * kwrap, 0.0, 0.0, "periodic_psi")
        add((xe2[6] - pr.d0) / 100.0, 0.0, 0.0, "periodic_l")
        add((gen.T + rec.T) / TIME_SCALE, 0.0, bnd.t_max / TIME_SCALE, "t_max")

        P_avg = (E_gen - E_thr - E_rw) / (gen.T + rec.T)
        J = -P_avg / P_SCALE + REG_WEIGHT * reg + p_sym[5] * slack_sum / max(1, len(self.phases[1].U))
        self.nlp = {"x": ca.vertcat(*w_parts), "p": p_sym, "f": J, "g": ca.vertcat(*g)}
        self.lbw, self.ubw = np.array(lbw), np.array(ubw)
        self.lbg, self.ubg = np.array(lbg), np.array(ubg)
        self.energy_fn = ca.Function("energies", [self.nlp["x"], p_sym], [E_gen, E_thr, E_rw, gen.T, rec.T])
        self.g_fn = ca.Function("g", [self.nlp["x"], p_sym], [self.nlp["g"]])
        self.nw = nw

    def _point_function(self, ip: int, nx: int, nu: int, fold: bool = False) -> ca.Function:
        """CasADi function (state, control, params) -> (derivative, [P_gen, P_thr, P_rw], path);
        ``fold``: a recovery point of a fold transition, with the fold state as a fourth input."""
        s = ca.SX.sym("s", nx)
        u = ca.SX.sym("u", nu)
        p = ca.SX.sym("p", NP)
        f = ca.SX.sym("fold")
        args = ([s[i] for i in range(nx)], [u[i] for i in range(nu)], (p[0], p[1]), p[2])
        out = self.model.generation(*args) if ip == 0 else self.model.recovery(*args, p[4], f if fold else None)
        if ip == 0:
            path = [out["v_reel"], out["G"]]
            if self.model.scenario.generator == "ideal":  # the half-bridge carries one current direction
                path.append(ideal_generator_current(out["G"], out["v_reel"], self.model.winch))
        else:
            path = [out["l"] - out["d"]]
        if self.model.scenario.propeller in ("physical", "engine"):
            # thrust within what the propeller gives at this airspeed (full throttle); p[6] < 1
            # blends the bound towards the static T_max (a homotopy path only)
            prop = self.model.gen_airframe.propulsion
            path.append(p[6] * (prop.thrust_available(s[3]) - prop.T_max) + prop.T_max - u[2])
        return ca.Function(f"phase{ip}" + ("_fold" if fold else ""), [s, u, p] + ([f] if fold else []),
                           [ca.vertcat(*out["f"]), ca.vertcat(out["P_gen"], out["P_thr"], out["P_rw"]), ca.vertcat(*path)])

    def _path(self, ip: int, path: Any, add, tag: str) -> None:
        bnd, m = self.problem.bounds, self.model
        if ip == 0:
            add(path[0] / 5.0, 0.0, ca.inf, f"ddot_{tag}")
            if not m.scenario.tension_control:
                add(path[1] / 30.0, bnd.G_min / 30.0, bnd.G_max / 30.0, f"G_{tag}")
            if m.scenario.generator == "ideal":
                add(path[2] / 10.0, 0.0, ca.inf, f"current_{tag}")
        else:
            add(path[0] / 100.0, 0.0, ca.inf, f"slack_{tag}")
        if m.scenario.propeller in ("physical", "engine"):
            add(path[-1] / 5.0, 0.0, ca.inf, f"thrust_avail_{tag}")

    # ------------------------------------------------------------------ solve
    def params(self, wind_ned: tuple[float, float], drag_factor: float = 1.0, k_wrap: int = 0, morph: float = 1.0,
               penalty: float = 0.0, thrust_bound: float = 1.0) -> np.ndarray:
        """NLP parameter vector: wind north/east [m/s], tether-drag factor, heading wrap count,
        recovery-aerodynamics morph (1 = the configuration's own recovery form), weight of the
        exact (L1) penalty on the elastic slacks (used only in the elastic mode), and the
        thrust-bound blend (1 = ``T <= T_avail(V)``, 0 = ``T <= T_max``; < 1 only on a homotopy
        path)."""
        return np.array([wind_ned[0], wind_ned[1], drag_factor, float(k_wrap), morph, penalty, thrust_bound])

    def max_slack(self, w: np.ndarray) -> float:
        """Largest elastic slack in ``w`` (scaled; 0 for a solution of the strict problem)."""
        return float(np.max(np.abs(w[self.idx_slack]))) if self.idx_slack else 0.0

    def solve(self, w0: np.ndarray, params: np.ndarray, lam_x0: np.ndarray | None = None,
              lam_g0: np.ndarray | None = None, options: dict | None = None, elastic: bool = False) -> RawSolution:
        """Run IPOPT from the scaled start ``w0``; ``lam_*`` enable a warm start. ``elastic``
        opens the bounds of the recovery's elastic slacks (a feasibility aid: such a solution
        only serves as a start of the strict problem, whose slacks are fixed at zero)."""
        solver = self._solver(options)
        ubw = self.ubw
        if elastic:
            ubw = self.ubw.copy()
            ubw[self.idx_slack] = SLACK_MAX
        else:
            w0 = np.array(w0, float)
            w0[self.idx_slack] = 0.0
            lam_x0 = None if lam_x0 is None else np.where(np.isin(np.arange(self.nw), self.idx_slack), 0.0, lam_x0)
        args = {"x0": np.clip(w0, self.lbw, ubw), "p": params, "lbx": self.lbw, "ubx": ubw,
                "lbg": self.lbg, "ubg": self.ubg}
        if lam_x0 is not None:
            args["lam_x0"] = lam_x0
        if lam_g0 is not None:
            args["lam_g0"] = lam_g0
        t0 = time.perf_counter()
        try:
            sol = solver(**args)
            st = solver.stats()
        except RuntimeError as exc:  # evaluation errors (NaN) surface as exceptions
            return RawSolution("failed", f"solver error: {exc}".splitlines()[0], 0, time.perf_counter() - t0,
                               np.asarray(w0, float), np.zeros(self.nw), np.zeros(len(self.lbg)), math.nan, params)
        dt = time.perf_counter() - t0
        ok = bool(st.get("success", False))
        reason = str(st.get("return_status", "unknown"))
        it = int(st.get("iter_count", 0))
        return RawSolution("ok" if ok else "failed", reason, it, dt, np.array(sol["x"]).ravel(),
                           np.array(sol["lam_x"]).ravel(), np.array(sol["lam_g"]).ravel(), float(sol["f"]), params)

    def _solver(self, options: dict | None) -> Any:
        """IPOPT instance for these extra options (built once per option set).

        The derivative functions IPOPT evaluates (objective gradient, constraint Jacobian,
        Hessian of the Lagrangian) do not depend on the options: the first instance generates
        them (symbolic differentiation, most of an instance's creation time: 0.8 s at mesh 10/8),
        later instances are handed the same functions (0.1 s), so they evaluate exactly what
        their own would have (bit-identical iterates).
        """
        key = tuple(sorted((options or {}).items()))
        if key not in self._solvers:
            t0 = time.perf_counter()
            opts = {**self._base_opts(), **self._extra, **(options or {}), **self._derivatives}
            solver = ca.nlpsol("cycle", "ipopt", self.nlp, opts)
            for opt, name in _DERIVATIVES:
                if opt not in self._derivatives and solver.has_function(name):
                    self._derivatives[opt] = solver.get_function(name)
            self._solvers[key] = solver
            self.solvers_build_s += time.perf_counter() - t0
        return self._solvers[key]

    def _base_opts(self) -> dict:
        """IPOPT defaults of this NLP.

        Optimality tolerance 1e-6 and constraint tolerance 1e-7 (scaled): an accepted solution
        must hold every scaled constraint within 1e-6 (``solve.VIOLATION_TOL``), and the
        re-integration check (:data:`fdm_awe.ocp.verify.POSITION_TOL_REL`, ``ENERGY_TOL_REL``) is met with a
        wide margin at the default mesh.
        Monotone (Fiacco-McCormick) barrier: the adaptive strategy's extra linear solves per
        iteration cost more than they save here. Measured at the default mesh (physical nominal
        3..12 m/s, paper 3 m/s both configurations; each accepted and re-integrated): 2606
        instead of 4445 iterations in total, 8 m/s physical 246 -> 127, paper foldable 351 -> 193;
        powers equal where the same local optimum is reached (others move by up to 2.8 W).
        """
        return {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.linear_solver": "mumps",
                "ipopt.max_iter": DEFAULT_MAX_ITER, "ipopt.tol": 1e-6, "ipopt.constr_viol_tol": 1e-7,
                "ipopt.acceptable_iter": 0, "ipopt.mu_strategy": "monotone", "ipopt.max_cpu_time": DEFAULT_MAX_CPU_S}

    # ------------------------------------------------------------------ unpack
    def unpack(self, w: np.ndarray) -> list[dict[str, np.ndarray]]:
        """Per phase: ``t`` (node + internal collocation times) [s], ``X`` (points x states),
        ``U`` (intervals x controls), ``T`` [s], ``t_nodes`` [s] (interval bounds), ``fold``
        (fold state at each point of ``t``: 0 unfolded .. 1 folded), in value units."""
        scale = np.empty(self.nw)
        # scale of each variable: rebuild from layout
        out = []
        d = self.d
        for ip, ph in enumerate(self.phases):
            xs = np.array([STATE_SCALE[s] for s in ph.states])
            us = np.array([CONTROL_SCALE[c] for c in ph.controls])
            T = float(w[ph.idx_T] * TIME_SCALE)
            pts = []
            ts = []
            folds = []
            own = 1.0 if (ip == 1 and self.model.rec_airframe is not self.model.gen_airframe) else 0.0
            t_nodes = ph.node_times(T)
            for k in range(ph.n):
                for j in range(d):
                    pts.append(w[ph.idx_X[k, j]] * xs)
                    ts.append(ph.time(t_nodes, k, self.tau[j]))
                    f = ph.fold(k, self.tau[j])
                    folds.append(own if f is None else f)
            pts.append(w[ph.idx_X[ph.n - 1, d]] * xs)
            ts.append(T)
            f = ph.fold(ph.n - 1, 1.0)
            folds.append(own if f is None else f)
            U = w[ph.idx_U] * us
            out.append({"t": np.array(ts), "X": np.array(pts), "U": U, "T": T, "t_nodes": t_nodes,
                        "fold": np.array(folds), "states": ph.states, "controls": ph.controls})
        del scale
        return out

    def pack(self, phases: list[dict[str, Any]]) -> np.ndarray:
        """Scaled decision vector from per-phase guesses: ``T`` [s], ``state(t)`` callable
        returning the state vector at time t, ``control(t)`` callable returning controls."""
        w = np.zeros(self.nw)
        d = self.d
        for ph, gs in zip(self.phases, phases):
            xs = np.array([STATE_SCALE[s] for s in ph.states])
            us = np.array([CONTROL_SCALE[c] for c in ph.controls])
            T = gs["T"]
            w[ph.idx_T] = T / TIME_SCALE
            # node times of the guess (its duration stretched to hold a fold and an unfold)
            t_nodes = ph.node_times(max(T, 2.0 * ph.fold_time))
            if ph.n_fold:
                t_nodes = t_nodes * (T / t_nodes[-1])
            for k in range(ph.n):
                u = np.asarray(gs["control"](ph.time(t_nodes, k, 0.5)), float)
                if len(u) == len(ph.controls) - 1 and ph.controls[-1] == ON_FRACTION:
                    u = np.append(u, 1.0)  # a guess without the motor's on-fraction: motor running
                w[ph.idx_U[k]] = u / us
                for j in range(d + 1):
                    w[ph.idx_X[k, j]] = np.asarray(gs["state"](ph.time(t_nodes, k, self.tau[j])), float) / xs
        return w

    def constraint_violation(self, w: np.ndarray, params: np.ndarray) -> tuple[float, str]:
        """Largest violation of the scaled constraints and bounds, and where."""
        gv = np.array(self.g_fn(w, params)).ravel()
        viol_g = np.maximum(self.lbg - gv, 0) + np.maximum(gv - self.ubg, 0)
        viol_x = np.maximum(self.lbw - w, 0) + np.maximum(w - self.ubw, 0)
        ig, ix = int(np.argmax(viol_g)), int(np.argmax(viol_x))
        if viol_g[ig] >= viol_x[ix]:
            return float(viol_g[ig]), self.g_names[ig]
        return float(viol_x[ix]), f"bound of variable {ix}"

    def energies(self, w: np.ndarray, params: np.ndarray) -> dict[str, float]:
        E_gen, E_thr, E_rw, T1, T2 = (float(v) for v in self.energy_fn(w, params))
        return {"E_generated_J": E_gen, "E_thrust_J": E_thr, "E_reel_in_J": E_rw, "T1_s": T1, "T2_s": T2}
