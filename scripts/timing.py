"""What the side-by-side timing scripts share. Import it before NumPy: it
pins the BLAS libraries to one thread (ctrlab's solvers run on one), unless the
caller set them."""

import json
import os
import subprocess
import tempfile
import time

for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(var, "1")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def median_time(f, repeats):
    """The median wall time of `repeats` calls of `f`, in seconds."""
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return sorted(times)[len(times) // 2]


def run_example(example, payload):
    """Runs `cargo run --release --example <example> -- <file>` with
    `payload` written to a temporary JSON file; returns the JSON objects
    the example printed, one per line."""
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(payload, f)
        path = f.name
    try:
        out = subprocess.run(
            ["cargo", "run", "--quiet", "--release", "--example", example, "--", path],
            cwd=ROOT, check=True, capture_output=True, text=True,
        ).stdout
    finally:
        os.unlink(path)
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")]
