#!/usr/bin/env python3
"""Column A feed step: plantwide's BDF against SciPy, SUNDIALS CVODE and CasADi, in one run.

What it measures: the wall time (median of repeated runs, after one untimed warm-up run) of integrating
the same model and scenario as tools/bench_bdf_scipy.py, whose model definition (constants, state
layout n[i, c] in mol, RHS, sparsity pattern, steady state by fsolve) is imported from there unchanged:
Skogestad's column A in closed loop (LV, P-only level loops D = 0.5 + 10 (M_41 - 0.5),
B = 0.5 + 10 (M_1 - 0.5) [kmol/min, kmol]), feed step F 1 -> 1.01 kmol/min at t = 0, 2000 min,
rtol 1e-6, atol 1e-8 x nominal (0.5 kmol per component holdup, so 5e-6 mol for every state), SI units
(mol, s). Every Python peer starts from the same steady state at F = 1 (the array returned by fsolve);
plantwide starts from its own converged steady state. The script checks that the final xB, yD agree.

Peers:
  scipy_bdf           scipy.integrate.solve_ivp(method="BDF"), Python (numpy) RHS, Jacobian by grouped
                      finite differences on the exact sparsity pattern (jac_sparsity), sparse LU (SuperLU).
  cvode_python        SUNDIALS CVODE (scikit-sundae), BDF, Python (numpy) RHS, band linear solver
                      (lband = uband = 3, the bandwidth of the block-tridiagonal Jacobian), Jacobian by
                      CVODE's internal band difference quotients (7 RHS calls per Jacobian).
  cvode_python_dense  the same with the dense linear solver and dense difference quotients (82 RHS calls
                      per Jacobian).
                      For both, rhs_s = (RHS calls, counted by a wrapper, incl. difference quotients) x
                      (time per RHS call, measured separately on the initial state), i.e. the share of
                      the wall time spent in the Python RHS itself (callback overhead from C not included).
  casadi_cvodes       CasADi's "cvodes" plugin on the RHS written with casadi.SX symbols: the RHS and its
  casadi_idas         exact Jacobian (CasADi's AD, its default) are evaluated by CasADi's SX virtual
                      machine in C++ (no Python per call; no code generation or JIT); CasADi's default
                      linear solver (csparse, sparse direct) and Newton scheme ("direct"); same rtol and
                      scalar abstol. "idas" is the same ODE handed to IDAS in implicit form. The integrator
                      is built once outside the timing loop; only the call I(x0=..., p=...) is timed.
  plantwide           `cargo bench --bench dynamics -- --repeats N` from the repository root (median of N
                      runs inside the bench; exact Jacobians by dual numbers); --no-plantwide skips it,
                      --plantwide-json '<json line>' passes its last line in instead. Its line also
                      carries ("ode") plantwide's BDF on this script's 82-state ODE written in Rust
                      (benches/column_a_ode.rs), the integrator without the plant's DAE formulation.

Equal work: plantwide's scenario records a row every 2 min (1001 rows, t = 0 ... 2000 min), so every peer
is timed producing its trajectory at the same 1001 times (SciPy t_eval, CVODE's tspan, CasADi's output grid;
each interpolates its BDF polynomial there, as plantwide does): "wall_s" and the ratios. The same with the
final state alone (no output grid; plantwide's scenario recording only its end) is reported beside it as
"final_only_wall_s" and "ratios_final_only".

Rounds: the peers are timed in turn, plantwide then SciPy, CVODE and CasADi, and that round is repeated
(--rounds, default 5). A shared machine's speed drifts by a factor of 2-3 over seconds (seen on this
2-core VM: the same binary's run took 2.2 ms, then 5.8 ms, then 2.3 ms), so a ratio is taken inside a
round, between peers timed seconds apart, and the figure reported ("ratios", "ratios_final_only") is
the median of the rounds' ratios, each round's listed beside it ("ratios_by_round"). A peer's times in
the JSON are the medians over the rounds of its per-round medians ("wall_s_by_round" beside them);
its counters are the last round's. Compare ratios, not absolute times across runs.

Pairs (--pairs, default 41; 0 skips them): plantwide's bench is started once, kept running
(`cargo bench --bench dynamics -- --serve`), and each peer's run is paired with one plantwide run,
milliseconds apart, the order alternating from pair to pair; both processes are pinned to one CPU,
because each vCPU of this VM has speed phases of its own (seen: plantwide's run 0.96 -> 1.70 ms while
CVODE's on the other vCPU stayed at 10.5 ms). A ratio ("paired": "ratios", "ratios_final_only") is the
median over the pairs of the pair's ratio, with its quartiles, min and max: on one CPU the quartiles of
CVODE's ratio span ~10 % where the rounds' ratios spread from 5 to 14.

Usage (virtual environment outside the repository):
  python3 -m venv /work/venv-bench && /work/venv-bench/bin/pip install numpy scipy casadi scikit-sundae
  /work/venv-bench/bin/python tools/bench_dynamics_peers.py [--no-plantwide | --plantwide-json '<json>']
                                                           [--repeats N] [--plantwide-repeats M] [--rounds R]
                                                           [--pairs K]
--repeats N (default 21) is the number of timed runs of SciPy and CVODE in a round; CasADi gets 3 N (it
is fast); --plantwide-repeats M (default 15) plantwide's in its bench.
numpy and scipy are required; a peer whose package (scikit-sundae, casadi) is missing is skipped with a
note in the JSON. Prints one line per peer, then one JSON line.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.dont_write_bytecode = True  # importing bench_bdf_scipy must leave no __pycache__ in the repository
sys.path.insert(0, str(Path(__file__).resolve().parent))
try:
    import numpy as np
    import scipy
    from scipy.integrate import solve_ivp

    import bench_bdf_scipy as model
except ImportError as e:
    sys.exit(f"bench_dynamics_peers.py: missing required package '{e.name}' (numpy and scipy are required); "
             "install with /work/venv-bench/bin/pip install numpy scipy casadi scikit-sundae")

N = model.N
FEED_STEP = 1.01 * model.KMOL_MIN  # mol/s
T_END = 2000.0 * 60.0  # s
RTOL = 1e-6
ATOL = 1e-8 * model.M0  # mol
GRID = np.linspace(0.0, T_END, 1001)  # plantwide's recorded times: every 2 min
PEERS = ("plantwide", "scipy_bdf", "cvode_python", "cvode_python_dense", "casadi_cvodes", "casadi_idas")
XB_REF, YD_REF = 0.0171621032, 0.9924946428  # plantwide's final values from the bench


def ends(n):
    """(xB, yD): light-component fractions of the reboiler (stage 0) and the condenser (stage N-1)."""
    n = np.asarray(n, dtype=float).reshape(N, 2)
    x = n[:, 0] / n.sum(axis=1)
    return float(x[0]), float(x[N - 1])


def timed(run, repeats):
    """One untimed warm-up run, then `repeats` timed runs; (median wall [s], fastest [s], last result)."""
    run()
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        out = run()
        walls.append(time.perf_counter() - start)
    return statistics.median(walls), min(walls), out


def scipy_runner(n0):
    """run(t_eval): one SciPy BDF integration of the scenario (t_eval None: the final state only)."""
    pattern = model.sparsity()

    def run(t_eval):
        sol = solve_ivp(model.rhs, (0.0, T_END), n0, method="BDF", rtol=RTOL, atol=ATOL, args=(FEED_STEP,),
                        jac_sparsity=pattern, t_eval=t_eval)
        assert sol.success, sol.message
        assert t_eval is None or len(sol.t) == len(GRID)
        return sol

    return run


def run_scipy(n0, repeats):
    run = scipy_runner(n0)
    final_only, _, final = timed(lambda: run(None), repeats)
    wall, fastest, sol = timed(lambda: run(GRID), repeats)
    xb, yd = ends(sol.y[:, -1])
    return {"wall_s": wall, "min_s": fastest, "final_only_wall_s": final_only, "steps": len(final.t) - 1, "rhs_evals": int(sol.nfev),
            "jacobian_evals": int(sol.njev), "lu": int(sol.nlu), "xB": xb, "yD": yd, "repeats": repeats,
            "config": "solve_ivp BDF, Python RHS, FD Jacobian on jac_sparsity, SuperLU"}


def cvode_runner(n0, linsolver):
    """(run(tspan), f): one CVODE integration returning (solution, RHS calls), and the counted RHS."""
    from sksundae.cvode import CVODE

    calls = [0]

    def f(_t, y, yp):
        calls[0] += 1
        yp[:] = model.rhs(_t, y, FEED_STEP)

    band = {"lband": 3, "uband": 3} if linsolver == "band" else {}
    solver = CVODE(f, method="BDF", rtol=RTOL, atol=ATOL, linsolver=linsolver, max_num_steps=100000, **band)

    def run(tspan):
        calls[0] = 0
        sol = solver.solve(tspan, n0)
        assert sol.success, sol.message
        return sol, calls[0]

    return run, f


def run_cvode(n0, repeats, linsolver):
    run, f = cvode_runner(n0, linsolver)
    # a two-point tspan returns every internal step: its length counts them
    final_only, _, (final, _) = timed(lambda: run(np.array([0.0, T_END])), repeats)
    wall, fastest, (sol, ncalls) = timed(lambda: run(GRID), repeats)
    # time per Python RHS call, measured on its own
    yp = np.empty(2 * N)
    reps = 2000
    start = time.perf_counter()
    for _ in range(reps):
        f(0.0, n0, yp)
    per_call = (time.perf_counter() - start) / reps
    xb, yd = ends(sol.y[-1])
    return {"wall_s": wall, "min_s": fastest, "final_only_wall_s": final_only, "rhs_s": ncalls * per_call, "rhs_fraction": ncalls * per_call / wall,
            "rhs_call_s": per_call, "steps": len(final.t) - 1, "rhs_calls": ncalls, "rhs_evals_nfe": int(sol.nfev),
            "jacobian_evals": int(sol.njev), "xB": xb, "yD": yd, "repeats": repeats,
            "config": f"CVODE BDF, Python RHS, {linsolver} linear solver, internal {linsolver} DQ Jacobian"}


def rhs_sx(ca, n, feed):
    """model.rhs written with CasADi symbols, term by term (checked against model.rhs below)."""
    m = [n[2 * i] + n[2 * i + 1] for i in range(N)]
    x = [n[2 * i] / m[i] for i in range(N)]
    y = [model.ALPHA * x[i] / (1.0 + (model.ALPHA - 1.0) * x[i]) for i in range(N)]
    d = 0.5 * model.KMOL_MIN + model.KC * (m[N - 1] - model.M0)
    b = 0.5 * model.KMOL_MIN + model.KC * (m[0] - model.M0)
    liq = [model.L0[i] + (m[i] - model.M0) / model.TAU_L for i in range(N)]
    liq[N - 1] = model.L_NOM
    liq[0] = b
    vap = [model.V_NOM] * N
    vap[N - 1] = 0.0
    xs = [(x[i], 1.0 - x[i]) for i in range(N)]
    ys = [(y[i], 1.0 - y[i]) for i in range(N)]
    out = []
    for i in range(N):
        for c in range(2):
            r = -liq[i] * xs[i][c] - vap[i] * ys[i][c]
            if i < N - 1:
                r = r + liq[i + 1] * xs[i + 1][c]
            if i > 0:
                r = r + vap[i - 1] * ys[i - 1][c]
            if i == model.FEED:
                r = r + feed * 0.5
            if i == N - 1:
                r = r - d * xs[i][c]
            out.append(r)
    return ca.vertcat(*out)


def casadi_model(n0):
    import casadi as ca

    n = ca.SX.sym("n", 2 * N)
    feed = ca.SX.sym("F")
    ode = rhs_sx(ca, n, feed)
    f = ca.Function("f", [n, feed], [ode])
    # the SX RHS must be the numpy RHS: at the initial state and at perturbed states
    rng = np.random.default_rng(1)
    diff = 0.0
    for state in [n0] + [n0 * (1.0 + 0.05 * rng.standard_normal(2 * N)) for _ in range(3)]:
        ref = model.rhs(0.0, state, FEED_STEP)
        got = np.array(f(state, FEED_STEP)).ravel()
        diff = max(diff, float(np.max(np.abs(got - ref)) / np.max(np.abs(ref))))
    return ca, {"x": n, "p": feed, "ode": ode}, f, diff


def casadi_runners(ca, dae, n0, plugin):
    """(final(), grid(), the grid integrator): CasADi integrations of the final state alone and of
    the trajectory on the output grid after t0 (x0 is the row at t = 0: plantwide's 1000 later times)."""
    opts = {"abstol": ATOL, "reltol": RTOL, "max_num_steps": 100000}
    final = ca.integrator("F", plugin, dae, 0.0, T_END, opts)
    integ = ca.integrator("F", plugin, dae, 0.0, GRID[1:], opts)
    return (lambda: final(x0=n0, p=FEED_STEP)), (lambda: integ(x0=n0, p=FEED_STEP)), integ


def run_casadi(ca, dae, n0, repeats, plugin):
    final, run, integ = casadi_runners(ca, dae, n0, plugin)
    final_only, _, _ = timed(final, repeats)
    wall, fastest, res = timed(run, repeats)
    st = integ.stats()
    xf = np.array(res["xf"])
    assert xf.shape == (2 * N, len(GRID) - 1), xf.shape
    xb, yd = ends(xf[:, -1])
    return {"wall_s": wall, "min_s": fastest, "final_only_wall_s": final_only, "steps": int(st["nsteps"]), "rhs_evals": int(st["nfevals"]),
            "jacobian_evals": int(st["n_call_jacF"]), "lu": int(st["nlinsetups"]), "newton_iters": int(st["nniters"]),
            "error_test_failures": int(st["netfails"]), "xB": xb, "yD": yd, "repeats": repeats,
            "config": f"CasADi {ca.__version__} {plugin}, SX RHS, AD Jacobian, csparse"}


def run_plantwide(root, repeats):
    cmd = ["cargo", "bench", "--bench", "dynamics", "--", "--repeats", str(repeats)]
    out = subprocess.run(cmd, cwd=root, capture_output=True, text=True)
    lines = [line for line in out.stdout.splitlines() if line.startswith('{"wall_s":')]
    if out.returncode != 0 or not lines:
        tail = "\n".join(out.stderr.splitlines()[-10:])
        raise RuntimeError(f"cargo bench --bench dynamics failed (exit {out.returncode}):\n{tail}")
    return json.loads(lines[-1])


class PlantwideServer:
    """`cargo bench --bench dynamics -- --serve`, kept running: run(kind) is one run of the scenario
    ("recorded" or "final"), its wall time as timed inside the bench (seconds), its final xB checked."""

    def __init__(self, root, cpu):
        """Started on CPU `cpu` alone: cargo and the bench it spawns inherit the affinity."""
        cmd = ["cargo", "bench", "--bench", "dynamics", "--", "--serve"]
        self.proc = subprocess.Popen(cmd, cwd=root, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1,
                                     preexec_fn=lambda: os.sched_setaffinity(0, {cpu}))

    def run(self, kind):
        self.proc.stdin.write(kind + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError(f"cargo bench --bench dynamics -- --serve ended (exit {self.proc.wait()})")
        out = json.loads(line)
        assert abs(out["xB"] / XB_REF - 1.0) < 1e-6, out
        return out["wall_s"]

    def close(self):
        self.proc.stdin.close()
        self.proc.wait()


def wall_of(run):
    start = time.perf_counter()
    run()
    return time.perf_counter() - start


def peer_runs(n0, casadi):
    """{peer: (one run on the 1001-point grid, one run to the final state only)}, each a callable."""
    scipy_run = scipy_runner(n0)
    peers = {"scipy_bdf": (lambda: scipy_run(GRID), lambda: scipy_run(None))}
    try:
        for key, ls in (("cvode_python", "band"), ("cvode_python_dense", "dense")):
            cvode_run = cvode_runner(n0, ls)[0]
            peers[key] = ((lambda r=cvode_run: r(GRID)), (lambda r=cvode_run: r(np.array([0.0, T_END]))))
    except ImportError:
        pass
    if casadi is not None:
        ca, dae = casadi
        for key, plugin in (("casadi_cvodes", "cvodes"), ("casadi_idas", "idas")):
            final, grid, _ = casadi_runners(ca, dae, n0, plugin)
            peers[key] = (grid, final)
    return peers


def quartiles(values):
    q = statistics.quantiles(values, n=4)
    return {"median": statistics.median(values), "q1": q[0], "q3": q[2], "min": min(values), "max": max(values)}


def measure_paired(root, n0, casadi, pairs):
    """Ratios from pairs of runs: one plantwide run (in its kept-running bench) next to one run of
    the peer, milliseconds apart, the order alternating from pair to pair; each ratio is the median
    over the pairs of the pair's ratio (quartiles beside it). Both sides of a pair see the same phase
    of the machine's speed, which the rounds' ratios (peers timed seconds apart) do not."""
    out, spread = {}, {}
    # Both processes on one CPU: a vCPU of this VM has speed phases of its own (seen: plantwide's
    # run 0.96 -> 1.70 ms while CVODE's on the other vCPU stayed at 10.5 ms, and the reverse), so
    # a pair is in one phase only if both of its runs are on the same CPU.
    saved = os.sched_getaffinity(0)
    cpu = min(saved)
    server = PlantwideServer(root, cpu)
    os.sched_setaffinity(0, {cpu})
    try:
        for key, runs in peer_runs(n0, casadi).items():
            casadi_peer = key.startswith("casadi")
            name = f"plantwide/{key}" if casadi_peer else f"{key}/plantwide"
            for kind, run, target in (("recorded", runs[0], out), ("final", runs[1], spread)):
                server.run(kind)
                run()  # one untimed run of each side
                ratios = []
                for i in range(pairs):
                    if i % 2 == 0:
                        pw = server.run(kind)
                        peer = wall_of(run)
                    else:
                        peer = wall_of(run)
                        pw = server.run(kind)
                    ratios.append(pw / peer if casadi_peer else peer / pw)
                target[name] = quartiles(ratios)
    finally:
        server.close()
        os.sched_setaffinity(0, saved)
    return {"cpu": cpu, "pairs": pairs, "ratios": out, "ratios_final_only": spread}


def measure_round(args, root, n0, casadi):
    """One round: plantwide's bench, then every Python peer; {peer: its figures}."""
    out = {}
    if args.plantwide_json:
        out["plantwide"] = json.loads(args.plantwide_json)
    elif args.no_plantwide:
        out["plantwide"] = {"skipped": "--no-plantwide"}
    else:
        try:
            out["plantwide"] = run_plantwide(root, args.plantwide_repeats)
        except RuntimeError as e:
            out["plantwide"] = {"error": str(e).splitlines()[0]}
            print(e, file=sys.stderr)
    out["scipy_bdf"] = run_scipy(n0, args.repeats)
    try:
        import sksundae  # noqa: F401
        for key, ls in (("cvode_python", "band"), ("cvode_python_dense", "dense")):
            out[key] = run_cvode(n0, args.repeats, ls)
    except ImportError:
        out["cvode_python"] = {"skipped": "scikit-sundae not installed"}
    if casadi is None:
        out["casadi_cvodes"] = out["casadi_idas"] = {"skipped": "casadi not installed"}
    else:
        ca, dae = casadi
        for key, plugin in (("casadi_cvodes", "cvodes"), ("casadi_idas", "idas")):
            out[key] = run_casadi(ca, dae, n0, 3 * args.repeats, plugin)
    return out


def round_ratios(r):
    """Wall-time ratios of one round: every peer's trajectory at the 1001 recorded times against
    plantwide's recorded run, then the final state alone on both sides (plantwide's ODE run records
    nothing, so it is compared there). Peers slower than plantwide as peer/plantwide, CasADi as
    plantwide/CasADi."""
    pw = r.get("plantwide", {})
    pw_final, ode = pw.get("final_only", {}), pw.get("ode", {})
    ratios, final_ratios = {}, {}
    for k in ("scipy_bdf", "cvode_python", "cvode_python_dense", "casadi_cvodes", "casadi_idas"):
        peer = r.get(k, {})
        if "wall_s" not in peer:
            continue
        casadi = k.startswith("casadi")
        if "wall_s" in pw:
            ratios[f"plantwide/{k}" if casadi else f"{k}/plantwide"] = (
                pw["wall_s"] / peer["wall_s"] if casadi else peer["wall_s"] / pw["wall_s"])
        if "wall_s" in pw_final:
            final_ratios[f"plantwide/{k}" if casadi else f"{k}/plantwide"] = (
                pw_final["wall_s"] / peer["final_only_wall_s"] if casadi
                else peer["final_only_wall_s"] / pw_final["wall_s"])
        if casadi and "wall_s" in ode:
            final_ratios[f"plantwide_ode/{k}"] = ode["wall_s"] / peer["final_only_wall_s"]
    return ratios, final_ratios


def median_of(dicts):
    """{key: median over the dicts that have it}."""
    keys = [k for k in dicts[0]] if dicts else []
    return {k: statistics.median(d[k] for d in dicts if k in d) for k in keys}


def merge_rounds(rounds):
    """Each peer's figures from the last round, its times replaced by their medians over the rounds
    (the per-round medians listed beside them)."""
    merged = {}
    for k, last in rounds[-1].items():
        entry = dict(last)
        for key in ("wall_s", "final_only_wall_s"):
            walls = [r[k][key] for r in rounds if key in r.get(k, {})]
            if walls:
                entry[key], entry[f"{key}_by_round"] = statistics.median(walls), walls
        if k == "plantwide" and "final_only" in last:
            walls = [r[k]["final_only"]["wall_s"] for r in rounds if "final_only" in r.get(k, {})]
            entry["final_only"] = {"wall_s": statistics.median(walls), "wall_s_by_round": walls}
        merged[k] = entry
    return merged


def describe(result, rounds):
    """The human-readable lines: each peer's figures (times: medians over the rounds)."""
    pw, ode = result["plantwide"], result["plantwide"].get("ode", {})
    if "wall_s" in pw:
        final_ms = pw.get("final_only", {}).get("wall_s", float("nan")) * 1e3
        print(f"plantwide BDF: {pw['wall_s'] * 1e3:.2f} ms recording every 2 min, "
              f"{final_ms:.2f} ms recording the end only, {pw['steps']} steps, "
              f"{pw['residual_evals']} residual evaluations, {pw['jacobian_evals']} exact Jacobians, {pw['lu']} LU; "
              f"xB = {pw['xB']:.10f}, yD = {pw['yD']:.10f}")
    else:
        print(f"plantwide: {pw}")
    if "wall_s" in ode:
        print(f"plantwide BDF on this script's 82-state ODE (benches/column_a_ode.rs, hand-derived Jacobian; the "
              f"integrator without the plant DAE): {ode['wall_s'] * 1e3:.2f} ms, {ode['steps']} steps, "
              f"{ode['residual_evals']} RHS evaluations, {ode['lu']} LU; xB = {ode['xB']:.10f}")
    s = result["scipy_bdf"]
    print(f"SciPy BDF: {s['wall_s'] * 1e3:.2f} ms on the grid, "
          f"{s['final_only_wall_s'] * 1e3:.2f} ms final only, {s['steps']} steps, {s['rhs_evals']} RHS "
          f"evaluations (incl. FD Jacobians), {s['jacobian_evals']} Jacobians, {s['lu']} LU; "
          f"xB = {s['xB']:.10f}, yD = {s['yD']:.10f}")
    for key in ("cvode_python", "cvode_python_dense"):
        c = result.get(key, {})
        if "wall_s" in c:
            print(f"CVODE ({c['config']}): {c['wall_s'] * 1e3:.2f} ms on the grid, "
                  f"{c['final_only_wall_s'] * 1e3:.2f} ms final only, "
                  f"{c['steps']} steps, {c['rhs_calls']} Python RHS calls "
                  f"({c['rhs_evals_nfe']} + DQ Jacobians), {c['jacobian_evals']} Jacobians; Python RHS "
                  f"{c['rhs_calls']} x {c['rhs_call_s'] * 1e6:.1f} us = {c['rhs_s'] * 1e3:.2f} ms "
                  f"({100 * c['rhs_fraction']:.0f} %); xB = {c['xB']:.10f}, yD = {c['yD']:.10f}")
    for key in ("casadi_cvodes", "casadi_idas"):
        c = result.get(key, {})
        if "wall_s" in c:
            print(f"{c['config']}: {c['wall_s'] * 1e3:.2f} ms on the grid, "
                  f"{c['final_only_wall_s'] * 1e3:.2f} ms final only, {c['steps']} steps, "
                  f"{c['rhs_evals']} RHS evaluations, {c['jacobian_evals']} AD Jacobians, {c['lu']} LU setups, "
                  f"{c['error_test_failures']} error-test failures; xB = {c['xB']:.10f}, yD = {c['yD']:.10f}")
    print(f"times above: medians over {len(rounds)} round(s) of each round's median")


def agreement_of(result):
    """The final xB, yD of every peer against plantwide's (or the reference values)."""
    peers = [k for k in PEERS if "xB" in result.get(k, {})]
    ref_name = "plantwide" if "plantwide" in peers else "reference (plantwide's earlier bench)"
    ref = result["plantwide"] if "plantwide" in peers else {"xB": XB_REF, "yD": YD_REF}
    agreement = {"against": ref_name}
    for k in peers:
        if k != "plantwide":
            agreement[k] = {"xB_rel": abs(result[k]["xB"] / ref["xB"] - 1.0),
                            "yD_rel": abs(result[k]["yD"] / ref["yD"] - 1.0)}
    agreement["max_rel"] = max([max(v["xB_rel"], v["yD_rel"]) for k, v in agreement.items() if isinstance(v, dict)],
                               default=0.0)
    print(f"final values against {ref_name}: largest relative difference {agreement['max_rel']:.1e} "
          f"({'within' if agreement['max_rel'] < 1e-6 else 'OUTSIDE'} 1e-6); "
          + ", ".join(f"{k} xB {v['xB_rel']:.1e} yD {v['yD_rel']:.1e}" for k, v in agreement.items()
                      if isinstance(v, dict)))
    return agreement


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-plantwide", action="store_true", help="skip `cargo bench --bench dynamics`")
    ap.add_argument("--plantwide-json", metavar="JSON", help="the bench's last line, instead of running it")
    ap.add_argument("--repeats", type=int, default=21, help="timed runs for SciPy and CVODE (CasADi: 3x)")
    ap.add_argument("--plantwide-repeats", type=int, default=15, help="timed runs of plantwide in its bench")
    ap.add_argument("--rounds", type=int, default=5, help="rounds of every peer in turn (ratios: their median)")
    ap.add_argument("--pairs", type=int, default=41,
                    help="pairs of one plantwide run and one peer run, per peer and recording (0: none)")
    args = ap.parse_args()
    root = Path(__file__).resolve().parent.parent
    result = {"model": "column_a_feed_step_2000min", "rtol": RTOL, "atol": 1e-8}

    n0 = model.steady_state()
    xb0, yd0 = ends(n0)
    res0 = float(np.max(np.abs(model.rhs(0.0, n0, model.F_NOM))))
    print(f"Python peers: numpy {np.__version__}, SciPy {scipy.__version__}; initial steady state at F = 1 "
          f"kmol/min (fsolve): xB = {xb0:.10f}, yD = {yd0:.10f}, max |dn/dt| = {res0:.1e} mol/s")
    result["initial"] = {"xB": xb0, "yD": yd0, "max_abs_rhs_mol_s": res0, "xB_minus_0.01": xb0 - 0.01,
                         "yD_minus_0.99": yd0 - 0.99,
                         "note": "one array for all Python peers; plantwide converges its own (yD 0.99, xB 0.01)"}
    try:
        ca, dae, _, sx_diff = casadi_model(n0)
        casadi = (ca, dae)
        result["casadi_rhs_vs_numpy_max_rel_diff"] = sx_diff
        print(f"CasADi {ca.__version__}: SX RHS against numpy RHS, max relative difference {sx_diff:.1e}")
    except ImportError:
        casadi = None

    rounds, by_round = [], []
    for k in range(max(1, args.rounds)):
        rounds.append(measure_round(args, root, n0, casadi))
        by_round.append(round_ratios(rounds[-1]))
        print(f"round {k + 1}: " + ", ".join(f"{name} {v:.2f}" for name, v in by_round[-1][0].items())
              + "; final only: " + ", ".join(f"{name} {v:.2f}" for name, v in by_round[-1][1].items()))
    result.update(merge_rounds(rounds))
    describe(result, rounds)
    result["agreement"] = agreement_of(result)
    result["rounds"] = len(rounds)
    result["ratios"] = median_of([r for r, _ in by_round])
    result["ratios_final_only"] = median_of([f for _, f in by_round])
    result["ratios_by_round"] = [r for r, _ in by_round]
    result["ratios_final_only_by_round"] = [f for _, f in by_round]
    if result["ratios"]:
        print("wall-time ratios, equal work (1001-point trajectories), median of the rounds' ratios: "
              + ", ".join(f"{k} {v:.2f}" for k, v in result["ratios"].items()))
    if result["ratios_final_only"]:
        print("wall-time ratios, final state only, median of the rounds' ratios: "
              + ", ".join(f"{k} {v:.2f}" for k, v in result["ratios_final_only"].items()))
    if args.pairs > 0 and not (args.no_plantwide or args.plantwide_json):
        result["paired"] = measure_paired(root, n0, casadi, max(2, args.pairs))
        for key, label in (("ratios", "1001-point trajectories"), ("ratios_final_only", "final state only")):
            print(f"wall-time ratios in {result['paired']['pairs']} alternating pairs, {label}, median [quartiles]: "
                  + ", ".join(f"{k} {v['median']:.2f} [{v['q1']:.2f}, {v['q3']:.2f}]"
                              for k, v in result["paired"][key].items()))
    print(json.dumps(result))


if __name__ == "__main__":
    main()
