#!/usr/bin/env python3
"""Resident memory of `plantwide serve` against the commands it took: start the server on a
loopback port, send WARM commands, read VmRSS from /proc/PID/status, send N more seeded random
commands (reading VmRSS every STEP of them), and print the least-squares slope in bytes per command,
the journal's length at the end, and VmRSS over IDLE seconds with no commands (the clock running).

    tools/serve_memory.py [--bin target/release/plantwide] [--flowsheet flowsheets/column_a.json]
                          [--n 4500] [--warm 300] [--step 500] [--idle 20] [--seed 1]
                          [--mix all|plant|snapshots|journal|steps]

`all`: set, mode, ramp and pulse events, speed, pause, resume, step, snapshot and load (8 names);
`plant`: only the commands the journal keeps (set, mode, events); `snapshots`: a plant command
then a snapshot under one of 64 names, in turn; `journal`: a feed set then a step (so that
each one reaches the journal), and every 100th command a snapshot under the next of 64 names;
`steps`: `journal` without the snapshots.
"""

import argparse
import http.client
import json
import random
import re
import select
import subprocess
import time


def rss_kib(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS")


class Client:
    def __init__(self, host, port, token):
        self.conn = http.client.HTTPConnection(host, port, timeout=60)
        self.token = token

    def request(self, method, path, body=None):
        headers = {"Content-Type": "application/json"}
        if self.token:
            headers["X-Plantwide-Token"] = self.token
        self.conn.request(method, path, body=None if body is None else json.dumps(body), headers=headers)
        r = self.conn.getresponse()
        return r.status, json.loads(r.read() or b"null")


def plant_command(rng):
    k = rng.randrange(5)
    if k == 0:
        return {"set": {"feed_source.F": f"{rng.uniform(0.95, 1.05):.6f} kmol/min"}}
    if k == 1:
        return {"set": {"condenser_level.sp": f"{rng.uniform(0.45, 0.55):.6f} kmol"}}
    if k == 2:
        return {"mode": {"reboiler_level": rng.choice(["auto", "manual"])}}
    if k == 3:
        return {"event": {"type": "ramp", "path": "column.reflux", "by": f"{rng.uniform(-0.01, 0.01):.6f} kmol/min",
                          "duration": "5 min"}}
    return {"event": {"type": "pulse", "path": "column.boilup", "by": f"{rng.uniform(-0.02, 0.02):.6f} kmol/min",
                      "width": "1 min"}}


def any_command(rng):
    k = rng.randrange(10)
    if k < 4:
        return plant_command(rng)
    return [
        {"speed": rng.choice([1, 10, 60, 100])},
        {"pause": True},
        {"resume": True},
        {"step": True},
        {"snapshot": f"s{rng.randrange(8)}"},
        {"load": f"s{rng.randrange(8)}"},
    ][k - 4]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/plantwide")
    ap.add_argument("--flowsheet", default="flowsheets/column_a.json")
    ap.add_argument("--n", type=int, default=4500)
    ap.add_argument("--warm", type=int, default=300)
    ap.add_argument("--step", type=int, default=500)
    ap.add_argument("--idle", type=float, default=20.0)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mix", choices=["all", "plant", "snapshots", "journal", "steps"], default="all")
    a = ap.parse_args()
    proc = subprocess.Popen([a.bin, "serve", a.flowsheet, "--port", "0", "--speed", "10", "--rate", "1e6",
                             "--exit-after", "3600"], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, bufsize=0)
    try:
        m = re.search(r"http://(127\.0\.0\.1):(\d+)/", proc.stdout.readline().decode())
        token = None
        # A server with a session token prints it on its second line (older ones print none);
        # stdout is unbuffered, so select sees what readline has not read.
        if select.select([proc.stdout], [], [], 2.0)[0]:
            line = proc.stdout.readline().decode()
            token = line.split("token:", 1)[1].split()[0] if "token:" in line else None
        c = Client(m.group(1), int(m.group(2)), token)
        rng = random.Random(a.seed)
        counter = [0]

        def make():
            counter[0] += 1
            if a.mix == "plant":
                return plant_command(rng)
            if a.mix == "snapshots":
                return plant_command(rng) if counter[0] % 2 else {"snapshot": f"n{rng.randrange(64)}"}
            if a.mix in ("journal", "steps"):
                if a.mix == "journal" and counter[0] % 100 == 0:
                    return {"snapshot": f"j{counter[0] // 100 % 64}"}
                return {"step": True} if counter[0] % 2 else {"set": {"feed_source.F": f"{rng.uniform(0.95, 1.05):.6f} kmol/min"}}
            return any_command(rng)

        statuses = {}
        for _ in range(a.warm):
            s, _ = c.request("POST", "/api/command", make())
            statuses[s] = statuses.get(s, 0) + 1
        time.sleep(1.0)
        xs, ys = [0], [rss_kib(proc.pid)]
        for i in range(1, a.n + 1):
            try:
                s, body = c.request("POST", "/api/command", make())
            except OSError as e:
                raise SystemExit(f"command {i}: {e}; server exit status {proc.poll()}")
            statuses[s] = statuses.get(s, 0) + 1
            if s not in (200, 400, 409):
                raise SystemExit(f"command {i}: HTTP {s}: {body}")
            if i % a.step == 0:
                xs.append(i)
                ys.append(rss_kib(proc.pid))
        n = len(xs)
        mx, my = sum(xs) / n, sum(ys) / n
        slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        _, journal = c.request("GET", "/api/journal")
        print(f"{a.bin} on {a.flowsheet}, mix {a.mix}, seed {a.seed}: answers {statuses}")
        print("VmRSS [KiB] at commands " + ", ".join(f"{x}: {y}" for x, y in zip(xs, ys)))
        print(f"{slope * 1024:.0f} bytes per command (least squares over {a.n} commands; "
              f"{ys[-1] - ys[0]} KiB in all); journal {len(journal['events'])} events")
        idle0 = rss_kib(proc.pid)
        time.sleep(a.idle)
        print(f"idle {a.idle:g} s with the clock running: VmRSS {idle0} -> {rss_kib(proc.pid)} KiB")
    finally:
        proc.kill()
        proc.wait()


if __name__ == "__main__":
    main()
