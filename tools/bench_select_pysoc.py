#!/usr/bin/env python3
"""`plantwide select` against pySOC's PB3 (Yi Cao's partial bidirectional branch and bound), in one run.

What it measures: for each case n (subset size) x K (number of best subsets), the wall time of
  plantwide  `plantwide select --matrices DATA --size n --best K --json` as a subprocess (so process
             start, reading the JSON and printing the K subsets with their H are included); fastest of
             --repeats runs (default 3), and its branch-and-bound node count (`nodes` in its JSON).
  pySOC      `pysoc.bnb.pb3wc(Gy, Gyd, Wd, Wn, Juu, Jud, n, nc=K)` in this process (pySOC 0.0.3, PyPI,
             Apache-2.0; a line-by-line Python port of Yi Cao's pb3wc.m), called as pySOC's own test
             pysoc/tests/bnb/bnb_pytest/test_bnbmatlab.py calls it (Wd, Wn as diagonals). Timed with
             time.perf_counter around the call, fastest of --repeats runs, but only one run when the
             first takes longer than --once-after seconds (default 10; the table says how many runs).
             Its node counters `ops` are printed as [terminal, nodes, sub-nodes, calls].
and it checks, per case, that both return the same K subsets (sets of 1-based measurement indices) in
the same order with worst-case losses equal to 1e-8 relative, and that both match the MATLAB PB3
results stored in the repository (the first K of the stored K = 100 ranking). Exits 1 on any
disagreement.

Data: crates/soc/tests/data/cao_ny40_nu15_nd5.json (Yi Cao's random case from pySOC's tests: 40
candidate measurements y1..y40, 15 inputs, 5 disturbances; Gy, Gyd, Juu, Jud as lists of rows, Wd, Wn
as diagonals) and crates/soc/tests/data/cao_ny40_nu15_nd5_pb3.json (the MATLAB pb3wc results).

numpy 2: pySOC 0.0.3 uses np.NaN, np.Inf and np.int, which numpy 2 removed; this script sets them
(np.nan, np.inf, int) in-process before importing pysoc and says so in its output. pySOC's import
also calls logging.basicConfig(filename='python.log'), which would write python.log into the current
directory; the root logger is given a NullHandler first, so nothing is written.

Setup (virtual environment outside the repository; the wheel is pysoc==0.0.3 from PyPI):
  python3 -m venv /tmp/bench-venv && /tmp/bench-venv/bin/pip install numpy scipy pysoc==0.0.3
Run from anywhere (the binary must be built; the script never runs cargo):
  nice -n 10 /tmp/bench-venv/bin/python tools/bench_select_pysoc.py [--bin target/release/plantwide]
      [--sizes 15 20 25] [--best 5 100] [--repeats 3] [--once-after 10]
A relative --bin is taken from the repository root. Prints machine information and versions, then one
table row per case.
"""

import argparse
import json
import logging
import os
import platform
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path

import numpy as np
import scipy

REPO = Path(__file__).resolve().parent.parent
DATA = REPO / "crates/soc/tests/data/cao_ny40_nu15_nd5.json"
REFERENCE = REPO / "crates/soc/tests/data/cao_ny40_nu15_nd5_pb3.json"
RTOL = 1e-8
SETUP = "python3 -m venv /tmp/bench-venv && /tmp/bench-venv/bin/pip install numpy scipy pysoc==0.0.3"


def load_pb3wc():
    """Apply the numpy-2 shims pySOC needs, silence its log file, import it; (pb3wc, shims applied)."""
    shims = []
    for name, value in (("NaN", np.nan), ("Inf", np.inf), ("int", int)):
        if not hasattr(np, name):
            setattr(np, name, value)
            shims.append(f"np.{name}")
    logging.basicConfig(handlers=[logging.NullHandler()], level=logging.CRITICAL)
    try:
        from pysoc.bnb import pb3wc
    except ImportError as e:
        sys.exit(f"bench_select_pysoc.py: cannot import pysoc ({e}); set up with: {SETUP}")
    return pb3wc, shims


def load_case():
    """(matrices as numpy arrays in pb3wc's argument order, measurement names, MATLAB results by n)."""
    data = json.loads(DATA.read_text())
    matrices = tuple(np.array(data[key], dtype=float) for key in ("Gy", "Gyd", "Wd", "Wn", "Juu", "Jud"))
    reference = {r["n"]: r for r in json.loads(REFERENCE.read_text())["results"]}
    return matrices, data["measurements"], reference


def run_plantwide(binary, n, k, repeats, names):
    """(fastest wall [s], subsets as tuples of 1-based indices, worst-case losses, nodes, deterministic)."""
    index = {name: i + 1 for i, name in enumerate(names)}
    cmd = [str(binary), "select", "--matrices", str(DATA), "--size", str(n), "--best", str(k), "--json"]
    walls, results = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        walls.append(time.perf_counter() - start)
        if proc.returncode != 0:
            sys.exit(f"bench_select_pysoc.py: {' '.join(cmd)} exited {proc.returncode}: {proc.stderr.strip()}")
        out = json.loads(proc.stdout)
        subsets = [tuple(sorted(index[m] for m in s["measurements"])) for s in out["subsets"]]
        losses = [s["worst_case_loss"] for s in out["subsets"]]
        results.append((subsets, losses, out["nodes"]))
    subsets, losses, nodes = results[0]
    return min(walls), subsets, losses, nodes, all(r == results[0] for r in results)


def run_pysoc(pb3wc, matrices, n, k, repeats, once_after):
    """(fastest wall [s], runs, subsets as tuples of 1-based indices, worst-case losses, ops)."""
    walls = []
    while len(walls) < repeats:
        args = [m.copy() for m in matrices]
        start = time.perf_counter()
        losses, sset, ops, _, _ = pb3wc(*args, n, nc=k)
        walls.append(time.perf_counter() - start)
        if walls[0] > once_after:
            break
    subsets = [tuple(int(i) for i in row) for row in sset]
    return min(walls), len(walls), subsets, [float(x) for x in losses], [int(x) for x in ops]


def max_rel_diff(a, b):
    """Largest |a_i - b_i| / |b_i| over two equally long loss lists."""
    return max(abs(x - y) / abs(y) for x, y in zip(a, b))


def compare(label, subsets, losses, ref_subsets, ref_losses):
    """(max relative loss difference, problems): same subsets in the same order and losses to RTOL."""
    problems = []
    if len(subsets) != len(ref_subsets) or len(losses) != len(ref_losses):
        return float("inf"), [f"{label}: {len(subsets)} subsets vs {len(ref_subsets)}"]
    if subsets != ref_subsets:
        first = next(i for i, (s, r) in enumerate(zip(subsets, ref_subsets)) if s != r)
        problems.append(f"{label}: subsets differ from rank {first + 1}")
    diff = max_rel_diff(losses, ref_losses)
    if not diff <= RTOL:
        problems.append(f"{label}: loss rel diff {diff:.1e}")
    return diff, problems


def machine_info(binary):
    """Lines describing the machine, its load and the software versions."""
    cpu = next((line.split(":", 1)[1].strip() for line in Path("/proc/cpuinfo").read_text().splitlines()
                if line.startswith("model name")), platform.processor())
    nproc = subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip()
    version = subprocess.run([str(binary), "--version"], capture_output=True, text=True).stdout.strip()
    return [
        f"machine: {cpu}; os.cpu_count() = {os.cpu_count()}, nproc = {nproc}; "
        f"load average (1, 5, 15 min) = {' '.join(f'{x:.2f}' for x in os.getloadavg())}; "
        f"nice = {os.nice(0)}",
        f"versions: {version}; Python {platform.python_version()}, numpy {np.__version__}, "
        f"scipy {scipy.__version__}, pysoc {metadata.version('pysoc')}",
    ]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", type=Path, default=Path("target/release/plantwide"),
                    help="plantwide binary (relative paths from the repository root)")
    ap.add_argument("--sizes", type=int, nargs="+", default=[15, 20, 25], help="subset sizes n")
    ap.add_argument("--best", type=int, nargs="+", default=[5, 100], help="numbers of best subsets K")
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per tool; the fastest is reported")
    ap.add_argument("--once-after", type=float, default=10.0,
                    help="run pySOC only once in a case whose first run takes longer than this [s]")
    args = ap.parse_args()
    binary = args.bin if args.bin.is_absolute() else REPO / args.bin
    if not binary.is_file():
        sys.exit(f"bench_select_pysoc.py: no plantwide binary at {binary} (build it first)")

    pb3wc, shims = load_pb3wc()
    matrices, names, reference = load_case()
    for line in machine_info(binary):
        print(line)
    print(f"numpy-2 shims set before importing pysoc: {', '.join(shims) if shims else 'none needed'}")
    print(f"data: {DATA.relative_to(REPO)}; MATLAB reference: {REFERENCE.relative_to(REPO)}")
    print(f"plantwide: fastest of {args.repeats} runs (subprocess wall time); pySOC: fastest of "
          f"{args.repeats} runs, or 1 run when the first takes > {args.once_after:g} s; "
          f"losses compared to {RTOL:g} relative")
    print()
    header = (f"{'case':<11} {'plantwide s':>11} {'nodes':>7} {'pySOC s':>8} {'runs':>4} "
              f"{'pySOC ops [term, nodes, sub, calls]':<36} {'pySOC/pw':>8} {'Δ pw-py':>8} {'Δ pw-ML':>8} "
              f"{'load':>5}  agree?")
    print(header)
    print("-" * len(header))
    failures = 0
    for n in args.sizes:
        for k in args.best:
            load = os.getloadavg()[0]
            pw_s, pw_subsets, pw_losses, nodes, deterministic = run_plantwide(
                binary, n, k, args.repeats, names)
            py_s, py_runs, py_subsets, py_losses, ops = run_pysoc(
                pb3wc, matrices, n, k, args.repeats, args.once_after)
            d_py, problems = compare("plantwide vs pySOC", pw_subsets, pw_losses, py_subsets, py_losses)
            if not deterministic:
                problems.append("plantwide's repeated runs differ")
            ref = reference.get(n)
            if ref is not None and k <= len(ref["subsets"]):
                ref_subsets = [tuple(s) for s in ref["subsets"][:k]]
                ref_losses = ref["worst_case_loss"][:k]
                d_ml, pw_problems = compare("plantwide vs MATLAB", pw_subsets, pw_losses, ref_subsets, ref_losses)
                _, py_problems = compare("pySOC vs MATLAB", py_subsets, py_losses, ref_subsets, ref_losses)
                problems += pw_problems + py_problems
                d_ml_text = f"{d_ml:.1e}"
            else:
                d_ml_text = "n/a"
            failures += bool(problems)
            print(f"{f'n={n} K={k}':<11} {pw_s:>11.3f} {nodes:>7} {py_s:>8.2f} {py_runs:>4} {str(ops):<36} "
                  f"{py_s / pw_s:>8.1f} {d_py:>8.1e} {d_ml_text:>8} {load:>5.2f}  "
                  f"{'yes' if not problems else 'NO: ' + '; '.join(problems)}", flush=True)
    print()
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print("all cases agree" if not failures else f"{failures} case(s) disagree")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
