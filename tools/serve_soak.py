#!/usr/bin/env python3
"""Soak of `plantwide serve`: random operator commands for a given wall time on one plant.

The commands are those an operator (or a training instructor) gives: setpoint and feed changes,
ramps, pulses, faults and their repairs, mode switches, speed changes, pause and resume, single
steps, snapshots and loads. Each answer must be one the API documents (200, 400 with a message,
409); a state read is timed after every command; resident memory is read from /proc at the start
and the end; at the end the clock must still advance and the journal must replay (its length is
reported). A plant that stops (a failed integration, reported in the state's `failure`) is a
failure of the soak, as it would be of a training session.

    python3 tools/serve_soak.py --bin target/release/plantwide --flowsheet flowsheets/two_column_plant.json --minutes 60
"""

import argparse
import http.client
import json
import os
import random
import re
import select
import subprocess
import sys
import time

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from soak import plant_parts  # noqa: E402


def rss_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


class Client:
    def __init__(self, host, port, token):
        self.conn = http.client.HTTPConnection(host, port, timeout=60)
        self.token = token

    def request(self, method, path, body=None):
        headers = {"Content-Type": "application/json", "X-Plantwide-Token": self.token or ""}
        self.conn.request(method, path, body=None if body is None else json.dumps(body), headers=headers)
        r = self.conn.getresponse()
        return r.status, json.loads(r.read() or b"null")


class Operator:
    """Random commands that keep faults in order: a fault is repaired before the next on its target."""

    def __init__(self, parts, rng):
        self.parts, self.rng = parts, rng
        self.stuck, self.lost, self.manual = set(), set(), set()

    def feed_move(self):
        feed = self.rng.choice(self.parts["free_feeds"])
        if feed in self.lost:
            return None
        value, unit = self.parts["feeds"][feed]["F"].split(" ", 1)
        to = f"{float(value) * self.rng.uniform(0.9, 1.1):.6g} {unit}"
        kind = self.rng.choice(["set", "ramp", "pulse"])
        if kind == "set":
            return {"set": {f"{feed}.F": to}}
        event = {"type": kind, "path": f"{feed}.F", "to": to}
        event["duration" if kind == "ramp" else "width"] = f"{self.rng.uniform(1, 30):.1f} min"
        return {"event": event}

    def fault(self):
        rng, parts = self.rng, self.parts
        k = rng.randrange(3)
        # A feed's flow is one input whether a valve on it sticks or its supply is lost: one
        # fault at a time on it.
        if k == 0 and parts["outputs"]:
            path = rng.choice(parts["outputs"])
            if path in self.stuck:
                self.stuck.discard(path)
                return {"event": {"type": "valve_repaired", "path": path}}
            if path.endswith(".F") and path[:-2] in self.lost:
                return None
            self.stuck.add(path)
            return {"event": {"type": "valve_stuck", "path": path}}
        if k == 1:
            feed = rng.choice(sorted(parts["feeds"]))
            if feed in self.lost:
                self.lost.discard(feed)
                return {"event": {"type": "feed_restored", "unit": feed}}
            if f"{feed}.F" in self.stuck:
                return None
            self.lost.add(feed)
            return {"event": {"type": "feed_lost", "unit": feed}}
        c = rng.choice(sorted(parts["pids"]))
        mode = "auto" if c in self.manual else "manual"
        (self.manual.discard if mode == "auto" else self.manual.add)(c)
        return {"mode": {c: mode}}

    def refused(self, cmd):
        """Undo the bookkeeping of a command the server refused."""
        event, mode = cmd.get("event", {}), cmd.get("mode")
        kind = event.get("type")
        if kind == "valve_stuck":
            self.stuck.discard(event["path"])
        elif kind == "valve_repaired":
            self.stuck.add(event["path"])
        elif kind == "feed_lost":
            self.lost.discard(event["unit"])
        elif kind == "feed_restored":
            self.lost.add(event["unit"])
        elif mode:
            for c, m in mode.items():
                (self.manual.discard if m == "manual" else self.manual.add)(c)

    def reset(self):
        """After loading the start snapshot: no faults, every controller as the file has it."""
        self.stuck, self.lost, self.manual = set(), set(), set()

    def command(self):
        k = self.rng.randrange(12)
        if k < 5 and self.parts["free_feeds"]:
            return self.feed_move()
        if k < 8:
            return self.fault()
        return [
            {"speed": self.rng.choice([1, 10, 60, 100])},
            {"pause": True},
            {"resume": True},
            {"snapshot": f"s{self.rng.randrange(1, 8)}"},
        ][k - 8]


def start(bin_path, flowsheet):
    proc = subprocess.Popen([bin_path, "serve", flowsheet, "--port", "0", "--speed", "60", "--rate", "1e6"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, bufsize=0)
    m = re.search(r"http://(127\.0\.0\.1):(\d+)/", proc.stdout.readline().decode())
    token = None
    if select.select([proc.stdout], [], [], 2.0)[0]:
        line = proc.stdout.readline().decode()
        token = line.split("token:", 1)[1].split()[0] if "token:" in line else None
    return proc, Client(m.group(1), int(m.group(2)), token)


def soak_serve(bin_path, flowsheet, seconds, seed=1, pace=0.5):
    """Drive a server on `flowsheet` for `seconds` of wall time, a command every `pace` seconds."""
    proc, c = start(bin_path, flowsheet)
    rng = random.Random(seed)
    op = Operator(plant_parts(flowsheet), rng)
    statuses, latencies, failures, refusals, samples = {}, [], [], {}, []
    try:
        time.sleep(1.0)
        c.request("POST", "/api/command", {"snapshot": "start"})
        trips = []
        rss0, started, n = rss_mb(proc.pid), time.perf_counter(), 0
        while time.perf_counter() - started < seconds:
            cmd = op.command()
            if cmd is None:
                continue
            s, body = c.request("POST", "/api/command", cmd)
            n += 1
            statuses[s] = statuses.get(s, 0) + 1
            if s != 200:
                op.refused(cmd)
            if s == 400:
                key = str(body.get("error", ""))[:60] if isinstance(body, dict) else str(body)[:60]
                refusals[key] = refusals.get(key, 0) + 1
            if len(samples) <= (time.perf_counter() - started) // 60:
                samples.append(round(rss_mb(proc.pid), 1))
            if s not in (200, 400, 409):
                failures.append(f"command {n} {json.dumps(cmd)}: HTTP {s}: {body}")
            t0 = time.perf_counter()
            s, state = c.request("GET", "/api/state")
            latencies.append((time.perf_counter() - t0) * 1000)
            if s != 200:
                failures.append(f"state after command {n}: HTTP {s}")
            elif state.get("failure") and ": stopped: " in state["failure"]:
                # The plant tripped (a vessel run dry under the faults and manual loops the
                # operator left): as an instructor would, restart from the start snapshot.
                trips.append(f"after command {n} at t = {state['time']:.0f} s: {state['failure'][:160]}")
                s, body = c.request("POST", "/api/command", {"load": "start"})
                if s != 200:
                    failures.append(f"loading the start snapshot after a trip: HTTP {s}: {body}")
                    break
                c.request("POST", "/api/command", {"resume": True})
                op.reset()
            elif state.get("failure"):
                _, journal = c.request("GET", "/api/journal")
                kept = f"/tmp/serve_soak_failure_{os.getpid()}.json"
                with open(kept, "w") as f:
                    json.dump(journal, f, indent=1)
                failures.append(f"the plant stopped after command {n} {json.dumps(cmd)} at t = {state['time']:.0f} s: "
                                f"{state['failure']} (the journal replaying it: {kept})")
                break
            time.sleep(pace)
        c.request("POST", "/api/command", {"resume": True})
        _, before = c.request("GET", "/api/state")
        time.sleep(2.0)
        _, after = c.request("GET", "/api/state")
        if not after["time"] > before["time"] and not after.get("failure"):
            failures.append(f"the clock stalled at {after['time']} s")
        _, journal = c.request("GET", "/api/journal")
        latencies.sort()
        return {
            "flowsheet": flowsheet,
            "commands": n,
            "seconds": time.perf_counter() - started,
            "simulated_hours": after["time"] / 3600,
            "statuses": statuses,
            "p99_ms": latencies[int(0.99 * (len(latencies) - 1))] if latencies else float("nan"),
            "rss_start_mb": rss0,
            "rss_end_mb": rss_mb(proc.pid),
            "journal_events": len(journal["events"]),
            "rss_per_minute_mb": samples,
            "refusals": refusals,
            "trips": trips,
            "failures": failures,
        }
    finally:
        proc.kill()
        proc.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default="target/release/plantwide")
    ap.add_argument("--flowsheet", default="flowsheets/two_column_plant.json")
    ap.add_argument("--minutes", type=float, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--pace", type=float, default=0.5, help="seconds between commands")
    a = ap.parse_args()
    r = soak_serve(a.bin, a.flowsheet, a.minutes * 60, a.seed, a.pace)
    print(json.dumps(r, indent=1))
    sys.exit(1 if r["failures"] else 0)


if __name__ == "__main__":
    main()
