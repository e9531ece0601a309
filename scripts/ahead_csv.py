"""ctrlab's `Recording::read_csv` against pandas' `read_csv`, on the same
files, in the same run (issue 30, item 1: at least 1.5x pandas' speed).

    python3 scripts/ahead_csv.py

Writes the lab log of `benches/csv.rs` (1e6 rows `t,u,x1,x2`, 31 MB) once
to a temporary directory, and the same log as Excel writes it in a German
locale (`;`, decimal commas; no comments); builds and runs
`examples/csv_bench.rs` (release) on both, times pandas on the same files,
and prints one table. Each time is the minimum over `rounds` rounds of
`repeats` reads (wall clock, this machine). pandas reads on one thread;
ctrlab's `read_csv` reads a file of 4 MiB or more on a thread per CPU the
process may use (`taskset -c 0 python3 scripts/ahead_csv.py`: one).

`rows()` is what `scripts/ahead_vs_peers.py` calls.
"""

import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timing  # noqa: E402  (sets the BLAS threads first)

import time  # noqa: E402

import pandas as pd  # noqa: E402

ROWS = 1_000_000
TARGET = 1.5


def lab_log():
    """`benches/csv.rs`'s `lab_log`: time in s to the millisecond, the
    input in V, positions in mm to six decimals."""
    out = ["t_s,u,x1_mm,x2_mm\n"]
    for k in range(ROWS):
        t = k * 0.002
        u = "2" if (k // 100) % 2 == 0 else "-2"
        x1 = 12.5 * math.sin(t * 3.1)
        x2 = 20.25 * math.cos(t * 2.3)
        out.append(f"{t:.3f},{u},{x1:.6f},{x2:.6f}\n")
    return "".join(out)


CASES = [
    # (work, file name, pandas keyword arguments, transform of the log)
    ("CSV, 1e6 rows t,u,x1,x2 (31 MB)", "comma.csv", {}, lambda s: s),
    (
        "CSV, 1e6 rows t;u;x1;x2 decimal commas",
        "semicolon.csv",
        {"sep": ";", "decimal": ","},
        lambda s: s.replace(",", ";").replace(".", ","),
    ),
]


def min_time(f, repeats):
    """The minimum wall time of `repeats` calls of `f`, in seconds."""
    best = math.inf
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def rows(rounds=3, repeats=5):
    """One row per log: ctrlab's and pandas' minimum time over `rounds`
    rounds of `repeats` reads of the same file."""
    with tempfile.TemporaryDirectory() as tmp:
        log = lab_log()
        paths = {}
        for work, name, _, transform in CASES:
            paths[work] = os.path.join(tmp, name)
            with open(paths[work], "w", newline="") as f:
                f.write(transform(log))
        del log
        payload = {
            "cases": [{"name": work, "path": paths[work], "repeats": repeats} for work, *_ in CASES]
        }
        ours = {work: math.inf for work, *_ in CASES}
        theirs = dict(ours)
        for _ in range(rounds):
            for line in timing.run_example("csv_bench", payload):
                ours[line["name"]] = min(ours[line["name"]], line["min_s"])
            for work, _, kwargs, _ in CASES:
                frame = pd.read_csv(paths[work], **kwargs)
                assert frame.shape == (ROWS, 4), frame.shape
                t = min_time(lambda: pd.read_csv(paths[work], **kwargs), repeats)
                theirs[work] = min(theirs[work], t)
    return [
        {
            "work": work,
            "ctrlab_s": ours[work],
            "peer": "pandas read_csv" + ("" if not kwargs else "(sep=';', decimal=',')"),
            "peer_s": theirs[work],
            "target": TARGET,
        }
        for work, _, kwargs, _ in CASES
    ]


def main():
    print(f"{'work':<42} {'ctrlab':>10} {'pandas':>10} {'ratio':>6} {'target':>6}")
    for row in rows():
        ratio = row["peer_s"] / row["ctrlab_s"]
        print(
            f"{row['work']:<42} {row['ctrlab_s'] * 1e3:>7.1f} ms {row['peer_s'] * 1e3:>7.1f} ms "
            f"{ratio:>6.2f} {row['target']:>6.1f}"
        )


if __name__ == "__main__":
    main()
