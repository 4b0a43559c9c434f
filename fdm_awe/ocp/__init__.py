"""Optimal periodic pumping cycle (paper section III, corrected per docs/design.md section 4).

Modules, one job each (CasADi is imported only by :mod:`.collocation` and what uses it):

- :mod:`.problem` -- scenario, configuration, bounds and mesh dataclasses with input checks
- :mod:`.energy` -- power terms: propeller, passive-rectifier generator, reel-in motor
- :mod:`.model` -- the generation and recovery phases as state-space blocks
- :mod:`.collocation` -- Radau direct collocation, scaling, IPOPT (MUMPS)
- :mod:`.guess` -- crosswind-loop initial guesses, guesses from previous solutions
- :mod:`.solve` -- starts, homotopy, mesh continuation, warm starts, NLP cache
- :mod:`.result` -- result dataclass, JSON summary, reference-trajectory file writer/reader
- :mod:`.verify` -- re-integration of the optimal controls with scipy, energy re-count

Typical use::

    from fdm_awe.ocp.problem import CycleProblem
    from fdm_awe.ocp.solve import solve_cycle
    from fdm_awe.ocp.result import write_reference, read_reference

    res = solve_cycle(CycleProblem(scenario="physical", config="foldable", wind_speed=8.0))
    if res.ok:
        write_reference(res, "ref.json")
"""
