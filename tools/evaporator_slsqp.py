#!/usr/bin/env python3
"""Newell-Lee evaporator, economic optimum with all its constraints free: an independent SciPy
SLSQP reference for `plantwide optimize` (written to tests/data/evaporator/slsqp.json).

Written from the published model, not from the flowsheet file nor from tools/evaporator_scipy.py
(nothing is imported from it): Newell & Lee (1989), "Applied Process Control - A Case Study",
Prentice Hall, ch. 2 (the evaporator model and its constants), with the economic operating region
of Kariwala, Cao & Janardhanan (2008), "Local self-optimizing control with average loss
minimization", Ind. Eng. Chem. Res. 47, 1150-1158 (the cost J, the constraints 40 <= P2 <= 80 kPa,
F3 <= 100 kg/min, X2 >= 35.5 %, P100 <= 400 kPa, and the bounds F1 <= 20, F200 <= 400 kg/min).
As in tools/evaporator_scipy.py, the equations and constants were read from public restatements
of the Newell-Lee model, which agree with one another to every digit.

Units are the paper's: flows kg/min, compositions %, pressures kPa, temperatures degC, duties kW,
cost $/h. Decision variables v = (F1, F200, P100, X2): four steady-state degrees of freedom (X2 is
the setpoint of the composition loop; the level L2 has no steady-state effect). With the
disturbances d = (X1, T1, T200) = (5 %, 40 degC, 25 degC), the steady state is explicit in v:
  F2   = F1 X1 / X2                                   (eq. 2 at steady state)
  F4   = F1 - F2,  F5 = F4,  Q200 = 38.5 F5           (eqs. 1, 3, 12)
  T3   = T200 + Q200 (1 + UA2/(2 Cp F200)) / UA2      (eq. 10; UA2 = 6.84 kW/K, Cp = 0.07)
  P2   = (T3 - 55) / 0.507                            (eq. 5)
  T2   = 0.5616 P2 + 0.3126 X2 + 48.43                (eq. 4)
  T100 = 0.1538 P100 + 90                             (eq. 7)
  Q100 = 38.5 F4 + 0.07 F1 (T2 - T1)                  (eq. 6)
  F3   = Q100 / (0.16 (T100 - T2)) - F1               (eq. 8)
  F100 = Q100 / 36.6                                  (eq. 9)
  T201 = T200 + Q200 / (F200 Cp)                      (eq. 11)
  J    = 600 F100 + 0.6 F200 + 1.009 (F2 + F3) + 0.2 F1 - 4800 F2   [$/h], minimised.

What the script computes:
(a) the optimum by scipy.optimize.minimize(method="SLSQP") from several starting points, with
    exact (complex-step) gradients of J and of the constraints; the Kariwala constraints on P2, F3,
    X2 and P100 are general inequality constraints (so SLSQP reports their multipliers), the flow
    limits are bounds, and X2 <= 50 %, P100 >= 100 kPa are loose bounds of ours that keep SLSQP in
    the model's domain (asserted inactive);
(b) the optimum polished on the two unconstrained variables (F1, F200) at the active limits by
    solving grad J = 0 (complex step) with scipy.optimize.root, exact to rounding; every SLSQP run
    must agree with it to 1e-6 relative, and with tests/data/evaporator/scipy.json to 1e-7;
(c) the shadow prices dJ*/d(limit) of the two active constraints, by the envelope theorem
    (partial derivative of J at the optimum with F1, F200 held, complex step) and by central
    differences of the polished re-optimum at limit +- h, h = 1e-3 of the limit (truncation error
    O(h^2): 7e-6 relative for X2, so it is checked to 1e-4) and their Richardson extrapolation
    with h/2 (checked to 1e-6), plus SLSQP's own KKT multipliers;
(d) the reduced Hessian Juu of J in (F1, F200) at the active limits (Kariwala et al. 2008), by
    central differences (relative steps 1e-3 and 5e-4) of the complex-step gradient, Richardson-
    extrapolated (error O(h^4), checked against the extrapolation at half the steps to 1e-9), and its
    eigenvalues;
(e) the local model of self-optimizing control at the optimum with X2 = 35.5 %, P100 = 400 kPa held
    (Halvorsen et al. 2003; Kariwala et al. 2008's u = (F1, F200), d = (X1, T1, T200) and ten
    candidate measurements): Gy, Gyd by complex step, Juu, Jud by Richardson-extrapolated central
    differences of the complex-step gradient (as in (d)), and, for information, the difference
    from the pySOC matrices in crates/soc/tests/data/evaporator.json;
(f) the nonlinear loss J_held - J_opt of holding each of the 45 pairs of candidates at its nominal
    optimal value when one disturbance moves by +- Wd = (0.25 %, 8 degC, 5 degC), J_opt the polished
    re-optimum at X2 = 35.5 %, P100 = 400 kPa;
(g) the optimum under a hostile extra limit, F3 <= 0.01 kg/min: the vertex of F3, P2, X2 and P100
    at their limits, by a root solve of the closed form (SLSQP stops there: "Inequality constraints
    incompatible").

Usage: python3 tools/evaporator_slsqp.py           (rewrite tests/data/evaporator/slsqp.json)
       python3 tools/evaporator_slsqp.py --check   (recompute; exit 1 unless it matches the file)
"""

import json
import sys
from pathlib import Path

import numpy as np
import scipy
from scipy.optimize import minimize, root

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "tests" / "data" / "evaporator" / "slsqp.json"
# The reduced reference (optimum over F1, F200 at the active limits): the numbers to agree with.
REDUCED = ROOT / "tests" / "data" / "evaporator" / "scipy.json"

# Newell & Lee (1989) constants.
CP = 0.07  # kW/(K kg/min), liquor heat capacity
LAM = 38.5  # kW/(kg/min), latent heat of the liquor vapour
LAM_S = 36.6  # kW/(kg/min), latent heat of the steam
UA1_PER_FLOW = 0.16  # kW/(K kg/min), evaporator UA1 = 0.16 (F1 + F3)
UA2 = 6.84  # kW/K, condenser

# Nominal disturbances (Newell & Lee 1989; Kariwala et al. 2008).
D_NOM = {"X1": 5.0, "T1": 40.0, "T200": 25.0}

VARS = ["F1", "F200", "P100", "X2"]
UNITS = {"F1": "kg/min", "F200": "kg/min", "P100": "kPa", "X2": "%"}
# Bounds: F1 <= 20, F200 <= 400 are Kariwala et al.'s; the small positive lower bounds on the flows
# and X2 <= 50, P100 >= 100 are ours (loose, to keep SLSQP where the model is defined).
BOUNDS = {"F1": (0.1, 20.0), "F200": (0.1, 400.0), "P100": (100.0, None), "X2": (None, 50.0)}
OURS = ["F1:min", "F200:min", "P100:min", "X2:max"]
# Kariwala et al. (2008) inequality constraints: (name, variable, kind, limit).
CONSTRAINTS = [
    ("evaporator.P2:min", "P2", "min", 40.0),
    ("evaporator.P2:max", "P2", "max", 80.0),
    ("evaporator.F3:max", "F3", "max", 100.0),
    ("evaporator.X2:min", "X2", "min", 35.5),
    ("evaporator.P100:max", "P100", "max", 400.0),
]
ACTIVE = {"evaporator.X2:min": ("X2", 35.5), "evaporator.P100:max": ("P100", 400.0)}
UNCONSTRAINED = ["F1", "F200"]

STARTS = [[10.0, 200.0, 300.0, 40.0], [15.0, 300.0, 350.0, 45.0], [5.0, 100.0, 150.0, 36.0]]
SLSQP_OPTIONS = {"ftol": 1e-14, "maxiter": 500}
# SLSQP works on v / SCALE and COST_SCALE * J (units of 1 kg/min, 50 kg/min, 10 kPa, 0.1 % and
# 100 $/h). Unscaled, J is ~3000 times stiffer in F1 than in F200 (Juu below) and SLSQP stops
# from these starts with "Positive directional derivative for linesearch", F200 off by up to 3e-5.
SCALE = np.array([1.0, 50.0, 10.0, 0.1])
COST_SCALE = 0.01
H_CS = 1e-30  # complex step


def model(v, d=D_NOM):
    """The steady state for v = (F1, F200, P100, X2): every variable in closed form (real or
    complex arithmetic, so that the complex step differentiates it exactly)."""
    f1, f200, p100, x2 = v
    f2 = f1 * d["X1"] / x2
    f4 = f1 - f2
    q200 = LAM * f4
    t3 = d["T200"] + q200 * (1.0 + UA2 / (2.0 * CP * f200)) / UA2
    p2 = (t3 - 55.0) / 0.507
    t2 = 0.5616 * p2 + 0.3126 * x2 + 48.43
    t100 = 0.1538 * p100 + 90.0
    q100 = LAM * f4 + CP * f1 * (t2 - d["T1"])
    f3 = q100 / (UA1_PER_FLOW * (t100 - t2)) - f1
    f100 = q100 / LAM_S
    t201 = d["T200"] + q200 / (f200 * CP)
    j = 600.0 * f100 + 0.6 * f200 + 1.009 * (f2 + f3) + 0.2 * f1 - 4800.0 * f2
    return {
        "F1": f1, "F200": f200, "P100": p100, "X2": x2, "F2": f2, "F3": f3, "F4": f4, "P2": p2,
        "T2": t2, "T3": t3, "T100": t100, "Q100": q100, "Q200": q200, "F100": f100, "T201": t201,
        "cost": j,
    }


def cs_grad(fun, v):
    """Gradient of the real scalar fun at v by the complex step (exact to rounding)."""
    v = np.asarray(v, dtype=float)
    g = np.zeros(len(v))
    for j in range(len(v)):
        z = v.astype(complex)
        z[j] += 1j * H_CS
        g[j] = np.imag(fun(z)) / H_CS
    return g


def cost(v):
    """J in $/h at v = (F1, F200, P100, X2)."""
    return model(v)["cost"]


def constraint_value(v, var, kind, limit):
    """Constraint in SLSQP's form c(v) >= 0."""
    x = model(v)[var]
    return x - limit if kind == "min" else limit - x


def slsqp_constraints():
    """The five Kariwala constraints as SLSQP inequality dicts in the scaled variables."""
    cons = []
    for _, var, kind, limit in CONSTRAINTS:
        def c(s, var=var, kind=kind, limit=limit):
            return np.real(constraint_value(s * SCALE, var, kind, limit))

        def jac(s, var=var, kind=kind, limit=limit):
            return cs_grad(lambda z: constraint_value(z, var, kind, limit), s * SCALE) * SCALE

        cons.append({"type": "ineq", "fun": c, "jac": jac})
    return cons


def run_slsqp(x0):
    """SLSQP from x0 in the scaled variables v / SCALE with the cost in units of COST_SCALE^-1 $/h;
    returns the result with x in physical units and the multipliers in $/h per constraint unit."""
    bounds = [tuple(None if b is None else b / sc for b in BOUNDS[k]) for k, sc in zip(VARS, SCALE)]
    res = minimize(lambda s: COST_SCALE * np.real(cost(s * SCALE)), np.asarray(x0) / SCALE,
                   jac=lambda s: COST_SCALE * cs_grad(cost, s * SCALE) * SCALE, method="SLSQP",
                   bounds=bounds, constraints=slsqp_constraints(), options=SLSQP_OPTIONS)
    # Where SLSQP stops from a start depends on the machine's rounding: with SciPy 1.17.1 and
    # NumPy 2.4.6 every start converged on the machine that first wrote slsqp.json (2026-12-07),
    # while on the one that rewrote it (2026-12-08) the first stops at F1 = 18.75 with "Positive
    # directional derivative for linesearch". Each start's end is recorded (`reached`); solve()
    # needs one that reaches the optimum.
    res.x = res.x * SCALE
    res.fun = res.fun / COST_SCALE
    if getattr(res, "multipliers", None) is not None:
        res.multipliers = np.asarray(res.multipliers) / COST_SCALE
    return res


def reduced(u, x2, p100, d=D_NOM):
    """J as a function of the unconstrained (F1, F200) at fixed X2, P100 and disturbances d."""
    return model([u[0], u[1], p100, x2], d)["cost"]


def polish(u0, x2=35.5, p100=400.0, d=D_NOM):
    """Solve dJ/d(F1, F200) = 0 at fixed X2, P100, d (complex-step gradient): exact to rounding."""
    def grad(u):
        return cs_grad(lambda z: reduced(z, x2, p100, d), u)

    sol = root(grad, u0, method="hybr", options={"xtol": 1e-14})
    assert np.max(np.abs(grad(sol.x))) < 1e-9, sol
    return np.array([sol.x[0], sol.x[1], p100, x2])


def rel(a, b):
    """Relative difference of a from b."""
    return abs(a - b) / abs(b)


def is_active(point, var, limit, tol=1e-7):
    """True when point[var] sits at limit (relative tolerance tol)."""
    return abs(float(np.real(point[var])) - limit) <= tol * abs(limit)


def summarize(point):
    """The recorded optimum: real floats of the named variables."""
    keys = ["F1", "F200", "P100", "X2", "F2", "F3", "P2", "F100", "T201", "cost"]
    return {k: float(np.real(point[k])) for k in keys}


def reoptimized_cost(v_opt, var, limit):
    """J* with one active limit moved to `limit`, F1 and F200 re-optimized (polished)."""
    lim = {"X2": 35.5, "P100": 400.0, var: limit}
    return float(np.real(cost(polish(v_opt[:2], x2=lim["X2"], p100=lim["P100"]))))


def shadow_prices(v_opt):
    """dJ*/d(limit) for each active limit: envelope theorem, and central differences of the
    polished re-optimum at limit +- h (h = 1e-3 of the limit, error O(h^2)) with the Richardson
    extrapolation of h and h/2 (error O(h^4))."""
    out = {}
    grad = cs_grad(cost, v_opt)
    for name, (var, limit) in ACTIVE.items():
        envelope = float(grad[VARS.index(var)])
        h = 1e-3 * limit
        cd = [(reoptimized_cost(v_opt, var, limit + s) - reoptimized_cost(v_opt, var, limit - s)) / (2.0 * s)
              for s in (h, h / 2.0)]
        richardson = (4.0 * cd[1] - cd[0]) / 3.0
        assert rel(cd[0], envelope) < 1e-4, (name, envelope, cd[0])
        assert rel(richardson, envelope) < 1e-6, (name, envelope, richardson)
        unit = "$/h per %" if var == "X2" else "$/h per kPa"
        out[name] = {"unit": unit, "envelope": envelope, "step": h, "central_difference": cd[0],
                     "central_difference_half_step": cd[1], "richardson": richardson,
                     "relative_difference": {"central_difference": rel(cd[0], envelope),
                                             "richardson": rel(richardson, envelope)}}
    return out


def richardson(central, h):
    """Central differences at steps h and h/2 combined to cancel the h^2 term: error O(h^4) (1e-12 of
    the value at h = 1e-3 of the variable), rounding ~1e-16/h; and the same at h/2 and h/4, whose
    difference from it estimates its error."""
    d1, d2, d4 = central(h), central(h / 2.0), central(h / 4.0)
    return (4.0 * d2 - d1) / 3.0, (4.0 * d4 - d2) / 3.0


def reduced_hessian(v_opt, rel_step=1e-3):
    """Juu: Richardson-extrapolated central differences of the complex-step gradient in (F1, F200)
    at the active limits."""
    u = np.array(v_opt[:2], dtype=float)
    x2, p100 = v_opt[3], v_opt[2]

    def central(scale):
        hess = np.zeros((2, 2))
        for j in range(2):
            h = scale * abs(u[j])
            gp = cs_grad(lambda z: reduced(z, x2, p100), u + h * np.eye(2)[j])
            gm = cs_grad(lambda z: reduced(z, x2, p100), u - h * np.eye(2)[j])
            hess[:, j] = (gp - gm) / (2.0 * h)
        return hess

    hess, finer = richardson(central, rel_step)
    assert max_rel(hess, finer) < 1e-9, (hess, finer)
    asym = abs(hess[0, 1] - hess[1, 0]) / np.max(np.abs(hess))
    assert asym < 1e-9, asym
    hess = 0.5 * (hess + hess.T)
    eig = np.linalg.eigvalsh(hess)
    assert np.all(eig > 0.0), eig
    return hess, eig, float(asym)


def multipliers(res, prices):
    """SLSQP's KKT multipliers (if this SciPy returns them) as dJ*/d(limit), against the envelope
    shadow prices."""
    if getattr(res, "multipliers", None) is None:
        return {"available": False, "note": f"SciPy {scipy.__version__} does not return res.multipliers"}
    lam = np.asarray(res.multipliers, dtype=float)
    assert len(lam) == len(CONSTRAINTS), lam
    raw = {name: float(m) for (name, _, _, _), m in zip(CONSTRAINTS, lam)}
    as_price = {name: (raw[name] if kind == "min" else -raw[name]) + 0.0 for name, _, kind, _ in CONSTRAINTS}
    diff = {name: rel(as_price[name], prices[name]["envelope"]) for name in ACTIVE}
    assert max(diff.values()) < 1e-6, diff
    return {
        "available": True,
        "convention": "SciPy SLSQP: L = J - sum(lambda_i c_i) with every constraint written c_i(v) >= 0 "
        "(c = x - limit for a :min, c = limit - x for a :max) and lambda_i >= 0, so "
        "dJ*/d(limit) = +lambda for a :min and -lambda for a :max; multipliers of the QP "
        "subproblem at the last iterate of the first start that reaches the optimum (bounds get none), unscaled to $/h per unit",
        "lambda": raw,
        "as_dJ_dlimit": as_price,
        "relative_difference": diff,
    }


def start_record(x0, res, opt):
    """One SLSQP run for the JSON, asserted within 1e-6 relative of the polished optimum."""
    pt = model(res.x)
    keys = VARS + ["cost"]
    worst = max(rel(float(pt[k]), float(opt[k])) for k in keys)
    return {"x0": dict(zip(VARS, x0)), "reached": bool(worst < 1e-6), "iterations": int(res.nit), "function_evaluations": int(res.nfev),
            "gradient_evaluations": int(res.njev), "message": str(res.message),
            "x": dict(zip(VARS, map(float, res.x))), "cost": float(res.fun),
            "max_relative_difference_from_polished": worst}


def solve():
    """Every SLSQP run, checked against each other, the polished optimum and the reduced reference."""
    all_runs = [run_slsqp(x0) for x0 in STARTS]
    ref = json.loads(REDUCED.read_text())["optimum"]
    near = lambda res: all(rel(float(x), ref[k]) < 1e-7 for k, x in (("F1", res.x[0]), ("F200", res.x[1]), ("cost", res.fun)))
    runs = [res for res in all_runs if near(res)]
    for x0, res in zip(STARTS, all_runs):
        if not near(res):
            print(f"evaporator_slsqp: SLSQP from {x0} stops short ({res.message}): F1 {res.x[0]:.6g}", file=sys.stderr)
    assert runs, "SLSQP reaches the reduced reference's optimum from no start"
    v_opt = polish(runs[0].x[:2])
    opt = model(v_opt)
    for k in ("F1", "F200", "cost"):
        assert rel(float(opt[k]), ref[k]) < 1e-7, (k, opt[k], ref[k])
    starts = [start_record(x0, res, opt) for x0, res in zip(STARTS, all_runs)]
    return runs, v_opt, opt, starts


def active_set(opt):
    """The constraints at their limits (must be exactly ACTIVE); every bound must be inactive."""
    active = [name for name, var, _, limit in CONSTRAINTS if is_active(opt, var, limit)]
    assert active == list(ACTIVE), active
    for var, (lo, hi) in BOUNDS.items():
        for limit in (lo, hi):
            assert limit is None or not is_active(opt, var, limit, tol=1e-3), (var, limit)
    return active


def problem():
    """The problem statement for the JSON: variables, bounds (ours marked), constraints, cost, solver."""
    return {
        "variables": [{"name": k, "unit": UNITS[k], "bounds": list(BOUNDS[k])} for k in VARS],
        "disturbances": D_NOM,
        "constraints": [{"name": n, "variable": var, "kind": kind, "limit": lim} for n, var, kind, lim in CONSTRAINTS],
        "ours": {"bounds": [f"evaporator.{b}" for b in OURS],
                 "note": "F1 >= 0.1, F200 >= 0.1 kg/min (the paper's 0 < F1, F200, made closed), X2 <= 50 % and "
                 "P100 >= 100 kPa are ours, loose, to keep SLSQP in the model's domain; all inactive at the "
                 "optimum. F1 <= 20, F200 <= 400 kg/min and the five constraints are Kariwala et al. (2008)'s."},
        "cost": "J = 600 F100 + 0.6 F200 + 1.009 (F2 + F3) + 0.2 F1 - 4800 F2 [$/h], minimised",
        "solver": {"method": "scipy.optimize.minimize SLSQP", "options": SLSQP_OPTIONS,
                   "gradients": "complex step (objective and constraints)",
                   "scaling": {"variables": dict(zip(VARS, SCALE.tolist())), "cost": COST_SCALE,
                               "note": "SLSQP iterates on v / scale and cost * J; results are unscaled"}},
    }


def compute():
    """Everything the JSON holds, recomputed."""
    runs, v_opt, opt, starts = solve()
    hess, eig, asym = reduced_hessian(v_opt)
    prices = shadow_prices(v_opt)
    return {
        "description": "Reference economic optimum of the Newell & Lee (1989) evaporator with every constraint "
        "of Kariwala, Cao & Janardhanan (2008) free, by SciPy SLSQP over (F1, F200, P100, X2), from "
        "tools/evaporator_slsqp.py; the optimum is polished on (F1, F200) at the active limits. "
        "Units: flows kg/min, X %, P kPa, T degC, Q kW, cost $/h.",
        "versions": {"python": sys.version.split()[0], "numpy": np.__version__, "scipy": scipy.__version__},
        "problem": problem(),
        "starts": starts,
        "optimum": summarize(opt),
        "active": active_set(opt),
        "shadow_prices": prices,
        "slsqp_multipliers": multipliers(runs[0], prices),
        "reduced_hessian": {
            "variables": UNCONSTRAINED,
            "unit": "$/h per (kg/min)^2",
            "at": {"X2": 35.5, "P100": 400.0},
            "method": "central differences (relative steps 1e-3, 5e-4) of the complex-step gradient, "
            "Richardson-extrapolated, symmetrised",
            "hessian": hess.tolist(),
            "eigenvalues": eig.tolist(),
            "asymmetry_over_max": asym,
        },
        "local_model": local_model(v_opt, hess),
        "nonlinear_losses": nonlinear_losses(v_opt),
        "hostile_limit": hostile_vertex(),
    }


def hostile_vertex(f3_max=0.01):
    """The optimum under the extra limit F3 <= 0.01 kg/min (a plant squeezed 10^4-fold): the vertex
    where F3 = 0.01 kg/min and P2 = 40 kPa with X2 = 35.5 % and P100 = 400 kPa, by a root solve of the
    closed form; SLSQP itself stops there with "Inequality constraints incompatible"."""
    def vertex(u):
        m = model([u[0], u[1], 400.0, 35.5])
        return [m["F3"] - f3_max, m["P2"] - 40.0]

    sol = root(vertex, [0.005, 0.02], method="hybr", options={"xtol": 1e-14})
    assert sol.success and max(abs(r) for r in vertex(sol.x)) < 1e-10, sol
    m = model([sol.x[0], sol.x[1], 400.0, 35.5])
    return {"limit": "evaporator.F3 <= 0.01 kg/min", "active": ["F3:max", "P2:min", "X2:min", "P100:max"],
            "method": "root of F3 = 0.01 kg/min, P2 = 40 kPa at X2 = 35.5 %, P100 = 400 kPa on the closed form",
            "F1": float(sol.x[0]), "F200": float(sol.x[1]), "cost": float(np.real(m["cost"]))}


# --- (e) local model of self-optimizing control, (f) nonlinear losses of measurement pairs -------------
# Skogestad (2000), "Plantwide control: the search for the self-optimizing control structure",
# J. Process Control 10, 487-507; Halvorsen, Skogestad, Morud & Alstad (2003), "Optimal selection of
# controlled variables", IECR 42, 3273-3284 (the local model Gy, Gyd, Juu, Jud); Kariwala, Cao &
# Janardhanan (2008) (the evaporator's inputs, disturbances, magnitudes Wd and ten candidates).

INPUTS = ["F1", "F200"]  # u, kg/min (F1 first; crates/soc/tests/data/evaporator.json has F200 first)
DISTURBANCES = ["X1", "T1", "T200"]  # d: %, degC, degC
WD = [0.25, 8.0, 5.0]  # Kariwala et al. (2008): expected disturbance magnitudes
CANDIDATES = ["P2", "T2", "T3", "F2", "F100", "T201", "F3", "F5", "F200", "F1"]
CANDIDATE_UNITS = {"P2": "kPa", "T2": "degC", "T3": "degC", "T201": "degC"}  # the rest kg/min
HELD = {"X2": 35.5, "P100": 400.0}  # the active constraints, controlled at their limits
# Kariwala et al.'s other limits, checked at the held points: (variable, kind, limit).
OTHER_LIMITS = [("P2", "min", 40.0), ("P2", "max", 80.0), ("F3", "max", 100.0), ("F1", "max", 20.0),
                ("F200", "max", 400.0)]
KARIWALA = ROOT / "crates" / "soc" / "tests" / "data" / "evaporator.json"  # pySOC matrices, u = (F200, F1)
HELD_ROOT_OPTIONS = {"xtol": 1e-14}
# A pair whose 2x2 Gy is singular (P2, T2, T3 are affine in one another at fixed X2; F2, F5, F1 are
# proportional at fixed X1, X2) does not determine u; its held point counts as not converged.
SINGULAR_COND = 1e10
HELD_RESIDUAL = 1e-10  # relative residual of a converged held point
LOSS_ATOL = 1e-9  # $/h: --check floor for a loss, the difference of two J's of ~600 $/h


def d_dict(dv):
    """The disturbance dict of model() from a vector in DISTURBANCES order."""
    return dict(zip(DISTURBANCES, dv))


def measure(point, name):
    """Candidate `name` from a model() point; F5 = F4 (Newell & Lee eq. 3 at steady state)."""
    return point["F4"] if name == "F5" else point[name]


def outputs(u, dv, names=CANDIDATES):
    """The candidates `names` at u = (F1, F200), d = dv, with X2 and P100 held (complex-safe)."""
    point = model([u[0], u[1], HELD["P100"], HELD["X2"]], d_dict(dv))
    return np.array([measure(point, n) for n in names])


def held_cost(u, dv):
    """J ($/h) at u = (F1, F200), d = dv, with X2 and P100 held (complex-safe)."""
    return model([u[0], u[1], HELD["P100"], HELD["X2"]], d_dict(dv))["cost"]


def cs_jacobian(fun, x):
    """Jacobian of the real vector fun at x by the complex step (exact to rounding)."""
    x = np.asarray(x, dtype=float)
    cols = []
    for j in range(len(x)):
        z = x.astype(complex)
        z[j] += 1j * H_CS
        cols.append(np.imag(fun(z)) / H_CS)
    return np.array(cols).T


def u_gradient(u, dv):
    """dJ/du at (u, dv), complex step."""
    return cs_grad(lambda z: held_cost(z, dv), u)


def second_derivatives(u, dv, h_u, h_d):
    """Juu and Jud by central differences (steps h_u in u, h_d in d) of the complex-step dJ/du."""
    juu = np.array([(u_gradient(u + hj * e, dv) - u_gradient(u - hj * e, dv)) / (2.0 * hj)
                    for hj, e in zip(h_u, np.eye(2))]).T
    jud = np.array([(u_gradient(u, dv + hk * e) - u_gradient(u, dv - hk * e)) / (2.0 * hk)
                    for hk, e in zip(h_d, np.eye(3))]).T
    return 0.5 * (juu + juu.T), jud


def max_rel(a, b, floor=1e-8):
    """Largest elementwise |a - b| / |b| over the entries of b above floor * max|b|."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    mask = np.abs(b) > floor * np.max(np.abs(b))
    return float(np.max(np.abs(a - b)[mask] / np.abs(b)[mask]))


def kariwala_matrices(ours):
    """The pySOC matrices of KARIWALA reordered to u = (F1, F200), and their differences from ours."""
    ref = json.loads(KARIWALA.read_text())
    assert ref["disturbances"] == DISTURBANCES and ref["measurements"] == CANDIDATES, ref.keys()
    perm = [ref["inputs"].index(k) for k in INPUTS]
    theirs = {"Gy": np.array(ref["Gy"])[:, perm], "Gyd": np.array(ref["Gyd"]),
              "Juu": np.array(ref["Juu"])[np.ix_(perm, perm)], "Jud": np.array(ref["Jud"])[perm, :]}
    return {
        "source": str(KARIWALA.relative_to(ROOT)),
        "note": "for information only, not asserted: reordered from u = (F200, F1) to (F1, F200); "
        "max_relative_difference is elementwise over the entries of ours above 1e-8 of the matrix's largest, "
        "max_difference_over_max is max|theirs - ours| / max|ours|",
        **{k: v.tolist() for k, v in theirs.items()},
        "max_relative_difference": {k: max_rel(theirs[k], ours[k]) for k in theirs},
        "max_difference_over_max": {k: float(np.max(np.abs(theirs[k] - ours[k])) / np.max(np.abs(ours[k])))
                                    for k in theirs},
    }


def local_model(v_opt, juu_reduced, rel_step=1e-3):
    """Gy, Gyd (complex step) and Juu, Jud (Richardson-extrapolated central differences of the
    complex-step gradient, checked against the extrapolation at half the steps) at the optimum, with
    X2 and P100 held."""
    u = np.array(v_opt[:2], dtype=float)
    dv = np.array([D_NOM[k] for k in DISTURBANCES])
    gy = cs_jacobian(lambda z: outputs(z, dv), u)
    gyd = cs_jacobian(lambda z: outputs(u, z), dv)
    both = richardson(lambda s: np.concatenate(second_derivatives(u, dv, s * np.abs(u), s * np.abs(dv)), axis=1),
                      rel_step)
    (juu, jud), (juu_fine, jud_fine) = [(m[:, :2], m[:, 2:]) for m in both]
    check = {"Juu": max_rel(juu_fine, juu), "Jud": max_rel(jud_fine, jud)}
    assert max(check.values()) < 1e-9, check
    assert max_rel(juu, juu_reduced) < 1e-9, (juu, juu_reduced)
    ours = {"Gy": gy, "Gyd": gyd, "Juu": 0.5 * (juu + juu.T), "Jud": jud}
    return {
        "inputs": INPUTS, "disturbances": DISTURBANCES, "nominal_disturbances": dv.tolist(),
        "measurements": CANDIDATES,
        "units": {"inputs": "kg/min", "disturbances": ["%", "degC", "degC"],
                  "measurements": [CANDIDATE_UNITS.get(m, "kg/min") for m in CANDIDATES], "J": "$/h"},
        "at": {**HELD, "F1": float(u[0]), "F200": float(u[1])},
        "method": "Gy = dy/du and Gyd = dy/dd (u held) by complex step; Juu and Jud by central differences "
        "of the complex-step gradient dJ/du at steps 1e-3, 5e-4 of |u_j| or |d_k|, Richardson-extrapolated "
        "(error O(h^4)), Juu symmetrised; checked against the extrapolation at half the steps "
        "(second_derivative_check)",
        **{k: m.tolist() for k, m in ours.items()},
        "Wd": WD,
        "second_derivative_check": {"half_steps": {"Juu": juu_fine.tolist(), "Jud": jud_fine.tolist()},
                                    "max_relative_difference": check},
        "kariwala": kariwala_matrices(ours),
    }


def violated(point):
    """The names ("P2:min", ...) of OTHER_LIMITS that point violates."""
    out = []
    for var, kind, limit in OTHER_LIMITS:
        x = float(np.real(measure(point, var)))
        if (kind == "min" and x < limit) or (kind == "max" and x > limit):
            out.append(f"{var}:{kind}")
    return out


def disturbed(k, sign):
    """The disturbance vector with d_k moved by sign * Wd_k, the others at nominal."""
    dv = np.array([D_NOM[n] for n in DISTURBANCES])
    dv[k] += sign * WD[k]
    return dv


def reoptimize(u_opt, dv):
    """The optimum over (F1, F200) at d = dv with X2, P100 held (polished), and whether the held
    active set is still optimal there (dJ/dX2 > 0, dJ/dP100 < 0: X2:min and P100:max price positive)."""
    v = polish(u_opt, x2=HELD["X2"], p100=HELD["P100"], d=d_dict(dv))
    grad = cs_grad(lambda z: model(z, d_dict(dv))["cost"], v)
    point = model(v, d_dict(dv))
    return v, point, bool(grad[VARS.index("X2")] > 0.0 and grad[VARS.index("P100")] < 0.0)


def solve_held(pair, y0, dv, u0):
    """(F1, F200) holding the measurements `pair` at y0 at d = dv (scipy root, hybr, complex-step
    Jacobian); None unless the residual is at rounding level and the 2x2 Jacobian is nonsingular."""
    def resid(u):
        return np.real(outputs(u, dv, pair)) - y0

    def jac(u):
        return cs_jacobian(lambda z: outputs(z, dv, pair), u)

    with np.errstate(all="ignore"):
        sol = root(resid, u0, jac=jac, method="hybr", options=HELD_ROOT_OPTIONS)
        ok = np.all(np.isfinite(sol.x)) and np.all(np.isfinite(resid(sol.x)))
        if not ok or np.max(np.abs(resid(sol.x)) / np.maximum(np.abs(y0), 1.0)) > HELD_RESIDUAL:
            return None
        if np.linalg.cond(jac(sol.x)) > SINGULAR_COND:
            return None
    return sol.x


def loss_point(pair, y0, u_opt, k, sign, j_opt):
    """One (pair, disturbance, sign) entry: J with the pair held, J re-optimized, their difference."""
    dv = disturbed(k, sign)
    u = solve_held(pair, y0, dv, u_opt)
    rec = {"disturbance": DISTURBANCES[k], "sign": sign, "loss": None, "J_held": None, "J_opt": j_opt,
           "converged": u is not None, "violated": None}
    if u is not None:
        point = model([u[0], u[1], HELD["P100"], HELD["X2"]], d_dict(dv))
        j_held = float(point["cost"])
        assert j_held - j_opt > -1e-9, (pair, rec, j_held)  # J_opt is the minimum
        rec.update(loss=j_held - j_opt, J_held=j_held, violated=violated(point))
    return rec


def nonlinear_losses(v_opt):
    """Loss J_held - J_opt ($/h) of holding each pair of candidates at its nominal optimal value, for
    each disturbance moved by +- Wd; plus the re-optimized points."""
    u_opt = np.array(v_opt[:2], dtype=float)
    y_nom = np.real(outputs(u_opt, np.array([D_NOM[n] for n in DISTURBANCES])))
    cases = [(k, s) for k in range(len(DISTURBANCES)) for s in (1, -1)]
    reopt = []
    for k, s in cases:
        v, point, optimal = reoptimize(u_opt, disturbed(k, s))
        reopt.append({"disturbance": DISTURBANCES[k], "sign": s, "F1": float(v[0]), "F200": float(v[1]),
                      "J": float(point["cost"]), "violated": violated(point), "active_set_optimal": optimal})
    subsets = []
    for a in range(len(CANDIDATES)):
        for b in range(a + 1, len(CANDIDATES)):
            pair = [CANDIDATES[a], CANDIDATES[b]]
            y0 = y_nom[[a, b]]
            points = [loss_point(pair, y0, u_opt, k, s, r["J"]) for (k, s), r in zip(cases, reopt)]
            subsets.append({"measurements": pair, "setpoints": y0.tolist(), "points": points})
    return {
        "description": "Kariwala et al. (2008)'s evaporator with X2 = 35.5 % and P100 = 400 kPa held: each pair "
        "of candidates held at its value at the nominal optimum (setpoints, candidate units) by solving for "
        "(F1, F200) with scipy.optimize.root (hybr, xtol 1e-14, complex-step Jacobian, from the nominal "
        "optimum); loss = J_held - J_opt in $/h, J_opt the re-optimum at the same disturbance. converged is "
        "false (loss null) when no solution is found or the pair's 2x2 Jacobian is singular (u not "
        "determined). violated lists the other Kariwala limits (P2 in [40, 80] kPa, F3 <= 100, F1 <= 20, "
        "F200 <= 400 kg/min) broken at the held point. In reoptimized, active_set_optimal says whether "
        "X2:min and P100:max still have positive shadow prices there.",
        "disturbances": DISTURBANCES,
        "magnitudes": WD,
        "held": HELD,
        "root_options": HELD_ROOT_OPTIONS,
        "reoptimized": reopt,
        "subsets": subsets,
    }


def compare(new, old, path="", rtol=1e-9, atol=1e-12):
    """Numbers within rtol (relative to each number, atol floor; LOSS_ATOL for a loss, which is the
    difference of two J's each compared at rtol); other values equal; versions and rounding-level
    diagnostics ignored."""
    if path.endswith(("versions", "asymmetry_over_max", "relative_difference", "max_relative_difference_from_polished",
                      "max_difference_over_max")):
        return []
    # The optimizer's path (each start's end, counts and message; the QP multipliers at the last
    # iterate of the first start that reaches the optimum) depends on the machine's rounding; the
    # script asserts the multipliers against the envelope prices to 1e-6 and needs one start at
    # the optimum. The optimum itself and everything derived from it is compared.
    if path.startswith((".starts", ".slsqp_multipliers")):
        return []
    if path.endswith(".loss"):
        atol = LOSS_ATOL
    if isinstance(new, dict) and isinstance(old, dict):
        if set(new) != set(old):
            return [f"{path}: keys {sorted(set(new) ^ set(old))} differ"]
        return [b for k in new for b in compare(new[k], old[k], f"{path}.{k}", rtol, atol)]
    if isinstance(new, list) and isinstance(old, list):
        if len(new) != len(old):
            return [f"{path}: length {len(new)} vs {len(old)}"]
        return [b for i, (a, o) in enumerate(zip(new, old)) for b in compare(a, o, f"{path}[{i}]", rtol, atol)]
    numbers = (int, float)
    if isinstance(new, numbers) and isinstance(old, numbers) and not isinstance(new, bool):
        return [] if abs(new - old) <= rtol * abs(old) + atol else [f"{path}: {new!r} vs committed {old!r}"]
    return [] if new == old else [f"{path}: {new!r} vs committed {old!r}"]


def main():
    """Write the JSON, or with --check compare a fresh run with it."""
    ref = compute()
    name = OUT.relative_to(ROOT)
    if "--check" in sys.argv[1:]:
        bad = compare(ref, json.loads(OUT.read_text()))
        if bad:
            print(f"{name}: {len(bad)} numbers differ from a fresh run:", file=sys.stderr)
            print("\n".join(bad[:20]), file=sys.stderr)
            sys.exit(1)
        o, s = ref["optimum"], ref["shadow_prices"]
        print(f"{name}: matches a fresh run (optimum F1 {o['F1']:.4f}, F200 {o['F200']:.3f} kg/min, "
              f"J {o['cost']:.3f} $/h; shadow prices X2:min {s['evaporator.X2:min']['envelope']:.4f} $/h per %, "
              f"P100:max {s['evaporator.P100:max']['envelope']:.5f} $/h per kPa; "
              f"SLSQP iterations {[r['iterations'] for r in ref['starts']]}, "
              f"reaching the optimum {[r['reached'] for r in ref['starts']]})")
        return
    OUT.write_text(json.dumps(ref, indent=1) + "\n")
    print(f"wrote {name}")


if __name__ == "__main__":
    main()
