#!/usr/bin/env python3
"""Seven-day soak of plantwide's dynamic runs: random disturbances and equipment faults, hourly
snapshots each resumed once and checked against the continuous run bit for bit.

For each plant and seed this writes a scenario of `--days` simulated days with, at random times:
- disturbances: feed-rate steps, ramps and pulses, a feed-rate random walk (a chain of hourly
  ramps), sinusoids, feed composition and temperature steps;
- equipment faults, each ended later by the scenario: an input stuck where it is or failed closed
  or open (`valve_stuck` / `valve_repaired`, on inputs controllers drive), a feed lost and restored
  (`feed_lost` / `feed_restored`, also a feed a controller drives), a composition analyzer frozen
  and repaired, a controller put to manual and back to auto;
- a snapshot every simulated hour.
It runs the scenario once (`plantwide run --json`), then resumes from every snapshot with the same
scenario and checks that the resumed CSV is, byte for byte, the continuous run's from that time
(the snapshot holds the integrator's history: a resume is the same computation). It reports runs,
simulated hours, failures, the largest conservation error (relative to throughput), resident memory
of a one-day and the full run, and the slowest simulated hour.

`--serve-minutes M` then drives `plantwide serve` on each plant for M minutes of wall time with
random commands (disturbances, faults, mode switches, snapshots, pause/resume) and reports
commands, statuses, the p99 state latency and resident memory at start and end.

Usage (from the project root, after `cargo build --release`):
    python3 tools/soak.py --days 7 --seeds 1,2,3 --serve-minutes 60
Exit status: 0 when every run and every resume held, 1 otherwise.
"""

import argparse
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLANTS = ["two_column_plant", "reactor_column_recycle"]


def plant_parts(path):
    """Feeds (with components), controller outputs and composition controllers of a flowsheet."""
    with open(path) as f:
        spec = json.load(f)
    feeds = {name: unit for name, unit in spec["units"].items() if unit["type"] == "feed"}
    pids = {n: c for n, c in spec.get("controllers", {}).items() if c.get("type") == "pid"}
    driven = {c["output"]: n for n, c in pids.items()}
    return {
        "components": [c if isinstance(c, str) else c["name"] for c in spec["components"]],
        "feeds": feeds,
        "free_feeds": [n for n in feeds if f"{n}.F" not in driven],
        "pids": pids,
        "outputs": sorted(driven),
        "analyzed": [n for n, c in pids.items() if ".x[" in c["pv"]],
    }


class Schedule:
    """Events with their targets kept apart: one event per target at a time, faults in order."""

    def __init__(self, rng, hours):
        self.rng, self.hours, self.events, self.busy = rng, hours, [], {}

    def free(self, target, start, end):
        return all(end <= a or start >= b for a, b in self.busy.get(target, []))

    def slot(self, target, length_h, margin_h=0.5):
        """A start time [h] with `target` free for `length_h` hours, or None."""
        for _ in range(50):
            start = round(self.rng.uniform(0.5, self.hours - length_h - margin_h), 3)
            if start > 0 and self.free(target, start, start + length_h + margin_h):
                self.busy.setdefault(target, []).append((start, start + length_h + margin_h))
                return start
        return None

    def add(self, at_h, event):
        self.events.append(dict(event, at=f"{at_h:.3f} h"))


def feed_flow(unit):
    value, text_unit = unit["F"].split(" ", 1)
    return float(value), text_unit


def disturbances(s, parts, n):
    """`n` random feed disturbances on the feeds no controller drives."""
    rng = s.rng
    for _ in range(n):
        if not parts["free_feeds"]:
            return
        feed = rng.choice(parts["free_feeds"])
        unit = parts["feeds"][feed]
        flow, fu = feed_flow(unit)
        path = f"{feed}.F"
        kind = rng.choice(["step", "ramp", "pulse", "walk", "sinusoid", "composition", "temperature"])
        if kind == "walk":
            steps = rng.randint(4, 12)
            at = s.slot(path, steps)
            value = flow
            for k in range(steps if at is not None else 0):
                value = max(0.5 * flow, min(1.5 * flow, value * (1 + rng.uniform(-0.03, 0.03))))
                s.add(at + k, {"type": "ramp", "path": path, "to": f"{value:.6g} {fu}", "duration": "50 min"})
            continue
        if kind == "sinusoid":
            hours = rng.uniform(2, 12)
            at = s.slot(path, hours)
            if at is not None:
                amp, period = flow * rng.uniform(0.02, 0.08), rng.choice(["30 min", "1 h", "2 h", "4 h"])
                s.add(at, {"type": "sinusoid", "path": path, "amplitude": f"{amp:.6g} {fu}", "period": period,
                           "duration": f"{hours:.3f} h"})
            continue
        if kind == "composition":
            # Every fraction input of the feed at once (the last component's fraction is the
            # balance, not an input): an impurity moves from the main component to another, from
            # the file's composition, whatever earlier steps set.
            z = unit.get("z", {})
            inputs = parts["components"][:-1]
            main = max(z, key=z.get) if z else None
            if main not in inputs:
                continue
            minor = rng.choice([c for c in parts["components"] if c != main])
            impurity = rng.uniform(0.005, 0.03)
            at = s.slot(f"{feed}.z", rng.uniform(1, 8))
            for c in inputs if at is not None else []:
                to = z.get(c, 0.0) - impurity * (c == main) + impurity * (c == minor)
                s.add(at, {"type": "step", "path": f"{feed}.z[{c}]", "to": round(to, 6)})
            continue
        if kind == "temperature":
            at = s.slot(f"{feed}.T", 1)
            if at is not None and "T" in unit:
                s.add(at, {"type": "step", "path": f"{feed}.T", "by": f"{rng.uniform(-5, 5):.3f} K"})
            continue
        at = s.slot(path, 2)
        if at is None:
            continue
        to = f"{flow * (1 + rng.uniform(-0.15, 0.15)):.6g} {fu}"
        event = {"type": kind, "path": path, "to": to}
        if kind == "ramp":
            event["duration"] = f"{rng.uniform(10, 90):.1f} min"
        elif kind == "pulse":
            event["width"] = f"{rng.uniform(5, 60):.1f} min"
        s.add(at, event)


def is_level(pid):
    """A level (inventory) loop: its measurement a level or a holdup."""
    return ".level" in pid["pv"] or ".M[" in pid["pv"]


def faults(s, parts, n, severe=False):
    """`n` random faults, each ended by the scenario. Without `severe` they are those a plant rides
    through: valves stuck where they are, feeds lost and restored, analyzers frozen, quality loops
    to manual. `severe` adds valves failed closed and level loops to manual, after which a plant
    may trip (a drum drawn dry by its reflux once the boilup valve has failed closed): the run
    then stops naming the vessel, which the soak counts as a trip, not a failure. A level loop's
    valve stuck is severe too: with the level uncontrolled, the vessel drains or fills with any
    change of its other flows (seed 2 drew column 2's drum dry with its distillate valve stuck
    while the plant recovered from a lost feed)."""
    rng = s.rng
    kinds = ["stuck", "feed_lost", "analyzer", "manual"] + (["failed"] if severe else [])
    pids = sorted(c for c, p in parts["pids"].items() if severe or not is_level(p))
    outputs = sorted(p["output"] for c, p in parts["pids"].items() if severe or not is_level(p))
    for _ in range(n):
        kind = rng.choice(kinds)
        length = rng.uniform(0.25, 4.0)
        if kind in ("stuck", "failed") and outputs:
            path = rng.choice(outputs)
            at = s.slot(path, length)
            if at is None:
                continue
            event = {"type": "valve_stuck", "path": path}
            if kind == "failed":
                # A flow valve failed closed: the input to zero.
                event["to"] = 0
            s.add(at, event)
            s.add(at + length, {"type": "valve_repaired", "path": path})
        elif kind == "feed_lost":
            feed = rng.choice(sorted(parts["feeds"]))
            at = s.slot(f"{feed}.F", length)
            if at is not None:
                s.add(at, {"type": "feed_lost", "unit": feed})
                s.add(at + length, {"type": "feed_restored", "unit": feed})
        elif kind == "analyzer" and parts["analyzed"]:
            c = rng.choice(parts["analyzed"])
            at = s.slot(f"analyzer:{c}", length)
            if at is not None:
                s.add(at, {"type": "analyzer_frozen", "controller": c})
                s.add(at + length, {"type": "analyzer_repaired", "controller": c})
        elif kind == "manual" and pids:
            c = rng.choice(pids)
            at = s.slot(parts["pids"][c]["output"], length)
            if at is not None:
                s.add(at, {"type": "mode", "controller": c, "mode": "manual"})
                s.add(at + length, {"type": "mode", "controller": c, "mode": "auto"})


def scenario(parts, seed, days, snap_dir, severe=False):
    hours = 24 * days
    s = Schedule(random.Random(seed), hours)
    disturbances(s, parts, hours // 3)
    faults(s, parts, hours // 8, severe)
    return {
        "format_version": 1,
        "name": f"soak seed {seed}",
        "duration": f"{hours} h",
        "analyzers": {c: {"sample_time": "5 min", "dead_time": "5 min"} for c in parts["analyzed"]},
        "record": {"interval": "10 min", "time_unit": "h"},
        "snapshots": [{"at": f"{h} h", "file": os.path.join(snap_dir, f"snap_{h:04d}.json")} for h in range(1, hours)],
        "events": sorted(s.events, key=lambda e: float(e["at"].split()[0])),
    }


def run(args, bin_path):
    """Run plantwide; (exit code, stdout, stderr, seconds, peak resident memory [MB])."""
    with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
        started = time.perf_counter()
        proc = subprocess.Popen([bin_path, *args], cwd=ROOT, stdout=out, stderr=err, text=True)
        # wait4 reaps the child itself: its own resource usage, not the sum of all children's.
        _, status, usage = os.wait4(proc.pid, 0)
        proc.returncode = os.waitstatus_to_exitcode(status)
        took = time.perf_counter() - started
        out.seek(0)
        err.seek(0)
        return proc.returncode, out.read(), err.read(), took, usage.ru_maxrss / 1024


def soak_one(bin_path, plant, seed, days, work, severe=False):
    fs = os.path.join(ROOT, "flowsheets", f"{plant}.json")
    parts = plant_parts(fs)
    snap_dir = os.path.join(work, f"{plant}_{seed}")
    os.makedirs(snap_dir, exist_ok=True)
    result = {"plant": plant, "seed": seed, "failures": []}
    sc = scenario(parts, seed, days, snap_dir, severe)
    sc_path = os.path.join(snap_dir, "scenario.json")
    with open(sc_path, "w") as f:
        json.dump(sc, f, indent=1)
    one_day = dict(sc, duration="24 h", snapshots=[])
    one_day["events"] = [e for e in sc["events"] if float(e["at"].split()[0]) < 24]
    with open(os.path.join(snap_dir, "one_day.json"), "w") as f:
        json.dump(one_day, f)
    _, _, _, _, rss_day = run(["run", fs, "--scenario", os.path.join(snap_dir, "one_day.json"),
                               "--csv", os.path.join(snap_dir, "day.csv")], bin_path)
    full_csv = os.path.join(snap_dir, "full.csv")
    code, out, err, took, rss = run(["run", fs, "--scenario", sc_path, "--csv", full_csv, "--json"], bin_path)
    result.update(events=len(sc["events"]), seconds=took, rss_day_mb=rss_day, rss_mb=rss)
    # A plant that trips (a vessel run dry: the engine stops with `stopped:` naming it) is an
    # honest end, not a failure of the engine; its resumes must trip the same way.
    tripped = code == 2 and ": stopped: " in err
    if code != 0 and not tripped:
        result["failures"].append(f"continuous run exit {code}: {err.strip()[-600:]}")
        return result
    with open(full_csv) as f:
        full = f.read().splitlines()
    if tripped:
        result["stopped"] = err.strip().split(": stopped: ", 1)[1][:200]
        result["hours"] = float(full[-1].split(",")[0])
    else:
        result["conservation"] = json.loads(out)["conservation"]["max_relative_error"]
        result["hours"] = 24 * days
    # The resumed runs take the same snapshots (the same stops of the integrator) into a folder of
    # their own, so that no resume overwrites a snapshot a later one starts from.
    again_dir = os.path.join(snap_dir, "again")
    os.makedirs(again_dir, exist_ok=True)
    again = dict(sc, snapshots=[dict(s, file=os.path.join(again_dir, os.path.basename(s["file"]))) for s in sc["snapshots"]])
    again_path = os.path.join(snap_dir, "scenario_resumed.json")
    with open(again_path, "w") as f:
        json.dump(again, f, indent=1)
    times, resumed = [], 0
    for h in range(1, int(result["hours"]) + 1 if tripped else 24 * days):
        snap = os.path.join(snap_dir, f"snap_{h:04d}.json")
        csv = os.path.join(snap_dir, "resumed.csv")
        code, _, err, took_h, _ = run(["run", fs, "--scenario", again_path, "--csv", csv, "--resume", snap], bin_path)
        times.append(took_h)
        if code != 0 and not (tripped and code == 2 and ": stopped: " in err):
            result["failures"].append(f"resume from hour {h}: exit {code}: {err.strip()[-400:]}")
            continue
        with open(csv) as f:
            tail = f.read().splitlines()
        # A resume from the last snapshot before a trip may reach no recording time before it:
        # then its stop (time and vessel, to the microsecond) must be the continuous run's.
        same_trip = tripped and len(tail) == 1 and err.strip().split(": stopped: ", 1)[-1][:200] == result["stopped"]
        if not same_trip and (tail[0] != full[0] or full[-(len(tail) - 1):] != tail[1:] or len(tail) < 2):
            result["failures"].append(f"resume from hour {h}: its CSV is not the continuous run's tail")
        resumed += 1
    result["resumed"] = resumed
    # The cost of hour h is the difference of the resumes from h and h+1 (both run to the end).
    per_hour = [max(0.0, times[k] - times[k + 1]) for k in range(len(times) - 1)]
    if per_hour:
        k = max(range(len(per_hour)), key=per_hour.__getitem__)
        result["slowest_hour"] = {"hour": k + 1, "seconds": per_hour[k]}
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--days", type=float, default=7)
    ap.add_argument("--seeds", default="1,2,3")
    ap.add_argument("--plants", default=",".join(PLANTS))
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "plantwide"))
    ap.add_argument("--work", default=None, help="folder for scenarios, snapshots and CSVs (default: a temporary one)")
    ap.add_argument("--serve-minutes", type=float, default=0)
    ap.add_argument("--severe", action="store_true",
                    help="also valves failed closed and level loops to manual (plants may trip, named)")
    ap.add_argument("--json", action="store_true", help="print the report as JSON")
    a = ap.parse_args()
    a.days = int(a.days) if a.days == int(a.days) else a.days
    work = a.work or tempfile.mkdtemp(prefix="plantwide_soak_")
    results = []
    for plant in a.plants.split(","):
        for seed in [int(s) for s in a.seeds.split(",")]:
            r = soak_one(a.bin, plant, seed, a.days, work, a.severe)
            results.append(r)
            print(f"{plant} seed {seed}: {r.get('events', 0)} events, {r.get('hours', 0)} h in {r.get('seconds', 0):.2f} s, "
                  f"{r.get('resumed', 0)} resumes, conservation {r.get('conservation', float('nan')):.1e}, "
                  f"RSS {r.get('rss_day_mb', 0):.0f} MB (1 day) / {r.get('rss_mb', 0):.0f} MB ({a.days} days), "
                  f"slowest hour {r.get('slowest_hour', {}).get('seconds', 0):.3f} s, failures {len(r['failures'])}",
                  flush=True)
            for f in r["failures"]:
                print(f"  FAILURE: {f}", flush=True)
            if "stopped" in r:
                print(f"  the plant tripped at {r['hours']:.2f} h: {r['stopped']}", flush=True)
    serve = []
    if a.serve_minutes > 0:
        sys.path.insert(0, os.path.join(ROOT, "tools"))
        from serve_soak import soak_serve

        for plant in a.plants.split(","):
            s = soak_serve(a.bin, os.path.join(ROOT, "flowsheets", f"{plant}.json"), a.serve_minutes * 60)
            serve.append(s)
            print(f"serve {plant}: {s['commands']} commands in {s['seconds']:.0f} s, statuses {s['statuses']}, "
                  f"state p99 {s['p99_ms']:.1f} ms, RSS {s['rss_start_mb']:.1f} -> {s['rss_end_mb']:.1f} MB, "
                  f"failures {len(s['failures'])}", flush=True)
            for f in s["failures"]:
                print(f"  FAILURE: {f}", flush=True)
    failures = sum(len(r["failures"]) for r in results + serve)
    runs = len(results) + sum(r.get("resumed", 0) for r in results)
    drift = max((r.get("conservation", 0.0) for r in results), default=0.0)
    trips = sum("stopped" in r for r in results)
    print(f"soak: {runs} runs ({len(results)} continuous, {runs - len(results)} resumed, {trips} tripped), "
          f"{sum(r.get('hours', 0) for r in results)} simulated hours, largest conservation error {drift:.1e}, "
          f"failures {failures}")
    if a.json:
        print(json.dumps({"runs": results, "serve": serve}, indent=1))
    if not a.work:
        shutil.rmtree(work, ignore_errors=True)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
