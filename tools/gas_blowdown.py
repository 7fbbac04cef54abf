#!/usr/bin/env python3
"""Adiabatic blowdown of an ideal-gas vessel through a gas control valve, integrated by SciPy: the
independent reference for plantwide's `gas_vessel` (issue 56).

The vessel and the valve are read from the flowsheets `tests/data/gas/blowdown*.json` (volume, Cv,
opening, x_T, p_out, the feed's flow and temperature) and methane's ideal-gas heat capacity from the
component library `crates/thermo/data/library.json` (DIPPR 107, Perry's 8th Table 2-156): data, not
plantwide code. The equations are written here again from their sources:

- ideal gas `P V = N R T`; internal energy `U = N (h(T) − R T)`, `h(T) = ∫_{298.15}^T cp dT` in the
  closed form of DIPPR 107 (`c0 T + c1 c2 coth(c2/T) − c3 c4 tanh(c4/T)`);
- IEC 60534-2-1, gas service, SI form: `W = Cv f Y √(x P ρ)`, `x = min(ΔP/P, Fγ x_T)`,
  `Y = 1 − x/(3 Fγ x_T)`, `Fγ = γ/1.4`, `γ = cp/(cp − R)`, `ρ = P M/(R T)`; `f = opening` (linear);
  the square root smoothed within 10 Pa of ΔP = 0 as plantwide states it (`√δ u (3 − |u|)/2`);
- `dN/dt = F_in − W/M`, `dU/dt = F_in h(T_in) − (W/M) h(T)`.

The steady state before the feed stops (W(P0, T_in)/M = F_in, T0 = T_in: an ideal gas throttled
adiabatically keeps its temperature) is the start; the feed stops at t = 0. P, T, N and U at
every 10 s of 10 min, for each flowsheet, go to `tests/data/gas/blowdown_reference.json`, with the
vent opening that holds `flowsheets/gas_receiver.json` at 12 barg for its supply before and after
the shipped +20 % step.

    python3 tools/gas_blowdown.py            # write the reference
    python3 tools/gas_blowdown.py --check    # recompute; exit 1 unless it matches the file
"""

import json
import math
import pathlib
import sys

from scipy.integrate import solve_ivp
from scipy.optimize import brentq

ROOT = pathlib.Path(__file__).resolve().parent.parent
R = 8.314462618  # J/(mol K), plantwide_thermo::R_GAS
T_REF = 298.15
DP_SMOOTH = 10.0  # Pa
CASES = ["blowdown", "blowdown_subcritical"]
OUT = ROOT / "tests/data/gas/blowdown_reference.json"


def quantity(text, unit_si):
    """'5 m3', '3e-4 m2', '1 atm', '8 bar', '40 mol/s', '300 K' in SI."""
    value, unit = text.split()
    return float(value) * unit_si[unit]


UNITS = {"m3": 1.0, "m2": 1.0, "atm": 101325.0, "bar": 1e5, "mol/s": 1.0, "K": 1.0}


def methane():
    lib = json.loads((ROOT / "crates/thermo/data/library.json").read_text())
    comps = lib["components"] if isinstance(lib, dict) else lib
    c = next(x for x in comps if x["name"] == "methane")
    assert c["cp_ig"]["form"] == "dippr107"
    return c["mw"], c["cp_ig"]["c"]


def make(case, path=None):
    sheet = json.loads((path or ROOT / f"tests/data/gas/{case}.json").read_text())
    vessel, feed = sheet["units"]["receiver"], sheet["units"]["supply"]
    valve = vessel["outflow"]
    mw, c = methane()
    v = quantity(vessel["volume"], UNITS)
    cv, op, xt = quantity(valve["cv"], UNITS), valve["opening"], valve["xt"]
    equal_percentage = valve.get("characteristic") == "equal_percentage"
    rangeability = valve.get("rangeability", 50.0)
    p_out = quantity(valve["p_out"], UNITS)
    f_in, t_in = quantity(feed["F"], UNITS), quantity(feed["T"], UNITS)

    def cp(t):
        a, b = c[2] / t, c[4] / t
        return c[0] + c[1] * (a / math.sinh(a)) ** 2 + c[3] * (b / math.cosh(b)) ** 2

    def h_int(t):
        return c[0] * t + c[1] * c[2] / math.tanh(c[2] / t) - c[3] * c[4] * math.tanh(c[4] / t)

    def h(t):
        return h_int(t) - h_int(T_REF)

    def ssqrt(x):
        if x >= DP_SMOOTH:
            return math.sqrt(x)
        if x <= -DP_SMOOTH:
            return -math.sqrt(-x)
        u = x / DP_SMOOTH
        return u * (3.0 - abs(u)) * 0.5 * math.sqrt(DP_SMOOTH)

    def molar_flow(p, t, opening=op):
        f = rangeability ** (opening - 1.0) if equal_percentage else opening
        f_gamma = cp(t) / (cp(t) - R) / 1.4
        choke = f_gamma * xt
        dp = min(p - p_out, choke * p)
        y = 1.0 - (dp / p) / (3.0 * choke) if dp > 0 else 1.0
        rho = p * mw / (R * t)
        return cv * f * y * ssqrt(dp) * math.sqrt(rho) / mw

    def temperature(n, u):
        return brentq(lambda t: n * (h(t) - R * t) - u, 20.0, 2000.0, xtol=1e-14, rtol=1e-15)

    p0 = brentq(lambda p: molar_flow(p, t_in) - f_in, p_out * (1 + 1e-9), 1e3 * p_out, xtol=1e-12, rtol=1e-15)
    n0 = p0 * v / (R * t_in)
    u0 = n0 * (h(t_in) - R * t_in)

    def rhs(_t, s):
        n, u = s
        t = temperature(n, u)
        p = n * R * t / v
        w = molar_flow(p, t)
        return [-w, -w * h(t)]

    return v, (n0, u0), rhs, temperature, molar_flow


def receiver_openings():
    """flowsheets/gas_receiver.json held at 12 barg, 300 K: the vent valve's opening that passes
    the supply, 40 mol/s and, after its +20 % step, 48 mol/s."""
    path = ROOT / "flowsheets/gas_receiver.json"
    molar_flow = make(None, path)[4]
    p = 12e5 + 101325.0
    return {str(f): brentq(lambda op: molar_flow(p, 300.0, op) - f, 1e-6, 1.0, xtol=1e-15, rtol=1e-15) for f in (40, 48)}


def reference():
    out = {}
    for case in CASES:
        v, s0, rhs, temperature, _ = make(case)
        times = [10.0 * k for k in range(61)]
        sol = solve_ivp(rhs, (0.0, 600.0), list(s0), method="Radau", t_eval=times, rtol=1e-12, atol=[1e-9, 1e-3])
        assert sol.success, sol.message
        rows = []
        for k, t in enumerate(sol.t):
            n, u = sol.y[0][k], sol.y[1][k]
            temp = temperature(n, u)
            rows.append({"t": t, "P": n * R * temp / v, "T": temp, "N": n, "U": u})
        out[case] = rows
    return out


def main():
    ref = reference()
    openings = receiver_openings()
    source = "tools/gas_blowdown.py (SciPy solve_ivp Radau, rtol 1e-12; brentq)"
    text = json.dumps({"source": source, "cases": ref, "receiver_openings": openings}, indent=1)
    if "--check" in sys.argv[1:]:
        saved = json.loads(OUT.read_text())
        old = saved["cases"]
        worst = max(
            abs(a[k] - b[k]) / abs(b[k]) for case in CASES for a, b in zip(ref[case], old[case]) for k in ("P", "T", "N", "U")
        )
        worst = max([worst] + [abs(openings[f] - saved["receiver_openings"][f]) for f in openings])
        print(f"gas_blowdown: largest relative change against {OUT.name}: {worst:.2e}")
        sys.exit(0 if worst < 1e-9 else 1)
    OUT.write_text(text + "\n")
    for case in CASES:
        end = ref[case][-1]
        print(f"{case}: P {ref[case][0]['P']:.6f} -> {end['P']:.6f} Pa, T -> {end['T']:.6f} K in 600 s")
    print(f"gas_receiver.json at 12 barg: vent opening {openings}")


if __name__ == "__main__":
    main()
