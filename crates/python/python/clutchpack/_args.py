"""Checks of the Python arguments that the native half would take badly (a bool as a number,
1.5 as an integer, -1 as a count): ``TypeError`` or ``ValueError`` naming the argument and its
rule, before any work."""

from typing import Any

import numpy as np


#: The largest count the native half takes (a 64-bit unsigned integer): beyond it a count
#: would raise ``OverflowError`` without naming its argument.
_MAX_COUNT = 2**64 - 1


def _integer(name: str, value: Any, minimum: int, maximum: int = _MAX_COUNT) -> int:
    """``value`` as an int in ``[minimum, maximum]``; else ``TypeError`` (not an integer: a
    bool, a float such as 1.5, a string) or ``ValueError`` (out of range), naming the argument
    and its rule."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} = {value!r}: expected an integer >= {minimum}")
    if int(value) < minimum:
        raise ValueError(f"{name} = {value!r}: expected an integer >= {minimum}")
    if int(value) > maximum:
        raise ValueError(f"{name} = {value!r}: expected an integer in {minimum}..={maximum}")
    return int(value)


def _number(name: str, value: Any) -> float:
    """``value`` as a float (an input's value: a force in N, a torque in N m); else
    ``TypeError`` naming the input: a bool (``True`` would be taken as 1 N) or what is not a
    real number. Its bounds are the native half's (the scene key's)."""
    if isinstance(value, bool) or not isinstance(
        value, (int, float, np.integer, np.floating)
    ):
        raise TypeError(f"{name} = {value!r}: expected a number")
    return float(value)


def _time(name: str, value: Any) -> float:
    """``value`` as a finite time > 0 in s; else ``TypeError`` (a bool, a string) or
    ``ValueError``, naming the argument and its rule."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} = {value!r}: expected a number of seconds > 0")
    t = float(value)
    if not (t > 0.0 and t != float("inf")):
        raise ValueError(f"{name} = {value!r}: expected a finite number of seconds > 0")
    return t
