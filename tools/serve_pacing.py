#!/usr/bin/env python3
"""Real-time pacing of `plantwide serve`: start the server on a loopback port at speed ×K, read
`GET /api/state` now and after WALL seconds, and compare the simulated time that passed with
K × the wall time that passed. Prints the relative error and whether the run fell behind.

    tools/serve_pacing.py [--flowsheet flowsheets/two_column_plant.json] [--speed 1] [--wall 60]
                          [--bin target/release/plantwide]
"""

import argparse
import json
import re
import subprocess
import time
import urllib.request


def state(base):
    with urllib.request.urlopen(base + "api/state") as r:
        return json.load(r)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--flowsheet", default="flowsheets/two_column_plant.json")
    ap.add_argument("--speed", type=float, default=1.0)
    ap.add_argument("--wall", type=float, default=60.0)
    ap.add_argument("--bin", default="target/release/plantwide")
    a = ap.parse_args()
    proc = subprocess.Popen([a.bin, "serve", a.flowsheet, "--port", "0", "--speed", str(a.speed),
                             "--exit-after", str(a.wall + 600)],
                            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        m = re.search(r"http://(127\.0\.0\.1:\d+)/", proc.stdout.readline())
        base = "http://" + m.group(1) + "/"
        time.sleep(2.0)  # past the start
        w0, s0 = time.monotonic(), state(base)
        behind = 0
        samples = 0
        while time.monotonic() - w0 < a.wall:
            time.sleep(1.0)
            behind += bool(state(base)["behind"])
            samples += 1
        w1, s1 = time.monotonic(), state(base)
        sim, wall = s1["time"] - s0["time"], w1 - w0
        err = sim / (a.speed * wall) - 1.0
        print(f"{a.flowsheet} at x{a.speed:g}: {sim:.3f} s simulated in {wall:.3f} s of wall time; "
              f"pacing error {100 * err:+.3f} %; behind at {behind} of {samples} samples")
    finally:
        proc.kill()
        proc.wait()


if __name__ == "__main__":
    main()
