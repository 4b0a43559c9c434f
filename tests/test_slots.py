"""The compiled core's named slots (:mod:`fdm_awe.slots`): layouts, checks, and no cost in
compiled code."""

from __future__ import annotations

import re

import numpy as np
import pytest

from fdm_awe import slots

LAYOUT = slots.declare("Example", ("a", ("wind", 3), "b"))
TAIL = slots.declare("ExampleTail", ("c", "d"), start=slots.size(LAYOUT))


def test_offsets_sizes_and_names_follow_the_field_list() -> None:
    assert tuple(LAYOUT) == (0, 1, 4)
    assert (LAYOUT.a, LAYOUT.wind, LAYOUT.b) == (0, 1, 4)
    assert slots.size(LAYOUT) == 5 and slots.start(LAYOUT) == 0
    assert slots.width(LAYOUT, "wind") == 3 and slots.width(LAYOUT, "b") == 1
    assert slots.names(LAYOUT) == ("a", "wind[0]", "wind[1]", "wind[2]", "b")
    assert tuple(TAIL) == (5, 6) and slots.start(TAIL) == 5 and slots.size(TAIL) == 7


def test_new_check_and_read_by_name() -> None:
    arr = slots.new(LAYOUT, 2.0)
    assert arr.shape == (5,) and arr.dtype == np.float64 and np.all(arr == 2.0)
    arr[LAYOUT.wind + 2] = 7.0
    got = slots.as_dict(LAYOUT, arr)
    assert got["a"] == 2.0 and list(got["wind"]) == [2.0, 2.0, 7.0]
    assert slots.check(LAYOUT, arr, "memory") is not None
    with pytest.raises(ValueError, match="memory: expected 5 float64 slots of Example"):
        slots.check(LAYOUT, np.zeros(4), "memory")
    with pytest.raises(ValueError, match="memory"):
        slots.check(LAYOUT, np.zeros(5, dtype=np.int64), "memory")


@pytest.mark.parametrize("fields, message", [
    (("a", "a"), "twice"), (("a", ("b", 0)), "width 0"), (("a", "2b"), "not a public identifier"),
    (("_x",), "not a public identifier")])
def test_bad_field_lists_are_refused(fields, message) -> None:
    with pytest.raises(ValueError, match=message):
        slots.declare("Bad", fields)


def test_a_tuple_not_declared_here_is_refused() -> None:
    with pytest.raises(TypeError, match="slots.declare"):
        slots.size((1, 2))  # type: ignore[arg-type]


def test_a_named_read_compiles_to_the_same_code_as_a_number() -> None:
    numba = pytest.importorskip("numba")

    def by_name(mem):
        s = 0.0
        for i in range(100):
            s += mem[LAYOUT.wind + 1] * i
        mem[LAYOUT.b] = s
        return s

    def by_number(mem):
        s = 0.0
        for i in range(100):
            s += mem[2] * i
        mem[4] = s
        return s

    named, numbered = numba.njit(by_name), numba.njit(by_number)
    arr = slots.new(LAYOUT, 1.0)
    assert named(arr.copy()) == numbered(arr.copy()) == 4950.0

    def instructions(f) -> list[str]:
        asm = f.inspect_asm(f.signatures[0])
        lines = [ln.strip() for ln in asm.splitlines()]
        code = [ln for ln in lines if ln and not ln.startswith((".", "#")) and not ln.endswith(":")]
        # symbol names carry the function's name: compare the instructions without them
        return [re.sub(r"\$?[._A-Za-z][\w.$]*by_(name|number)\w*", "SYM", ln) for ln in code]

    assert instructions(named) == instructions(numbered)


def test_a_reader_reads_several_slots_at_once() -> None:
    arr = np.arange(5.0)
    read = slots.reader(LAYOUT, "b", "a")
    assert read(arr) == (4.0, 0.0) and read(arr.tolist()) == (4.0, 0.0)
    with pytest.raises(ValueError, match="no field 'c'"):
        slots.reader(LAYOUT, "a", "c")
    with pytest.raises(ValueError, match="'wind' has 3 slots"):
        slots.reader(LAYOUT, "a", "wind")
    with pytest.raises(ValueError, match="at least two"):
        slots.reader(LAYOUT, "a")


def test_new_takes_a_dtype_for_blocks_of_handles() -> None:
    arr = slots.new(TAIL, 0, np.int64)
    assert arr.dtype == np.int64 and arr.shape == (slots.size(TAIL),) and not arr.any()
