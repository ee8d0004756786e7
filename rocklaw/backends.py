"""Evaluation backends, so that a force law is written once and evaluated two ways.

A law written against the small interface below (``where``, ``minimum``, ``maximum``,
``sin``, ``mod``) runs

* numerically with :data:`NUMERIC` (NumPy: scalars or arrays), as used by the ODE formulation,
  the tests and post-processing, or :data:`SCALAR` (plain floats, for Python callbacks), and
* symbolically with :data:`SYMBOLIC` (``exudyn.symbolic``), recorded once into an expression
  tree that Exudyn evaluates in C++ at every solver evaluation (no Python call per evaluation).

A Python ``if`` on a symbolic value would be recorded once and silently keep one branch;
laws must branch with ``where`` only.
"""

from __future__ import annotations

import math
from typing import Any, Protocol

import numpy as np


class Backend(Protocol):
    """The operations a force law may use on its arguments."""

    def where(self, condition: Any, if_true: Any, if_false: Any) -> Any: ...
    def minimum(self, a: Any, b: Any) -> Any: ...
    def maximum(self, a: Any, b: Any) -> Any: ...
    def sin(self, x: Any) -> Any: ...
    def mod(self, x: Any, y: Any) -> Any: ...


class NumericBackend:
    """NumPy evaluation; returns floats for scalar input."""

    @staticmethod
    def _scalar(value: Any) -> Any:
        return float(value) if np.ndim(value) == 0 else value

    def where(self, condition: Any, if_true: Any, if_false: Any) -> Any:
        return self._scalar(np.where(condition, if_true, if_false))

    def minimum(self, a: Any, b: Any) -> Any:
        return self._scalar(np.minimum(a, b))

    def maximum(self, a: Any, b: Any) -> Any:
        return self._scalar(np.maximum(a, b))

    def sin(self, x: Any) -> Any:
        return self._scalar(np.sin(x))

    def mod(self, x: Any, y: Any) -> Any:
        return self._scalar(np.mod(x, y))


class ScalarBackend:
    """Plain Python floats (math module): the fastest way to evaluate a law in a Python callback."""

    def where(self, condition: Any, if_true: Any, if_false: Any) -> Any:
        return if_true if condition else if_false

    def minimum(self, a: Any, b: Any) -> Any:
        return min(b, a)

    def maximum(self, a: Any, b: Any) -> Any:
        return max(b, a)

    def sin(self, x: Any) -> Any:
        return math.sin(x)

    def mod(self, x: Any, y: Any) -> Any:
        return x % y


class SymbolicBackend:
    """``exudyn.symbolic`` evaluation: every constant is wrapped as a symbolic ``Real``."""

    def __init__(self) -> None:
        from .exudyn_module import exu

        self._sym = exu.symbolic

    def _real(self, value: Any) -> Any:
        return self._sym.Real(float(value)) if isinstance(value, (int, float, np.floating)) else value

    def where(self, condition: Any, if_true: Any, if_false: Any) -> Any:
        return self._sym.IfThenElse(condition, self._real(if_true), self._real(if_false))

    def minimum(self, a: Any, b: Any) -> Any:
        return self._sym.min(self._real(a), self._real(b))

    def maximum(self, a: Any, b: Any) -> Any:
        return self._sym.max(self._real(a), self._real(b))

    def sin(self, x: Any) -> Any:
        return self._sym.sin(self._real(x))

    def mod(self, x: Any, y: Any) -> Any:
        return self._sym.mod(self._real(x), self._real(y))


NUMERIC: Backend = NumericBackend()
SCALAR: Backend = ScalarBackend()
