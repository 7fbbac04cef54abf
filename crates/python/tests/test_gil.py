"""The GIL is released while the library works: another Python thread keeps running."""

import threading
import time

import plantwide as pw
from conftest import COLUMN_A


def test_other_threads_run_during_a_sweep():
    sets = [{"feed_source.F": f"{0.9 + 0.2 * k / 63} kmol/min"} for k in range(64)]
    inside, seen, done = threading.Event(), [], threading.Event()

    def work():
        inside.set()
        t0 = time.perf_counter()
        pw.sweep(COLUMN_A, sets=sets, outputs=["bottoms.x[light]"])
        seen.append(("call", t0, time.perf_counter()))
        done.set()

    worker = threading.Thread(target=work)
    worker.start()
    inside.wait()
    ticks = []
    while not done.is_set():
        ticks.append(time.perf_counter())
    worker.join()
    _, start, end = seen[0]
    during = [t for t in ticks if start <= t <= end]
    # With the GIL held, this loop could only run at the edges of the call (a switch interval,
    # 5 ms); released, it runs all along.
    assert end - start > 0.05, "the sweep is long enough to tell"
    assert during and during[-1] - during[0] > 0.5 * (end - start), (during[:1], during[-1:], start, end)
