"""Optimal periodic pumping cycle (paper section III, corrected per docs/design.md section 4).

Modules, one job each (CasADi is imported only by the transcription, :mod:`.layout`,
:mod:`.constraints` and :mod:`.collocation`, and what uses it):

- :mod:`.problem` -- scenario, configuration, bounds and mesh dataclasses with input checks
- :mod:`.energy` -- power terms: propeller, passive-rectifier generator, reel-in motor
- :mod:`.model` -- the generation and recovery phases as state-space blocks
- :mod:`.layout` -- the decision vector: scales, Radau mesh, fold transitions
- :mod:`.constraints` -- the constraint groups: bounds, path constraints, boundaries
- :mod:`.collocation` -- Radau direct collocation of the phases, objective, IPOPT (MUMPS)
- :mod:`.build` -- the NLP of a problem, built once per structure (in-process cache)
- :mod:`.nlpcache` -- built NLPs on disk, shared between processes
- :mod:`.guess` -- crosswind-loop initial guesses, guesses from previous solutions
- :mod:`.local` -- the local strategy: warm start, starts, continuations, the budget
- :mod:`.strategy` -- the global strategy's starts, selection and worker processes
- :mod:`.solve` -- ``solve_cycle``: global strategy, mesh continuation, polish, cold check
- :mod:`.assemble` -- acceptance of a solution and the result built from it
- :mod:`.result` -- result dataclass, JSON summary, reference-trajectory file writer/reader
- :mod:`.verify` -- re-integration of the optimal controls with scipy, energy re-count

Typical use::

    from fdm_awe.ocp.problem import CycleProblem
    from fdm_awe.ocp.solve import solve_cycle
    from fdm_awe.trajectory import write_reference, read_reference

    res = solve_cycle(CycleProblem(scenario="physical", config="foldable", wind_speed=8.0))
    if res.ok:
        write_reference(res, "ref.json")
"""
