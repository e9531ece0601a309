"""Interconnection fixtures: python-control's series, parallel, feedback and
append on small continuous and discrete models (state-space matrices of the
result, its poles and DC gain).

Run: python3 tests/data/gen_interconnect_fixtures.py > tests/data/interconnect_fixtures.json
"""
import json

import control
import numpy as np


def ss(a, b, c, d, dt=0):
    return control.ss(np.array(a, float), np.array(b, float), np.array(c, float),
                      np.array(d, float), dt)


def mat(m):
    m = np.atleast_2d(np.asarray(m, float))
    return {"rows": m.shape[0], "cols": m.shape[1], "data": m.flatten(order="F").tolist()}


def model(sys):
    return {"a": mat(sys.A), "b": mat(sys.B), "c": mat(sys.C), "d": mat(sys.D),
            "dt": float(sys.dt) if sys.dt else None}


def case(name, op, parts, result):
    poles = np.sort_complex(result.poles())
    return {"name": name, "op": op, "parts": [model(p) for p in parts],
            "result": model(result),
            "poles_re": poles.real.tolist(), "poles_im": poles.imag.tolist(),
            "dc_gain": mat(control.dcgain(result))}


g1 = ss([[0, 1], [-4, -0.8]], [[0], [1]], [[1, 0]], [[0.5]])
g2 = ss([[-1, 0.5, 0], [0, -2, 1], [0.3, 0, -3]], [[0], [0], [1]], [[1, 1, 0]], [[0]])
g3 = ss([[-1, 2], [-3, -4]], [[1, 0], [0, 2]], [[1, 0], [0.5, 1]], [[0.1, 0], [0, 0.2]])
k = ss(np.zeros((0, 0)), np.zeros((0, 2)), np.zeros((2, 0)), [[2, 0.5], [0, 1]])
d1 = ss([[0.9, 0.1], [0, 0.8]], [[0], [1]], [[1, 0]], [[0]], 0.01)
d2 = ss([[0.5]], [[1]], [[0.4]], [[0.2]], 0.01)

cases = [
    case("series SISO with feedthrough", "series", [g1, g2], control.series(g1, g2)),
    case("parallel SISO", "parallel", [g1, g2], control.parallel(g1, g2)),
    case("negative feedback SISO", "feedback-", [g1, g2], control.feedback(g1, g2, sign=-1)),
    case("positive feedback SISO", "feedback+", [g1, g2], control.feedback(g1, g2, sign=1)),
    case("append", "append", [g1, g2], control.append(g1, g2)),
    case("MIMO negative feedback, static gain with feedthrough", "feedback-", [g3, k],
         control.feedback(g3, k, sign=-1)),
    case("MIMO series", "series", [g3, k], control.series(g3, k)),
    case("discrete negative feedback", "feedback-", [d1, d2], control.feedback(d1, d2, sign=-1)),
    case("discrete series", "series", [d1, d2], control.series(d1, d2)),
]
print(json.dumps({"source": f"python-control {control.__version__}, numpy {np.__version__}",
                  "cases": cases}, indent=1))
