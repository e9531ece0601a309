"""Issue 30's rows side by side in one run: CSV reading against pandas,
`step_info` against python-control, the lab's two-stage identification
against NumPy's `lstsq` (and its Newey–West errors against its classical
ones), on identical data.

    python3 scripts/ahead_vs_peers.py [--rounds 3] [--repeats 5]

Each time is the minimum over rounds × repeats. The rows come from
`ahead_csv.py` and `ahead_metrics_ident.py`, which also run alone. Run on a
quiet machine: the table starts with the machine and its load."""

import argparse
import os
import platform
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import timing  # noqa: E402,F401  (first: pins BLAS to one thread)
import ahead_csv  # noqa: E402
import ahead_metrics_ident  # noqa: E402


def machine():
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return f"{cpu}, {os.cpu_count()} CPUs, load {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}"


def threads():
    """Who reads and solves on how many threads: `read_csv` takes a thread
    per CPU the process may use (at most 8) for a file of 4 MiB or more."""
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    blas = os.environ.get("OPENBLAS_NUM_THREADS", "?")
    return (
        f"ctrlab read_csv {min(cpus or 1, 8)}, pandas read_csv 1; "
        f"identification: ctrlab 1, NumPy BLAS {blas}"
    )


def fmt(seconds):
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.2f} ms"
    return f"{seconds * 1e6:.1f} µs"


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    print(f"machine: {machine()}")
    print(f"threads: {threads()}")
    rows = ahead_csv.rows(args.rounds, args.repeats)
    rows += ahead_metrics_ident.rows(args.rounds, args.repeats)
    print("| work | ctrlab | peer | peer time | ratio | target | holds |")
    print("|---|---|---|---|---|---|---|")
    failed = 0
    for r in rows:
        ratio = r["peer_s"] / r["ctrlab_s"]
        holds = ratio >= r["target"]
        failed += not holds
        print(
            f"| {r['work']} | {fmt(r['ctrlab_s'])} | {r['peer']} | {fmt(r['peer_s'])} "
            f"| {ratio:.2f}× | ≥ {r['target']:g}× | {'yes' if holds else 'NO'} |"
        )
    print(f"machine after: {machine()}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
