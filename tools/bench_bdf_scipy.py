#!/usr/bin/env python3
"""Column A feed step: SciPy's BDF against plantwide's, on the same model and scenario.

Model (validation-cases.md section 1; crates/model/src/units/column/simple.rs): 41 stages
(0 = reboiler, 40 = condenser, feed on 20), binary, alpha = 1.5, constant molar overflow, states
the component holdups n[i, c] [mol]; L_i = L0_i + (M_i - M0)/tau_L on the trays, L = reflux
from the condenser, L = B from the reboiler, V = boilup below the condenser;
D = 0.5 + 10 (M_41 - 0.5), B = 0.5 + 10 (M_1 - 0.5) [kmol/min, kmol]. Scenario
(flowsheets/scenarios/column_a_feed_step.json): F 1 -> 1.01 kmol/min at t = 0, 2000 min, from the
steady state at F = 1; rtol 1e-6 and atol 1e-8 x nominal (0.5 kmol per component holdup, as
plantwide's nominal values). SI units throughout (mol, s).

SciPy gets the exact sparsity pattern of the Jacobian (block tridiagonal plus the level loops) and
estimates it by grouped finite differences (those evaluations are in its nfev); plantwide
evaluates exact Jacobians by dual numbers (counted separately).

Usage: python3 tools/bench_bdf_scipy.py [--no-plantwide]
Runs `cargo bench --bench dynamics` for plantwide's figures unless --no-plantwide.
"""

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import scipy
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve
from scipy.sparse import lil_matrix

KMOL_MIN = 1000.0 / 60.0  # mol/s per kmol/min
N = 41
FEED = 20
ALPHA = 1.5
M0 = 500.0  # mol
TAU_L = 0.063 * 60.0  # s
L_NOM = 2.70629 * KMOL_MIN
V_NOM = 3.20629 * KMOL_MIN
F_NOM = 1.0 * KMOL_MIN
KC = 10.0 / 60.0  # (mol/s)/mol  = 10 (kmol/min)/kmol
L0 = np.array([L_NOM + (F_NOM if i <= FEED else 0.0) for i in range(N)])


def rhs(_t, n, feed):
    n = n.reshape(N, 2)
    m = n.sum(axis=1)
    x = n[:, 0] / m
    y = ALPHA * x / (1.0 + (ALPHA - 1.0) * x)
    d = 0.5 * KMOL_MIN + KC * (m[N - 1] - M0)
    b = 0.5 * KMOL_MIN + KC * (m[0] - M0)
    liq = L0 + (m - M0) / TAU_L
    liq[N - 1] = L_NOM
    liq[0] = b
    vap = np.full(N, V_NOM)
    vap[N - 1] = 0.0
    xs = np.stack([x, 1.0 - x], axis=1)
    ys = np.stack([y, 1.0 - y], axis=1)
    dn = -liq[:, None] * xs - vap[:, None] * ys
    dn[:-1] += liq[1:, None] * xs[1:]
    dn[1:] += vap[:-1, None] * ys[:-1]
    dn[FEED] += feed * np.array([0.5, 0.5])
    dn[N - 1] -= d * xs[N - 1]
    return dn.ravel()


def sparsity():
    s = lil_matrix((2 * N, 2 * N))
    for i in range(N):
        for j in range(max(0, i - 1), min(N, i + 2)):
            s[2 * i:2 * i + 2, 2 * j:2 * j + 2] = 1
    return s.tocsr()


def steady_state():
    x = np.linspace(0.01, 0.99, N)
    guess = np.stack([M0 * x, M0 * (1 - x)], axis=1).ravel()
    sol, info, ok, msg = fsolve(lambda n: rhs(0.0, n, F_NOM), guess, xtol=1e-13, full_output=True)
    assert ok == 1, msg
    return sol


def run_scipy(n0):
    t_end = 2000.0 * 60.0
    atol = 1e-8 * M0
    best = None
    for _ in range(3):
        start = time.perf_counter()
        sol = solve_ivp(rhs, (0.0, t_end), n0, method="BDF", rtol=1e-6, atol=atol, args=(1.01 * KMOL_MIN,),
                        jac_sparsity=sparsity())
        wall = time.perf_counter() - start
        assert sol.success, sol.message
        if best is None or wall < best[0]:
            best = (wall, sol)
    wall, sol = best
    n_end = sol.y[:, -1].reshape(N, 2)
    x = n_end[:, 0] / n_end.sum(axis=1)
    return {"wall_s": wall, "steps": len(sol.t) - 1, "nfev": sol.nfev, "njev": sol.njev, "nlu": sol.nlu,
            "xB": x[0], "yD": x[N - 1]}


def run_plantwide(root):
    out = subprocess.run(["cargo", "bench", "--bench", "dynamics"], cwd=root, capture_output=True, text=True, check=True)
    line = [l for l in out.stdout.splitlines() if l.startswith("{")][-1]
    return json.loads(line)


def main():
    root = Path(__file__).resolve().parent.parent
    n0 = steady_state()
    x0 = n0.reshape(N, 2)[:, 0] / n0.reshape(N, 2).sum(axis=1)
    print(f"SciPy {scipy.__version__}: steady state at F = 1 kmol/min: xB = {x0[0]:.9f}, yD = {x0[N - 1]:.9f}")
    s = run_scipy(n0)
    print(f"SciPy BDF (best of 3): {s['wall_s'] * 1e3:.1f} ms, {s['steps']} steps, {s['nfev']} RHS evaluations "
          f"(incl. finite-difference Jacobians), {s['njev']} Jacobians, {s['nlu']} LU; "
          f"xB = {s['xB']:.9f}, yD = {s['yD']:.9f}")
    if "--no-plantwide" in sys.argv:
        return
    p = run_plantwide(root)
    print(f"plantwide BDF (median of 15): {p['wall_s'] * 1e3:.1f} ms, {p['steps']} steps, {p['residual_evals']} residual "
          f"evaluations, {p['jacobian_evals']} exact Jacobians, {p['lu']} LU; xB = {p['xB']:.9f}, yD = {p['yD']:.9f}")
    print(f"wall-time ratio SciPy / plantwide: {s['wall_s'] / p['wall_s']:.1f}")
    print(f"final xB difference {abs(s['xB'] - p['xB']):.1e}, yD difference {abs(s['yD'] - p['yD']):.1e}")


if __name__ == "__main__":
    main()
