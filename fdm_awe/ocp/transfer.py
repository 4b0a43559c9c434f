"""A solution of one NLP carried over to another of the same mesh whose controls differ, with its
multipliers: the primal-dual warm start between the slack-line and the free-tension recovery.

The two NLPs share their phases, meshes, states and rows except for the extra controls of one
of them (the recovery's tension ``G``) and the rows that come with them (``taut_*``,
``reel_in_*``). A solution of the smaller problem is a point of the larger one with the extra
controls at zero (the slack line is one admissible recovery of the free-tension problem); its
multipliers carry over by variable and by row name, the new ones start at zero.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from .build import structure_key
from .collocation import CycleNLP
from .problem import CycleProblem


def same_but_recovery_tension(a: CycleProblem, b: CycleProblem) -> bool:
    """True when problems ``a`` and ``b`` make the same NLP but for the recovery's tension."""
    return a.recovery_tension != b.recovery_tension and \
        structure_key(replace(a, recovery_tension=b.recovery_tension)) == structure_key(b)


def _variable_map(src: CycleNLP, dst: CycleNLP) -> tuple[np.ndarray, np.ndarray]:
    """Indices ``(i_src, i_dst)`` of the variables both NLPs hold (durations, states, common
    controls, elastic slacks); ValueError when their meshes differ."""
    if src.d != dst.d or [p.n for p in src.phases] != [p.n for p in dst.phases] or \
            len(src.idx_slack) != len(dst.idx_slack):
        raise ValueError("transfer: the NLPs' meshes differ")
    i_src: list[int] = list(src.idx_slack)
    i_dst: list[int] = list(dst.idx_slack)
    for ps, pd in zip(src.phases, dst.phases):
        if ps.states != pd.states:
            raise ValueError("transfer: the NLPs' states differ")
        i_src.append(int(ps.idx_T))
        i_dst.append(int(pd.idx_T))
        i_src += ps.idx_X.ravel().tolist()
        i_dst += pd.idx_X.ravel().tolist()
        for c, name in enumerate(ps.controls):
            if name in pd.controls:
                i_src += ps.idx_U[:, c].tolist()
                i_dst += pd.idx_U[:, pd.controls.index(name)].tolist()
    return np.array(i_src, int), np.array(i_dst, int)


def transfer(src: CycleNLP, dst: CycleNLP, w: np.ndarray, lam_x: np.ndarray | None,
             lam_g: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The point ``w`` of ``src`` (scaled) with multipliers ``lam_x``, ``lam_g`` as a point of
    ``dst``: common variables and rows copied, controls ``dst`` adds at zero (clipped into their
    bounds), their multipliers and those of new rows zero."""
    i_src, i_dst = _variable_map(src, dst)
    w2 = np.zeros(dst.nw)
    w2[i_dst] = np.asarray(w, float)[i_src]
    new = np.ones(dst.nw, bool)
    new[i_dst] = False
    w2[new] = np.clip(0.0, dst.lbw[new], dst.ubw[new])
    lx = np.zeros(dst.nw)
    if lam_x is not None:
        lx[i_dst] = np.asarray(lam_x, float)[i_src]
    lg = np.zeros(len(dst.g_names))
    if lam_g is not None:
        rows = {n: i for i, n in enumerate(src.g_names)}
        lam_g = np.asarray(lam_g, float)
        for j, n in enumerate(dst.g_names):
            i = rows.get(n)
            if i is not None:
                lg[j] = lam_g[i]
    return w2, lx, lg


def transfer_result(result: Any, dst: CycleNLP, src: CycleNLP) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`transfer` of a solved :class:`~fdm_awe.ocp.result.CycleResult` of ``src``."""
    return transfer(src, dst, result.w, result.lam_x, result.lam_g)
