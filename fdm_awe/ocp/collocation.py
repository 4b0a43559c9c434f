"""Direct collocation of the two-phase periodic cycle (Radau IIA, CasADi SX + IPOPT/MUMPS).

The decision vector (:mod:`.layout`): each phase's intervals (with the fold transitions of a
folding wing), Radau collocation points, piecewise-constant controls (one value per interval,
so the optimal controls are exactly defined for re-integration), scaled variables; collocation
residuals are divided by the state scales. The constraint groups (bounds, path constraints,
boundaries) are :mod:`.constraints`'. :class:`CycleNLP` transcribes the phases' dynamics
(:mod:`.model`) at every collocation point, counts the energies by Radau quadrature and hands
the NLP to IPOPT.

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
from dataclasses import dataclass
from typing import Any, Callable

import casadi as ca
import numpy as np

from .constraints import (Constraints, add_boundaries, add_catch, add_path, add_smoothness, control_bounds,
                          fold_alpha_bounds, point_path, reel_in_limit, state_bounds)
from .layout import (CONTROL_SCALE, SLACK_SCALE, STATE_SCALE, TIME_SCALE, PhaseLayout, Variables, fold_intervals,
                     radau_coefficients)
from .model import GEN_STATES, ON_FRACTION, REC_STATES, CycleModel
from .problem import CycleProblem

#: Weight of the control-smoothing penalty (per interval, on scaled control changes) relative
#: to the scaled objective (average power / 10 W). Small enough to change P_avg by well
#: under 1 %; checked by tests that compare it with the reported physics energies.
REG_WEIGHT = 1e-3
P_SCALE = 10.0  #: objective scale [W]
NP = 7  #: number of NLP parameters
#: IPOPT defaults of every solve: iterations per solve (the deterministic limit) and a CPU-time
#: safety net [s]
DEFAULT_MAX_ITER = 500
DEFAULT_MAX_CPU_S = 900.0
#: upper bound of a scaled elastic slack when the elastic mode is on (0 when off)
SLACK_MAX = 100.0


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


@dataclass
class _Sums:
    """Running sums of the transcription (CasADi expressions): the energies [J] by Radau
    quadrature, the control-smoothing penalty and the elastic slacks' L1 norm (both scaled)."""

    E_gen: Any = 0.0
    E_thr: Any = 0.0
    E_rw: Any = 0.0
    reg: Any = 0.0
    slack: Any = 0.0


#: attributes of a :class:`CycleNLP` that :meth:`CycleNLP.to_cache` leaves out: the inputs, the
#: IPOPT instances, the build times and the NLP and its derivatives (given apart)
_NOT_CACHED = frozenset({"problem", "model", "_solvers", "solvers_build_s", "build_s", "nlp", "_derivatives"})


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
        self._derivatives: dict[str, Any] = {}  # IPOPT option -> derivative function (see solver_for)
        #: wall time [s] spent creating IPOPT instances so far (one per option set, created on
        #: first use, so a caller that always passes options, like a sweep, does not pay for the
        #: default instance)
        self.solvers_build_s = 0.0
        self.build_s = time.perf_counter() - t0

    @property
    def solver(self) -> Any:
        """The IPOPT instance with the default options."""
        return self.solver_for(None)

    # ------------------------------------------------------------------ cache
    def derive(self) -> None:
        """Generate the derivative functions IPOPT evaluates (the default instance does so),
        unless an IPOPT instance of this NLP did already."""
        if not self._derivatives:
            self.solver

    def to_cache(self) -> tuple[dict[str, Any], Any, dict[str, Any]]:
        """What an on-disk cache keeps of this NLP (:mod:`.nlpcache`): ``(state, nlp,
        derivatives)``, the transcription's attributes by name (not the inputs, the IPOPT
        instances or the build times), the NLP function and the derivative functions by IPOPT
        option, sorted (generated first when no IPOPT instance did so yet)."""
        self.derive()
        state = {name: v for name, v in vars(self).items() if name not in _NOT_CACHED}
        return state, self.nlp, dict(sorted(self._derivatives.items()))

    @classmethod
    def from_cache(cls, problem: CycleProblem, model: CycleModel, state: dict[str, Any], nlp: Any,
                   derivatives: dict[str, Any]) -> "CycleNLP":
        """The NLP of ``problem``/``model`` from the parts :meth:`to_cache` gave for them, without
        building it again (no IPOPT instance yet; ``solvers_build_s`` 0)."""
        obj = cls.__new__(cls)
        obj.problem = problem.validate()
        obj.model = model
        for name, v in state.items():
            setattr(obj, name, v)
        obj.nlp = nlp
        obj._derivatives = dict(derivatives)
        obj._solvers = {}
        obj.solvers_build_s = 0.0
        return obj

    # ------------------------------------------------------------------ build
    def _build(self) -> None:
        """Transcribe the problem: the scaled decision vector (:class:`.layout.Variables`), the
        constraint rows (:class:`.constraints.Constraints`), the objective, and the functions of
        the energies and the constraints."""
        pr, m = self.problem, self.model
        bnd = pr.bounds
        p_sym = ca.SX.sym("p", NP)  # wind north, wind east, tether-drag factor, heading wrap k, morph, penalty
        vs = Variables()
        cs = Constraints()
        self.g_names: list[str] = cs.names
        T_max = bnd.T_max if bnd.T_max is not None else m.gen_airframe.propulsion.T_max
        v_in = reel_in_limit(m, bnd)
        self.reel_in_speed_max = v_in
        self.T_max = T_max
        x_bounds = state_bounds(pr)
        sums = _Sums()
        self.idx_slack: list[int] = []
        for ip, ph in enumerate(self.phases):
            self._transcribe_phase(ip, ph, vs, cs, p_sym, x_bounds, control_bounds(m, bnd, ip, T_max, v_in), sums)
        gen, rec = self.phases
        add_boundaries(cs, pr, gen, rec, self.d, p_sym[3])
        add_smoothness(cs, pr.bounds, gen, rec)
        add_catch(cs, m, pr.bounds, rec, self.d, (p_sym[0], p_sym[1]))
        P_avg = (sums.E_gen - sums.E_thr - sums.E_rw) / (gen.T + rec.T)
        J = -P_avg / P_SCALE + REG_WEIGHT * sums.reg + p_sym[5] * sums.slack / max(1, len(rec.U))
        self.nlp = {"x": ca.vertcat(*vs.parts), "p": p_sym, "f": J, "g": ca.vertcat(*cs.g)}
        self.lbw, self.ubw = np.array(vs.lbw), np.array(vs.ubw)
        self.lbg, self.ubg = np.array(cs.lbg), np.array(cs.ubg)
        self.energy_fn = ca.Function("energies", [self.nlp["x"], p_sym],
                                     [sums.E_gen, sums.E_thr, sums.E_rw, gen.T, rec.T])
        self.g_fn = ca.Function("g", [self.nlp["x"], p_sym], [self.nlp["g"]])
        self.nw = vs.n

    def _transcribe_phase(self, ip: int, ph: PhaseLayout, vs: Variables, cs: Constraints, p_sym: Any,
                          x_bounds: dict[str, tuple[float, float]], u_bounds: dict[str, tuple[float, float]],
                          sums: _Sums) -> None:
        """Phase ``ip``'s variables and rows: its duration and the states at its start, then
        interval by interval the controls (in recovery the elastic slacks), the collocation
        states and the interval's rows (:meth:`_interval_rows`); the control-smoothing penalty
        between intervals is added to ``sums``."""
        m, bnd, d = self.model, self.problem.bounds, self.d
        # a folding wing needs the whole fold and unfold inside the recovery
        ph.T, ph.idx_T = vs.new(f"T{ip + 1}", TIME_SCALE, max(bnd.T_phase_min, 2.0 * ph.fold_time), bnd.t_max)
        nx, nu = len(ph.states), len(ph.controls)
        ph.idx_X = np.zeros((ph.n, d + 1, nx), dtype=int)
        ph.idx_U = np.zeros((ph.n, nu), dtype=int)
        F = self._point_function(ip, nx, len(ph.controls))
        F_fold = self._point_function(ip, nx, len(ph.controls), fold=True) if ph.n_fold else None
        hs = ph.lengths(ph.T)
        node, node_ids = vs.group(ph.states, f"p{ip}_0", STATE_SCALE, x_bounds)
        ph.X = []
        ph.U = []
        prev_u = None
        for k in range(ph.n):
            folds = [ph.fold(k, self.tau[j]) for j in range(d + 1)]
            bounds_k = dict(u_bounds)
            if folds[0] is not None:
                bounds_k["alpha"] = fold_alpha_bounds(m, bnd, ip, folds)
            u, u_ids = vs.group(ph.controls, f"p{ip}_{k}", CONTROL_SCALE, bounds_k)
            ph.idx_U[k] = u_ids
            ph.U.append(u)
            extra = self._slacks(ph, k, vs, sums) if ip == 1 else [0.0] * nx
            pts = [node]
            ph.idx_X[k, 0] = node_ids
            for j in range(1, d + 1):
                vals, ids = vs.group(ph.states, f"p{ip}_{k}_{j}", STATE_SCALE, x_bounds)
                pts.append(vals)
                ph.idx_X[k, j] = ids
            ph.X.append(pts)
            uv = ca.vertcat(*u)

            def point(j: int) -> Any:
                """The phase block at collocation point ``j`` of this interval."""
                args = (ca.vertcat(*pts[j]), uv, p_sym)
                return F(*args) if folds[j] is None else F_fold(*args, folds[j])

            self._interval_rows(ip, ph, k, hs[k], pts, extra, point, cs, sums)
            if prev_u is not None:
                sums.reg = sums.reg + sum(((u[i] - prev_u[i]) / CONTROL_SCALE[c]) ** 2
                                          for i, c in enumerate(ph.controls))
            prev_u = u
            node, node_ids = pts[d], list(ph.idx_X[k, d])

    def _slacks(self, ph: PhaseLayout, k: int, vs: Variables, sums: _Sums) -> list[Any]:
        """The elastic slacks of recovery interval ``k`` (bounds [0, 0] unless the elastic mode
        opens them, :meth:`solve`): the fictitious acceleration added to each state equation
        (0 where none is); their L1 norm is added to ``sums``."""
        extra: list[Any] = [0.0] * len(ph.states)
        for i_s, s_name in enumerate(ph.states):
            if s_name not in SLACK_SCALE:
                continue
            sp, i_p = vs.new(f"slack+_{s_name}_p1_{k}", SLACK_SCALE[s_name], 0.0, 0.0)
            sn, i_n = vs.new(f"slack-_{s_name}_p1_{k}", SLACK_SCALE[s_name], 0.0, 0.0)
            self.idx_slack += [i_p, i_n]
            extra[i_s] = sp - sn
            sums.slack = sums.slack + (sp + sn) / SLACK_SCALE[s_name]
        return extra

    def _interval_rows(self, ip: int, ph: PhaseLayout, k: int, h: Any, pts: list[list[Any]], extra: list[Any],
                       point: Callable[[int], Any], cs: Constraints, sums: _Sums) -> None:
        """Rows of interval ``k`` (length ``h`` [s], states ``pts`` at its points, ``point(j)``
        the phase block there): the path constraints at the phase start, then at each collocation
        point the collocation equations (scaled by the state scales) and the path constraints;
        its quadrature terms of the energies are added to ``sums``."""
        m, bnd, d, C, B = self.model, self.problem.bounds, self.d, self.C, self.B
        xs = [STATE_SCALE[s] for s in ph.states]
        if k == 0:
            out = point(0)
            add_path(cs, m, bnd, ip, out[2], f"p{ip}_start")
        for j in range(1, d + 1):
            fj, pw, path = point(j)
            for i_s in range(len(ph.states)):
                xp = sum(C[r, j] * pts[r][i_s] for r in range(d + 1))
                cs.add((xp - h * (fj[i_s] + extra[i_s])) / xs[i_s], 0.0, 0.0, f"coll_p{ip}_{k}_{j}_{ph.states[i_s]}")
            add_path(cs, m, bnd, ip, path, f"p{ip}_{k}_{j}")
            sums.E_gen = sums.E_gen + B[j] * h * pw[0]
            sums.E_thr = sums.E_thr + B[j] * h * pw[1]
            sums.E_rw = sums.E_rw + B[j] * h * pw[2]

    def _point_function(self, ip: int, nx: int, nu: int, fold: bool = False) -> ca.Function:
        """CasADi function (state, control, params) -> (derivative, [P_gen, P_thr, P_rw], path);
        ``fold``: a recovery point of a fold transition, with the fold state as a fourth input."""
        s = ca.SX.sym("s", nx)
        u = ca.SX.sym("u", nu)
        p = ca.SX.sym("p", NP)
        f = ca.SX.sym("fold")
        args = ([s[i] for i in range(nx)], [u[i] for i in range(nu)], (p[0], p[1]), p[2])
        out = self.model.generation(*args) if ip == 0 else self.model.recovery(*args, p[4], f if fold else None)
        path = point_path(self.model, ip, out, s, u, p)
        return ca.Function(f"phase{ip}" + ("_fold" if fold else ""), [s, u, p] + ([f] if fold else []),
                           [ca.vertcat(*out["f"]), ca.vertcat(out["P_gen"], out["P_thr"], out["P_rw"]), ca.vertcat(*path)])

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
        solver = self.solver_for(options)
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

    def solver_for(self, options: dict | None) -> Any:
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
        must hold every scaled constraint within 1e-6 (:data:`.assemble.VIOLATION_TOL`), and the
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
