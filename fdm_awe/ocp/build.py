"""The cycle NLP of a problem: built once per structure and kept, in the process and on disk.

Built NLPs are cached per structure (scenario, configuration, geometry, bounds, mesh:
:func:`structure_key`) and per glider and winch in the process (the least recently used dropped
first, :data:`CACHE_SIZE`), so sweeps and repeated solves pay the build once, and on disk
(:mod:`fdm_awe.ocp.nlpcache`), so a new process loads them instead of building them.
"""

from __future__ import annotations

from collections import OrderedDict

from ..definitions.aircraft import Glider, load_glider
from . import nlpcache
from .collocation import CycleNLP
from .energy import WinchElectrics, problem_winch
from .model import CycleModel
from .problem import CycleProblem

_CACHE: "OrderedDict[tuple, CycleNLP]" = OrderedDict()

#: built NLPs kept per process (least recently used dropped first); a sweep over design
#: variants walks each variant's wind chain, so a few entries give every chain one build
CACHE_SIZE = 8


def structure_key(problem: CycleProblem) -> tuple:
    """Everything that shapes the NLP except the wind (a parameter); the aircraft by its
    definition and the hash of its files (a folder changed between two solves is a new NLP), the
    ground station by its file and the hash of its bytes."""
    return (problem.scenario, problem.config, problem.d0, problem.d_tf, problem.elevation0_deg, problem.azimuth0_deg,
            problem.bounds, problem.mesh, problem.tether_drag_scale, problem.propeller,
            problem.line_weight, problem.line, problem.fold_time, problem.generator, problem.wind_profile,
            problem.line_model, problem.recovery_tension, problem.supply_voltage, problem.aircraft,
            None if problem.aircraft is None else problem.aircraft.sha256, problem.ground_station)


def get_nlp(problem: CycleProblem, glider: Glider | None = None, winch: WinchElectrics | None = None,
            cache: bool = True, disk_cache: bool | None = None) -> tuple[CycleNLP, float]:
    """The NLP for ``problem`` (built or from the caches) and the build time [s] spent now.

    ``disk_cache`` (default: the same as ``cache``): look the NLP up in the on-disk cache of
    :mod:`fdm_awe.ocp.nlpcache` before building it, and store a newly built one there.

    The cache key is the problem's structure plus the glider and winch values (both frozen
    dataclasses compared by value), so a custom glider variant is built once per process and
    reused for every wind speed of its sweep chain.
    """
    if disk_cache is None:
        disk_cache = cache
    key = (structure_key(problem), glider, winch)
    if cache and key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key], 0.0
    model = CycleModel.build(problem, glider or load_glider(problem.aircraft), winch or problem_winch(problem))
    nlp = nlpcache.load(problem, model) if disk_cache else None
    if nlp is None:
        nlp = CycleNLP(problem, model)
        if disk_cache:
            s0 = nlp.solvers_build_s
            nlpcache.save(nlp, background=True)  # generates the derivative functions (the first IPOPT instance)
            nlp.build_s += nlp.solvers_build_s - s0  # counted once, as the build of this NLP
            nlp.solvers_build_s = s0
    if cache:
        _CACHE[key] = nlp
        while len(_CACHE) > CACHE_SIZE:
            _CACHE.popitem(last=False)
    return nlp, nlp.build_s


def clear_cache() -> None:
    """Forget the NLPs kept in this process (the on-disk cache stays)."""
    _CACHE.clear()
