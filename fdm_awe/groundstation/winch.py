"""Winch drum dynamics (paper eq. 14) with the implicit, set-valued Coulomb friction.

Drum equation (reel-out positive, omega = reel speed / r_w):

    (J + mu l r_w^2) domega/dt = r_w T - K_t i - B omega - M_c sgn(omega)

- ``J`` is Table 1's total inertia (drum + rotor); the paid-out line adds ``mu l r_w^2``.
- ``M_c`` is Table 1's Coulomb friction, counted once (docs/design.md 4.8: eq. 14's M_c and eq. 16's
  T_f are the same term); ``B`` the viscous friction; ``K_t i`` the machine torque, which acts in
  the reel-in direction only (the asymmetric half-bridge carries one current direction).
- Stick-slip without chattering: friction is the set-valued law ``M_f in M_c Sign(omega)``
  solved implicitly (backward Euler) every sub-step. When the driving torque cannot overcome
  M_c the drum sticks exactly (omega = 0, friction = whatever holds it, |M_f| <= M_c): no
  switching at zero speed, no smoothing velocity (equivalent to Karnopp's stick band shrunk to
  the exact stick condition).
"""

from __future__ import annotations

from .definitions import TetherParams, WinchParams


def effective_inertia(w: WinchParams, t: TetherParams, length: float) -> float:
    """Drum inertia plus the axial mass of the paid-out line, kg m^2."""
    return w.inertia + t.mass_per_length * length * w.radius * w.radius


def solve_drum_speed(
    J: float, w0: float, h: float, B: float, Mc: float, r: float,
    tA: float, tB: float, K: float, iA: float, iB: float,
) -> tuple[float, float]:
    """One backward-Euler step of the drum speed with set-valued Coulomb friction.

    Solves for ``w`` (rad/s)::

        J (w - w0) = h [ r T(w) - K i(w) - B w - M_f ],   M_f in Mc Sign(w)
        T(w) = max(0, tA - tB w)   (tether tension at the end of the step, N; tB >= 0)
        i(w) = max(0, iA + iB w)   (armature current at the end of the step, A; iB >= 0)

    The residual ``R(w) = J (w - w0) - h [r T(w) - K i(w) - B w]`` is continuous, piecewise
    linear and strictly increasing, so the solution is unique; it is found exactly by checking
    the stick condition at w = 0 and then the linear pieces between the kinks.
    Returns ``(w, M_f)`` with the friction torque M_f in N m (>0 opposes reel-out).
    """
    hM = h * Mc
    R0 = -J * w0 - h * r * (tA if tA > 0.0 else 0.0) + h * K * (iA if iA > 0.0 else 0.0)
    if R0 + hM < 0.0:
        c, sgn = -hM, 1.0
    elif R0 - hM > 0.0:
        c, sgn = hM, -1.0
    else:
        return 0.0, -R0 / h  # stuck: friction holds the drum, |M_f| <= Mc
    # Fast path: the pieces active at a guess on the right side of zero.
    g = w0 if w0 * sgn > 0.0 else sgn * 1e-9
    w = _piece(J, w0, h, B, r, tA, tB, K, iA, iB, c, tA - tB * g > 0.0, iA + iB * g > 0.0)
    if w * sgn > 0.0 and (tA - tB * w > 0.0) == (tA - tB * g > 0.0) and (iA + iB * w > 0.0) == (iA + iB * g > 0.0):
        return w, sgn * Mc
    # General case: walk the linear pieces of the half-line.
    kinks = []
    if tB > 0.0:
        kinks.append(tA / tB)
    if iB > 0.0:
        kinks.append(-iA / iB)
    pts = sorted(k for k in kinks if k * sgn > 0.0)
    edges = [0.0] + pts if sgn > 0.0 else pts + [0.0]
    lo_hi = []
    if sgn > 0.0:
        for j, a in enumerate(edges):
            lo_hi.append((a, edges[j + 1] if j + 1 < len(edges) else float("inf")))
    else:
        for j, b in enumerate(edges):
            lo_hi.append((edges[j - 1] if j > 0 else float("-inf"), b))
    for lo, hi in lo_hi:
        m = 0.5 * (lo + hi) if (lo != float("-inf") and hi != float("inf")) else (lo + 1.0 if hi == float("inf") else hi - 1.0)
        w = _piece(J, w0, h, B, r, tA, tB, K, iA, iB, c, tA - tB * m > 0.0, iA + iB * m > 0.0)
        if lo - 1e-12 * (1.0 + abs(lo)) <= w <= hi + 1e-12 * (1.0 + abs(hi)):
            return w, sgn * Mc
    return w, sgn * Mc  # unreachable for consistent inputs (monotone residual)


def _piece(J, w0, h, B, r, tA, tB, K, iA, iB, c, t_on, i_on):
    """Root of the linear piece of R(w) = c with the given active tension/current terms."""
    a = -J * w0
    b = J + h * B
    if t_on:
        a -= h * r * tA
        b += h * r * tB
    if i_on:
        a += h * K * iA
        b += h * K * iB
    return (c - a) / b
