"""Exception types with one-line, user-facing messages, and the exit codes the command line
gives them."""

from __future__ import annotations


#: exit code of a run interrupted by Ctrl-C (128 + SIGINT, as shells report it)
EXIT_INTERRUPTED = 130
#: exit code of bad input
EXIT_INPUT = 2


class FdmAweError(Exception):
    """Base class of all errors the package raises on purpose."""


class DefinitionError(FdmAweError):
    """A definition file (aircraft, engine, tether) is missing, malformed or out of range.

    The message names the file, the element and, where it applies, the allowed range.
    """

    def __init__(self, path: object, element: str, problem: str) -> None:
        self.path = str(path)
        self.element = element
        self.problem = problem
        super().__init__(f"{self.path}: <{element}>: {problem}")


class InputError(FdmAweError):
    """A run input (command-line option, scenario value, state) is out of its allowed range."""
