"""Checks of the Python arguments that the native half would take badly (a bool as a number,
1.5 as an integer, -1 as a count): ``TypeError`` or ``ValueError`` naming the argument and its
rule, before any work."""

from typing import Any

import numpy as np


def _integer(name: str, value: Any, minimum: int) -> int:
    """``value`` as an int >= ``minimum``; else ``TypeError`` (not an integer: a bool, a float
    such as 1.5, a string) or ``ValueError`` (too small), naming the argument and its rule."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} = {value!r}: expected an integer >= {minimum}")
    if int(value) < minimum:
        raise ValueError(f"{name} = {value!r}: expected an integer >= {minimum}")
    return int(value)


def _time(name: str, value: Any) -> float:
    """``value`` as a finite time > 0 in s; else ``TypeError`` (a bool, a string) or
    ``ValueError``, naming the argument and its rule."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} = {value!r}: expected a number of seconds > 0")
    t = float(value)
    if not (t > 0.0 and t != float("inf")):
        raise ValueError(f"{name} = {value!r}: expected a finite number of seconds > 0")
    return t
