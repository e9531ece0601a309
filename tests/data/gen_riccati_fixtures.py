"""Exports SciPy's own CAREX/DAREX Riccati test cases to JSON.

The cases, their known failures and their required precisions are read from
SciPy's test module (scipy/linalg/tests/test_solvers.py, classes
TestSolveContinuousAre and TestSolveDiscreteAre), not copied by hand, and
SciPy's own solution X (solve_continuous_are / solve_discrete_are) is stored
next to each for cross-checking.

    python3 tests/data/gen_riccati_fixtures.py > tests/data/riccati_fixtures.json
"""

import json
import sys

import numpy as np
import scipy
from scipy.linalg import solve_continuous_are, solve_discrete_are

# The test module imports pytest only for its decorators; a stand-in lets it
# load without pytest installed (its cases are plain module data).
try:
    import pytest  # noqa: F401
except ImportError:
    import types

    class _Anything:
        def __getattr__(self, name):
            return _Anything()

        def __call__(self, *args, **kwargs):
            # Used as a decorator (`@pytest.mark.parametrize(...)`): pass through.
            if len(args) == 1 and callable(args[0]) and not kwargs:
                return args[0]
            return _Anything()

    stub = types.ModuleType("pytest")
    stub.__getattr__ = lambda name: _Anything()
    sys.modules["pytest"] = stub

from scipy.linalg.tests import test_solvers as ts  # noqa: E402


def mat(m):
    """A real or complex matrix as {re, im} lists of rows (im omitted if real)."""
    m = np.atleast_2d(np.asarray(m))
    out = {"re": np.real(m).astype(float).tolist()}
    if np.iscomplexobj(m) and np.any(np.imag(m) != 0):
        out["im"] = np.imag(m).astype(float).tolist()
    return out


def export(cls, solver, kind):
    rows = []
    tols = getattr(cls, "max_tol", None)
    for j, (a, b, q, r, knownfailure) in enumerate(cls.cases):
        dec = cls.min_decimal[j]
        if knownfailure:
            # SciPy expects these to fail (xfail); the tests skip them, so
            # their matrices (CAREX 20 alone has 421 states) are left out.
            rows.append({"index": j, "kind": kind, "knownfailure": knownfailure})
            continue
        row = {
            "index": j,
            "kind": kind,
            "a": mat(a),
            "b": mat(b),
            "q": mat(q),
            "r": mat(r),
            "knownfailure": knownfailure,
            "min_decimal": dec,
            # The absolute bound SciPy's test applies to every residual entry.
            "atol": (tols[j] if tols is not None else (1.5 * 10.0 ** -dec if dec is not None else None)),
        }
        try:
            row["scipy_x"] = mat(solver(a, b, q, r))
        except Exception as e:  # a known failure may raise
            row["scipy_x"] = None
            row["scipy_error"] = str(e)
        rows.append(row)
    return rows


out = {
    "source": "scipy/linalg/tests/test_solvers.py (TestSolveContinuousAre, TestSolveDiscreteAre)",
    "scipy_version": scipy.__version__,
    "numpy_version": np.__version__,
    "residual_check": "continuous: every |entry| of X A + A^H X - X B R^-1 B^H X + Q below atol; "
    "discrete: of A^H X A - X + Q - A^H X B (R + B^H X B)^-1 B^H X A",
    "carex": export(ts.TestSolveContinuousAre, solve_continuous_are, "continuous"),
    "darex": export(ts.TestSolveDiscreteAre, solve_discrete_are, "discrete"),
}
json.dump(out, sys.stdout, indent=None, separators=(",", ":"))
sys.stdout.write("\n")
