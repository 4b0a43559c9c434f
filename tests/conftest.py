import os

os.environ.setdefault("JSBSIM_DEBUG", "0")
os.environ.setdefault("MPLBACKEND", "Agg")
# the tests' many small NLPs are not written to the user's on-disk NLP cache (its own tests
# switch it on in a temporary folder)
os.environ.setdefault("FDM_AWE_NLP_CACHE", "off")

import signal  # noqa: E402

# The tests exercise Ctrl-C as a user at a terminal sends it. A suite started in the background
# by a non-interactive shell (or under nohup) inherits SIGINT ignored, and then neither this
# process nor the commands it starts would see Ctrl-C: restore Python's own handler here, which
# also gives every child process the default disposition (an ignored signal is inherited across
# exec, a handler is not).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

import pytest  # noqa: E402


class WorkStarted(AssertionError):
    """Raised by a spy: the command began its work although an input was bad."""


@pytest.fixture
def no_work(monkeypatch):
    """Every command's work raises :class:`WorkStarted` (fly: the flight, optimize/compare and
    fly without a reference: the optimisation, sweep: the sweep, info: the glide computations)."""
    import fdm_awe.sim.flight as flight
    import fdm_awe.ocp.solve as solve
    import fdm_awe.pointmass.performance as performance
    import fdm_awe.sweep.execute as execute

    def spy(name):
        def f(*a, **kw):
            raise WorkStarted(f"{name} was called")
        return f

    monkeypatch.setattr(flight, "fly", spy("fly"))
    monkeypatch.setattr(solve, "solve_cycle", spy("solve_cycle"))
    monkeypatch.setattr(execute, "run_sweep", spy("run_sweep"))
    monkeypatch.setattr(performance, "steady_glide", spy("steady_glide"))  # info's work

