"""Wall time of a 64-point feed-rate sweep of column A on a Dask LocalCluster of 1 and of 2
single-threaded worker processes (and in process, by rayon), with the results checked equal.

    python tools/bench_python_sweep.py [--points 64] [--repeat 2]

Needs `pip install crates/python "dask[distributed]"`. Prints one line per configuration and a
final JSON line. The cluster is started and warmed (the package imported on every worker) before
the clock starts, so the times are the sweep's."""

import argparse
import json
import time
from pathlib import Path

import numpy as np
import plantwide as pw
from dask.distributed import Client, LocalCluster

COLUMN_A = str(Path(__file__).resolve().parents[1] / "flowsheets" / "column_a.json")
OUTPUTS = ["distillate.x[light]", "bottoms.x[light]"]


def timed(fn, repeat):
    """Best wall time of `repeat` calls, and the last result."""
    best, result = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t)
    return best, result


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=64)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    sets = [{"feed_source.F": f"{f} kmol/min"} for f in np.linspace(0.9, 1.1, a.points)]
    figures, results = {}, {}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            with Client(cluster) as client:
                pw.sweep(COLUMN_A, sets=sets[:workers], outputs=OUTPUTS, client=client)  # warm the workers
                figures[f"dask_{workers}_workers_s"], results[workers] = timed(
                    lambda: pw.sweep(COLUMN_A, sets=sets, outputs=OUTPUTS, client=client), a.repeat
                )
        print(f"{a.points} points on {workers} worker(s): {figures[f'dask_{workers}_workers_s']:.2f} s")
    figures["in_process_s"], here = timed(lambda: pw.sweep(COLUMN_A, sets=sets, outputs=OUTPUTS), a.repeat)
    print(f"{a.points} points in process (rayon): {figures['in_process_s']:.2f} s")
    assert np.array_equal(results[1], results[2]) and np.array_equal(results[1], here), "results differ"
    figures["speedup_2_over_1"] = figures["dask_1_workers_s"] / figures["dask_2_workers_s"]
    print(json.dumps({"points": a.points, **figures}))


if __name__ == "__main__":
    main()
