"""Lumped-mass tether: N elastic segments between the winch and the glider hook.

Selected with ``GroundStation(tether="lumped:N")`` (``fdm-awe fly --tether lumped:N``; its entry
in :data:`.linemodels.LINE_MODELS`); the straight line (:mod:`.tether`) stays the default.

Model (docs/design.md section 10)
    Node 0 sits at the winch (the NED origin), node N at the glider's hook (prescribed, moving
    linearly over the step as the straight line's end does); nodes 1 .. N-1 are point masses
    ``m = mu l_s``. Each segment has the rest length ``l_s = l / N`` of the drum's unstretched
    paid-out length ``l`` (reel-out/in changes every rest length alike, as KiteModels does; the
    node masses follow), is tension-only ``T = (EA / l_s) (|dx| - l_s)`` when taut, else 0,
    with an optional axial damper ``c = 2 zeta sqrt(k m)`` while taut. Every segment carries
    the drag ``-0.5 rho C_D_perp d_t |dx| |v_perp| v_perp`` of its mid-point air velocity
    normal to it (wind from :func:`wind_at`, the one place the wind enters), half to each end
    node; every node its weight. The glider takes the last segment's force, its half drag and
    the half node mass's weight (the straight line's drag and weight shares are not added).

Integration
    Leapfrog (kick-drift-kick, symplectic: no drift of the energy with drag and damping off)
    sub-stepped inside each drivetrain sub-step. The fastest mode of the chain is the axial
    one, ``omega_max = 2 sqrt(k / m) = 2 sqrt(EA / mu) / l_s`` (e.g. EA 6.76 kN, mu 0.123 g/m,
    l 200 m, N 30: 2.2e3 rad/s); leapfrog is stable for ``h omega_max < 2``, the inner step is
    ``h <= cfl 2 / omega_max`` with ``cfl = 0.8`` (the damper's factor included): 20 inner
    steps per 1/120 s step at N = 30, 150 m. Two passes per inner step: the kicks and the drift
    over the nodes, the forces (with the payout energy) over the segments. Implicit axial springs
    with the trapezoidal rule (docs/design.md section 10) pump energy into a slack line at its
    taut-slack switches; ``lumped-implicit:N`` (:mod:`.lumped_implicit`) takes one linearly
    implicit Euler step per flight step instead, after the drum's sub-steps (the drum then pulls
    with the tensions of the step's start).

Coupling with the drum
    Each drivetrain sub-step first runs the drum (:func:`.substeps.advance`, prescribed tension)
    under the line's generalised force on the paid-out length ``-dE_el/dl = (1/N) sum (T_i +
    T_i^2 / (2 EA))`` (the rest length is the drum's coordinate), then the line over the same
    sub-step with the rest lengths moving from the old to the new drum length.

Energy ledger of the line (J; :data:`FIELDS`)::

    hook_work + mass_inflow = payout_work + drag + damping + break_release
                              + delta(kinetic + elastic + potential) + residual

``hook_work`` work of the glider on the line end; ``mass_inflow`` the kinetic and potential
energy of the line mass the node masses gain when paying out (the drum hands it over at the
nodes); ``payout_work`` the elastic energy the line gives to the drum through its rest lengths
(the drum's ledger books ``drum_handover``, the generalised force times the length change, as its
``glider_work``; ``coupling`` is their difference: the one-sub-step lag); ``residual`` the
integrator's error, not a booked term. Axial line inertia moving with the drum stays in the
drum's inertia ``mu l r_w^2`` as for the straight line.

The line's state, ledger and constants live in the ground station's arrays after the
drivetrain's (:mod:`.lumped_state`: the layout, the model spec, the views); its forces are
:mod:`.lumped_forces`'. Every function here is plain Python over floats and arrays; numba
compiles :func:`lumped_station_step` (its cache tied also to :mod:`.substeps`, :mod:`.winch`,
:mod:`.lumped_state`, :mod:`.lumped_forces`, :mod:`.lumped_implicit` and :mod:`fdm_awe.wind`),
Python runs the same source when ``FDM_AWE_JIT=0``.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .. import wind
from ..jitcache import compile_lazy, compiled_once
from ..wind import shear_factor
from . import lumped_forces, lumped_implicit, lumped_state, substeps, winch
from .linestep import compile_line_step
from .lumped_forces import along, line_energies, line_forces, segment_end, segment_pull, wind_at
from .lumped_implicit import (apply_step, assemble, back_substitute, forward_sweep, implicit_count, implicit_line,
                              implicit_step, scratch_offsets, scratch_size, segment_terms, settle_implicit)
from .lumped_state import HEAD, LINE, LINE_LEDGER, NODES
from .substeps import CONST, LEDGER, STATE, STATION, advance, machine_mode_code


def inner_steps(s, c, n: int, msteps: int, h: float, ls0: float, ls1: float, hx0: float, hy0: float, hz0: float,
                hx1: float, hy1: float, hz1: float, relax: float) -> tuple[float, float, float, float, float]:
    """``msteps`` leapfrog steps of ``h`` s of the interior nodes: rest length from ``ls0`` to
    ``ls1`` m, hook from ``(hx0, ..)`` to ``(hx1, ..)`` m; ``relax`` (1/s, 0 in flight) an extra
    damping of the node velocities (for finding a static shape). The force slots hold the forces
    at the start (:func:`line_forces`). Books the line ledger; returns the sums over the steps
    of the force on the glider ``(fx, fy, fz)`` N, of its half-drag part ``(dx, dy, dz)`` N and
    half-weight part ``wz`` N, of the glider-end tension N, and the largest segment tension N.

    A step's closing half kick runs in the same pass over the nodes as the next step's opening
    half kick and drift (the same operations in the same order: the two half kicks of one force
    are not merged), the last one after the loop."""
    P = NODES
    V = P + 3 * (n + 1)
    F = V + 3 * (n + 1)
    TT = F + 3 * (n + 1)
    mu, g = c[CONST.mu], c[STATION.g]
    vhx, vhy, vhz = (hx1 - hx0) / (msteps * h), (hy1 - hy0) / (msteps * h), (hz1 - hz0) / (msteps * h)
    sfx = sfy = sfz = sdx = sdy = sdz = swz = stg = tmax = 0.0
    kdamp = 1.0 - relax * h if relax * h < 1.0 else 0.0
    fh = F + 3 * n
    ph = P + 3 * n
    kb = 0.0  # the pending closing half kick (0: none before the first step)
    for j in range(msteps):
        lsa = ls0 + (ls1 - ls0) * j / msteps
        lsb = ls0 + (ls1 - ls0) * (j + 1) / msteps
        ma, mb = mu * lsa, mu * lsb
        paying = mb != ma
        fgx, fgy, fgz = s[fh], s[fh + 1], s[fh + 2]
        # the last step's closing half kick, this step's opening half kick, drift
        e_mass = 0.0
        ka = 0.5 * h / ma
        for i in range(1, n):
            f = F + 3 * i
            v = V + 3 * i
            p = P + 3 * i
            vx, vy, vz = s[v], s[v + 1], s[v + 2]
            fx, fy, fz = s[f], s[f + 1], s[f + 2]
            if j > 0:
                vx += kb * fx
                vy += kb * fy
                vz += kb * fz
            vx = (vx + ka * fx) * kdamp
            vy = (vy + ka * fy) * kdamp
            vz = (vz + ka * fz) * kdamp
            s[v], s[v + 1], s[v + 2] = vx, vy, vz
            pz = s[p + 2] + h * vz
            s[p] += h * vx
            s[p + 1] += h * vy
            s[p + 2] = pz
            if paying:
                vv = vx * vx + vy * vy + vz * vz
                e_mass += (mb - ma) * (0.5 * vv - g * pz)
        t1 = (j + 1.0) / msteps
        dhx = hx0 + (hx1 - hx0) * t1 - s[ph]
        dhy = hy0 + (hy1 - hy0) * t1 - s[ph + 1]
        dhz = hz0 + (hz1 - hz0) * t1 - s[ph + 2]
        s[ph], s[ph + 1], s[ph + 2] = s[ph] + dhx, s[ph + 1] + dhy, s[ph + 2] + dhz
        # the rest-length change's elastic energy at the start positions and at the end positions
        e_el, e_old, pay0, p_damp, p_drag, hdx, hdy, hdz, tm = line_forces(s, c, n, lsb, mb, vhx, vhy, vhz, lsa)
        fgx1, fgy1, fgz1 = s[fh], s[fh + 1], s[fh + 2]
        kb = 0.5 * h / mb
        # ledger: the glider works against the line's force on the hook (trapezoid)
        s[LINE_LEDGER.hook_work] -= 0.5 * ((fgx + fgx1) * dhx + (fgy + fgy1) * dhy + (fgz + fgz1) * dhz)
        s[LINE_LEDGER.mass_inflow] += e_mass
        if lsb != lsa:  # the mean of both: second order like the leapfrog's work
            s[LINE_LEDGER.payout_work] += 0.5 * (pay0 + e_old - e_el)
        s[LINE_LEDGER.drag] -= h * p_drag
        s[LINE_LEDGER.damping] += h * p_damp
        # the force on the glider: the line's, the half drag and the half node mass's weight
        sfx += fgx1 + hdx
        sfy += fgy1 + hdy
        sfz += fgz1 + hdz + 0.5 * mb * g
        sdx += hdx
        sdy += hdy
        sdz += hdz
        swz += 0.5 * mb * g
        stg += s[TT + n - 1]
        if tm > tmax:
            tmax = tm
    for i in range(1, n):  # the last step's closing half kick
        f = F + 3 * i
        v = V + 3 * i
        for a in range(3):
            s[v + a] += kb * s[f + a]
    return sfx, sfy, sfz, sdx, sdy, sdz, swz, stg, tmax


def inner_count(c, h: float, ls: float) -> int:
    """Leapfrog steps per ``h`` s for rest length ``ls`` m: ``h / (cfl 2 / omega_max)`` rounded
    up, ``omega_max = 2 sqrt(EA / mu) / ls`` (with the damper: times ``sqrt(1 + zeta^2) + zeta``)."""
    z = c[LINE.zeta]
    w = 2.0 * math.sqrt(c[CONST.EA] / c[CONST.mu]) / ls * (math.sqrt(1.0 + z * z) + z)
    return max(1, int(math.ceil(h * w / (2.0 * c[LINE.cfl]) - 1e-9)))


def store_energies(s, c, n: int, which: int) -> None:
    """Write the line's kinetic, elastic and potential energy into the ledger's ``stored_``
    (``which`` 1) or both ``stored0_`` and ``stored_`` (``which`` 0) slots (after
    :func:`line_forces`, whose tensions give the elastic energy)."""
    ls = s[STATE.length] / n
    m = c[CONST.mu] * ls
    ek, ep = line_energies(s, n, m, c[STATION.g])
    TT = NODES + 9 * (n + 1)
    k = c[CONST.EA] / ls
    ee = 0.0
    for i in range(n):
        T = s[TT + i]
        ee += 0.5 * T * T / k
    s[LINE_LEDGER.stored_kinetic], s[LINE_LEDGER.stored_elastic], s[LINE_LEDGER.stored_potential] = ek, ee, ep
    if which == 0:
        s[LINE_LEDGER.stored0_kinetic], s[LINE_LEDGER.stored0_elastic], s[LINE_LEDGER.stored0_potential] = ek, ee, ep


def place_line(s, c, n: int, x: float, y: float, z: float) -> None:
    """Nodes on the straight chord from the winch to the hook ``(x, y, z)`` m, at rest; forces
    computed (:func:`line_forces`)."""
    P = NODES
    V = P + 3 * (n + 1)
    for i in range(n + 1):
        f = i / n
        s[P + 3 * i], s[P + 3 * i + 1], s[P + 3 * i + 2] = f * x, f * y, f * z
        s[V + 3 * i] = s[V + 3 * i + 1] = s[V + 3 * i + 2] = 0.0
    ls = s[STATE.length] / n
    line_forces(s, c, n, ls, c[CONST.mu] * ls, 0.0, 0.0, 0.0, ls)


def relax_line(s, c, n: int, seconds: float) -> None:
    """Let the line settle for ``seconds`` s with its ends held and its velocities damped at the
    rate of its slowest transverse mode (a static shape; the ledger is not kept)."""
    ls = s[STATE.length] / n
    h = 0.5 * 2.0 * c[LINE.cfl] / (2.0 * math.sqrt(c[CONST.EA] / c[CONST.mu]) / ls)
    P = NODES + 3 * n
    x, y, z = s[P], s[P + 1], s[P + 2]
    T = 0.0
    TT = NODES + 9 * (n + 1)
    for i in range(n):
        T = max(T, s[TT + i])
    rate = math.pi * math.sqrt(max(T, 1e-3 * c[CONST.EA]) / c[CONST.mu]) / s[STATE.length]
    msteps = max(1, int(seconds / h))
    inner_steps(s, c, n, msteps, h, ls, ls, x, y, z, x, y, z, 2.0 * rate)
    V = NODES + 3 * (n + 1)
    for i in range(3 * (n + 1)):
        s[V + i] = 0.0
    line_forces(s, c, n, ls, c[CONST.mu] * ls, 0.0, 0.0, 0.0, ls)


def generalised_tension(s, c, n: int) -> float:
    """The line's force on the drum through its rest lengths, ``(1/N) sum (T_i + T_i^2 / (2 EA))``, N."""
    TT = NODES + 9 * (n + 1)
    EA = c[CONST.EA]
    t = 0.0
    for i in range(n):
        T = s[TT + i]
        t += T + T * T / (2.0 * EA)
    return t / n


def settle_line(s, c, n: int, x: float, y: float, z: float) -> None:
    """The line's static shape to the hook at ``(x, y, z)`` m (:func:`place_line`, then
    :func:`relax_line`, or :func:`settle_implicit` for the implicit line); its ledger starts
    there (the settling is not part of the flight's)."""
    place_line(s, c, n, x, y, z)
    if c[LINE.scheme] == 1.0:
        settle_implicit(s, c, n, x, y, z)
    else:
        relax_line(s, c, n, 3.0)
    for i in range(LINE_LEDGER.hook_work, LINE_LEDGER.stored0_kinetic):
        s[i] = 0.0
    store_energies(s, c, n, 0)
    s[HEAD.ready] = 1.0


def move_hook(s, c, n: int, x: float, y: float, z: float, vx: float, vy: float, vz: float) -> None:
    """The hook's real position ``(x, y, z)`` m differs from the last prediction: the hook node
    goes there (moving with ``(vx, vy, vz)`` m/s), the forces follow, and the work at the line
    end (trapezoid of the force on the hook) is booked."""
    ph = NODES + 3 * n
    dhx, dhy, dhz = x - s[ph], y - s[ph + 1], z - s[ph + 2]
    F = NODES + 6 * (n + 1) + 3 * n
    fx0, fy0, fz0 = s[F], s[F + 1], s[F + 2]
    s[ph], s[ph + 1], s[ph + 2] = x, y, z
    ls = s[STATE.length] / n
    line_forces(s, c, n, ls, c[CONST.mu] * ls, vx, vy, vz, ls)
    s[LINE_LEDGER.hook_work] -= 0.5 * ((fx0 + s[F]) * dhx + (fy0 + s[F + 1]) * dhy + (fz0 + s[F + 2]) * dhz)


def break_line(s, c, n: int, vx: float, vy: float, vz: float) -> None:
    """The line breaks: its strain energy is booked as released, its tensions drop to 0 (the
    glider's hook moves with ``(vx, vy, vz)`` m/s)."""
    s[STATE.broken] = 1.0
    ls = s[STATE.length] / n
    line_forces(s, c, n, ls, c[CONST.mu] * ls, vx, vy, vz, ls)
    store_energies(s, c, n, 1)
    s[LINE_LEDGER.break_release] += s[LINE_LEDGER.stored_elastic]
    TT = NODES + 9 * (n + 1)
    for i in range(n):
        s[TT + i] = 0.0


def lumped_station_step(s, c, n, dt, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL):
    """:func:`.substeps.station_step` with the lumped line (same arguments and returns; ``s``
    and ``c`` hold the line's block after the drivetrain's, see the module docstring)."""
    N = int(c[LINE.nseg])
    broken = s[STATE.broken] != 0.0
    implicit = c[LINE.scheme] == 1.0  # the line steps after the drum's sub-steps (see implicit_step)
    if s[HEAD.ready] == 0.0:  # first step: the line's static shape to the hook
        settle_line(s, c, N, x, y, z)
    elif not broken and not implicit:  # (the implicit step moves the hook from where it stands)
        move_hook(s, c, N, x, y, z, vx, vy, vz)
    h = dt / n
    tsum = pl_sum = ps_sum = 0.0
    ev = nin = 0
    sfx = sfy = sfz = stg = sdx = sdy = sdz = swz = tmax = 0.0
    l_start = s[STATE.length]
    tg = 0.0 if broken else generalised_tension(s, c, N)  # (the implicit line's holds over the step)
    for j in range(n):
        l0 = s[STATE.length]
        if j > 0 and not implicit:
            tg = 0.0 if broken else generalised_tension(s, c, N)
        tm, pl, ps, e = advance(s, c, 1, h, x, y, z, vx, vy, vz, motor, omega_ref, duty_cmd, boost_duty, RL, tg)
        l1 = s[STATE.length]
        s[LINE_LEDGER.drum_handover] += tg * (l1 - l0)
        tsum += tm
        pl_sum += pl
        ps_sum += ps
        if ev == 0:
            ev = e
        if broken or implicit:
            continue
        m = inner_count(c, h, min(l0, l1) / N)
        a, b = j * h, (j + 1) * h
        fx_, fy_, fz_, dx_, dy_, dz_, wz_, tg_, tm_ = inner_steps(s, c, N, m, h / m, l0 / N, l1 / N, x + a * vx, y + a * vy,
                                              z + a * vz, x + b * vx, y + b * vy, z + b * vz, 0.0)
        sfx += fx_ / m
        sfy += fy_ / m
        sfz += fz_ / m
        stg += tg_ / m
        nin += m
        sdx += dx_ / m
        sdy += dy_ / m
        sdz += dz_ / m
        swz += wz_ / m
        if tm_ > tmax:
            tmax = tm_
        if tm_ > c[CONST.Tbreak]:  # the line breaks: its strain energy is lost, the glider is free
            broken = True
            ev = 3
            break_line(s, c, N, vx, vy, vz)
    if implicit and not broken:  # the line over the whole step, the drum's lengths at its ends
        sfx, sfy, sfz, stg, sdx, sdy, sdz, swz, tmax, nin, snap = implicit_line(s, c, N, n, dt, l_start, x, y, z, vx,
                                                                                vy, vz)
        if snap:  # the line breaks: its strain energy is lost, the glider is free
            broken = True
            ev = 3
            break_line(s, c, N, vx, vy, vz)
    if broken and ev != 3:
        fx = fy = fz = 0.0
    else:
        fx, fy, fz = sfx / n, sfy / n, sfz / n
    s[HEAD.tension_glider] = stg / n
    s[HEAD.tension_max] = tmax
    s[HEAD.inner] = nin / n
    s[HEAD.drag_x], s[HEAD.drag_y], s[HEAD.drag_z], s[HEAD.weight_z] = sdx / n, sdy / n, sdz / n, swz / n
    store_energies(s, c, N, 1)
    # the straight line's share terms: the work on the glider of the half drag and half weight it takes
    s[LEDGER.line_drag_work_on_glider] += (s[HEAD.drag_x] * vx + s[HEAD.drag_y] * vy + s[HEAD.drag_z] * vz) * dt
    s[LEDGER.line_weight_work_on_glider] += s[HEAD.weight_z] * vz * dt
    d = math.sqrt(x * x + y * y + z * z)
    w, i = float(s[STATE.omega]), float(s[STATE.current])
    tmean = tsum / n
    return (fx, fy, fz, tmean, float(s[STATE.length]), w, i, float(s[STATE.duty]), float(s[STATE.u_link]),
            (pl_sum - ps_sum) / n, ev, machine_mode_code(w, i, c[CONST.K]), d, s[HEAD.tension_glider] <= 0.0, broken)


CALLED = (shear_factor, wind_at, segment_pull, segment_end, along, line_forces, line_energies, inner_steps,
          scratch_size, scratch_offsets, segment_terms, assemble, forward_sweep, back_substitute, apply_step,
          implicit_step, implicit_count, implicit_line, inner_count, store_energies, place_line, settle_implicit,
          relax_line, generalised_tension, settle_line, move_hook, break_line)
#: the other source files whose code or constants the compiled functions hold (their on-disk
#: cache follows them, :func:`fdm_awe.jitcache.follow_sources`)
SOURCES = (substeps, winch, wind, lumped_state, lumped_forces, lumped_implicit)


@compiled_once
def compiled_lumped() -> Callable | None:
    """:func:`lumped_station_step` compiled by numba (cached on disk), or None (numba missing,
    ``FDM_AWE_JIT=0``, or a broken install: the Python function runs instead); tied also to the
    drum step, the wind profile and the line's layout compiled into it."""
    return compile_line_step(lumped_station_step, CALLED, SOURCES, "fdm_awe.groundstation.lumped")


@compiled_once
def compiled_function(name: str) -> Callable:
    """The function ``name`` of this module (e.g. ``"relax_line"``, ``"inner_steps"``) compiled
    by numba for the types of its first call, or the Python function itself when numba is
    missing or ``FDM_AWE_JIT=0`` (for studies and tests of the line alone)."""
    return compile_lazy(globals()[name], substeps.CALLED + CALLED, SOURCES)
