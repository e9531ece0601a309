"""ctrlab's MPC move against python-control 0.10.2's optimal-control MPC
(`control.optimal`, the problem `create_mpc_iosystem` solves every step,
by SciPy's SLSQP) on the same constrained problem, in the same run (issue
31: the solve time per tick of the lab's problem beside python-control's).

    python3 scripts/mpc_vs_python.py [--repeats 5]

The problem: the lab's nominal two-cart plant (docs/lab.md: m1 = 1.3 kg,
m2 = 0.7 kg, k1 = k2 = 1000 N/m, b1 = 10, b2 = 5 N·s/m, K = 1 N/V),
ZOH at 2 ms, both positions measured; cart 2 to 45 mm from a state;
Q = diag(1e4, 0, 1e6, 0), R = 0.01, the terminal weight P the discrete
Riccati solution; the drive limited to ±24 V and both positions to
±48 mm (hard: python-control has no soft constraints); horizons 20, 30
and 40. python-control's discrete problem sums the stage cost over the
horizon's points including the last, so its terminal weight is P − Q to
make the two problems the same.

Each ctrlab move is timed from a controller fresh from its design (no
earlier plan to start from, as at a step), by `examples/mpc_bench.rs`;
python-control's `compute_trajectory` from its default initial guess.
Both first inputs are printed with their difference: SLSQP's tolerance
is about 1e-6 relative. Times are medians (wall clock, this machine, one
thread).
"""

import argparse
import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import median_time, run_example  # noqa: E402  (sets the BLAS threads first)

import control  # noqa: E402
import control.optimal as opt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.linalg import solve_discrete_are  # noqa: E402
from scipy.signal import cont2discrete  # noqa: E402

warnings.simplefilter("ignore")

DT = 0.002
UMAX = 24.0
XMAX = 0.048
SETPOINT = 0.045


def lab_plant():
    m1, m2, k1, k2, b1, b2, gain = 1.3, 0.7, 1000.0, 1000.0, 10.0, 5.0, 1.0
    a = np.array([
        [0.0, 1.0, 0.0, 0.0],
        [-(k1 + k2) / m1, -b1 / m1, k2 / m1, 0.0],
        [0.0, 0.0, 0.0, 1.0],
        [k2 / m2, 0.0, -k2 / m2, -b2 / m2],
    ])
    b = np.array([[0.0], [0.0], [0.0], [gain / m2]])
    c = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    ad, bd, _, _, _ = cont2discrete((a, b, c, np.zeros((2, 1))), DT, method="zoh")
    return ad, bd, c


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    a, b, c = lab_plant()
    q = np.diag([1e4, 0.0, 1e6, 0.0])
    r = np.array([[0.01]])
    p = solve_discrete_are(a, b, q, r)
    # The steady state with cart 2 at the setpoint: (I − A) xs = B us.
    k = np.block([[np.eye(4) - a, -b], [np.array([[0.0, 0.0, 1.0, 0.0, 0.0]])]])
    sol = np.linalg.solve(k, np.array([0.0, 0.0, 0.0, 0.0, SETPOINT]))
    xs, us = sol[:4], sol[4:]
    states = {
        "step from rest": np.zeros(4),
        "mid-transient": np.array([0.012, 0.15, 0.030, 0.40]),
        "near the setpoint": xs + np.array([0.0002, -0.001, 0.0003, 0.002]),
    }
    horizons = (20, 30, 40)
    payload = {
        "a": a.tolist(), "b": b.tolist(), "c": c.tolist(), "dt": DT,
        "q": q.tolist(), "r": r.tolist(), "umax": UMAX, "xmax": XMAX, "tracked": 1,
        "cases": [
            {"name": f"{h} {name}", "horizon": h, "x0": x0.tolist(), "reference": SETPOINT,
             "repeats": 201}
            for h in horizons for name, x0 in states.items()
        ],
    }
    ours = {line["name"]: line for line in run_example("mpc_bench", payload)}

    sys_ = control.ss(a, b, np.eye(4), np.zeros((4, 1)), DT)
    print(f"{'horizon':>7} {'state':<18} {'ctrlab':>10} {'python-control':>15} {'ratio':>8}  "
          f"{'u0 ctrlab':>10} {'u0 python':>10} {'|Δu0| (V)':>9}")
    for h in horizons:
        timepts = np.arange(h + 1) * DT
        ocp = opt.OptimalControlProblem(
            sys_, timepts,
            integral_cost=opt.quadratic_cost(sys_, q, r, x0=xs, u0=us),
            trajectory_constraints=[
                opt.input_range_constraint(sys_, [-UMAX], [UMAX]),
                opt.state_range_constraint(sys_, [-XMAX, -np.inf, -XMAX, -np.inf],
                                           [XMAX, np.inf, XMAX, np.inf]),
            ],
            terminal_cost=opt.quadratic_cost(sys_, p - q, None, x0=xs),
        )
        for name, x0 in states.items():
            mine = ours[f"{h} {name}"]
            result = {}

            def solve():
                result["r"] = ocp.compute_trajectory(x0, print_summary=False)

            theirs = median_time(solve, args.repeats)
            u_theirs = float(np.atleast_2d(result["r"].inputs)[0, 0])
            ratio = theirs / mine["median"]
            print(f"{h:>7} {name:<18} {mine['median'] * 1e6:>8.1f} µs {theirs * 1e3:>12.1f} ms "
                  f"{ratio:>7.0f}×  {mine['u0']:>10.4f} {u_theirs:>10.4f} "
                  f"{abs(mine['u0'] - u_theirs):>9.1e}"
                  + ("" if result["r"].success else "  (python-control: not converged)"))
    print(f"(ctrlab: median of 201 moves, each from a fresh controller; python-control: "
          f"median of {args.repeats} solves; load {os.getloadavg()[0]:.2f})")


if __name__ == "__main__":
    main()
