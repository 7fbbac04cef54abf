#!/usr/bin/env python3
"""The control study of the two-column reactor plant (Practical Distillation Control ch. 6).

Every number in the report is produced by a `plantwide` command run here; this script only
writes the variant flowsheets and scenarios those commands read, reads their JSON and CSV
output, and lays the numbers out as a report. The commands are listed in the report's last
section so that any number can be reproduced by hand.

    python3 tools/two_column_study.py                       # docs/two_column_plant.md + figures
    python3 tools/two_column_study.py --short --out DIR     # shorter horizons (the full-study test's run)

Outputs: `<out>/two_column_plant.md`, `<out>/two_column_plant/*.png|csv`, the variant
flowsheets and scenarios under `<out>/two_column_plant/inputs/`, and
`<out>/two_column_plant/results.json` (the numbers the test pins, ignored by default:
`cargo test --test it two_column_study:: -- --include-ignored`).
"""

import argparse
import copy
import csv
import json
import math
import os
import shlex
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BASE = os.path.join(ROOT, "flowsheets", "two_column_plant.json")
KMOLH = 3.6  # mol/s -> kmol/h

# Column structures: (drum level output, sump level output), (top-end input, bottom-end input).
STRUCTURES = {
    "LV": (("distillate", "bottoms"), ("reflux", "boilup")),
    "DV": (("reflux", "bottoms"), ("distillate", "boilup")),
    "LB": (("distillate", "boilup"), ("reflux", "bottoms")),
}
# Controlled variables of each column end, chosen from the `sensors` output and the temperature
# profile (column 2's top section is flat to 0.1 K, so its top end needs an analyzer).
ENDS = {"column1": ("column1.T[21]", "column1.T[11]"), "column2": ("product.x[S]", "column2.T[6]")}
QUALITY_LOOPS = {"column1": ("column1_top_T", "column1_bottom_T"), "column2": ("column2_top_S", "column2_bottom_T")}


class Study:
    def __init__(self, plantwide, out, short):
        self.bin = plantwide
        self.out = out
        self.dir = os.path.join(out, "two_column_plant")
        self.inputs = os.path.join(self.dir, "inputs")
        os.makedirs(self.inputs, exist_ok=True)
        self.short = short
        self.commands = []
        self.results = {}
        with open(BASE) as f:
            self.base = json.load(f)

    # ----- running plantwide -------------------------------------------------------------
    def rel(self, path):
        return os.path.relpath(path, self.out if path.startswith(self.out) else ROOT)

    def pw(self, *args, parse_json=False, allow_fail=False):
        cmd = [self.bin, *args]
        shown = "plantwide " + " ".join(shlex.quote(self.show(a)) for a in args)
        self.commands.append(shown)
        p = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
        if p.returncode != 0:
            if allow_fail:
                first = (p.stderr.strip().splitlines() or ["?"])[0]
                return {"error": first.split(".json: ", 1)[-1], "exit": p.returncode}
            sys.exit(f"{shown}\nfailed with exit {p.returncode}:\n{p.stderr}")
        return json.loads(p.stdout) if parse_json else p.stdout

    def show(self, a):
        """A command argument as the report shows it: paths relative to the output directory."""
        if isinstance(a, str) and os.path.isabs(a):
            return os.path.relpath(a, self.out) if a.startswith(self.out) else os.path.relpath(a, ROOT)
        return a

    def write(self, name, obj):
        path = os.path.join(self.inputs, name)
        with open(path, "w") as f:
            json.dump(obj, f, indent=1)
        return path

    def fig(self, name):
        return os.path.join(self.dir, name)

    def steady(self, flowsheet, *sets):
        args = ["steady", flowsheet, "--json"]
        for s in sets:
            args += ["--set", s]
        return self.pw(*args, parse_json=True)["values"]

    def gains(self, flowsheet, inputs, outputs, method="linear"):
        args = ["gains", flowsheet, "--inputs", ",".join(inputs), "--outputs", ",".join(outputs), "--method", method]
        if method == "linear":
            return self.pw(*args, "--json", parse_json=True, allow_fail=True)
        # The book's method: the command chooses the step from the scales and verifies the gains at
        # h and h/2 (and against the linearization), shrinking the step until they agree.
        g = self.pw(*args, "--json", parse_json=True, allow_fail=True)
        if "gain" in g:
            g["step"] = g["perturbation"]["step"]
        return g

    def run(self, flowsheet, scenario, name, plot=True, sets=(), allow_fail=False):
        """Run a scenario; with `allow_fail` a run that stops early returns its error as the summary
        and the trends `plantwide` wrote up to the failure."""
        csv_path = self.fig(name + ".csv")
        args = ["run", flowsheet, "--scenario", scenario, "--csv", csv_path, "--json"]
        if plot:
            args += ["--plot", self.fig(name + ".png")]
        for s in sets:
            args += ["--set", s]
        summary = self.pw(*args, parse_json=True, allow_fail=allow_fail)
        with open(csv_path) as f:
            rows = list(csv.reader(f))
        header = [h.split(" [")[0] for h in rows[0]]
        cols = {h: [float(r[i]) for r in rows[1:]] for i, h in enumerate(header)}
        return summary, cols

    def hours(self, full, short):
        return f"{short if self.short else full} h"

    # ----- flowsheet variants ------------------------------------------------------------
    def variant(self, name, edit):
        spec = copy.deepcopy(self.base)
        edit(spec)
        spec["name"] = f"two_column_plant_{name}"
        return self.write(f"{name}.json", spec)


def set_levels(spec, col, drum, sump, kc_drum="10 1/h", kc_sump=None):
    """P-only level loops of `col` on the given outputs (bias: the nominal flows)."""
    c = spec["controllers"]
    holdups = spec["units"][col]
    c[f"{col}_drum"] = {"type": "pid", "pv": f"{col}.M[32]", "output": f"{col}.{drum}",
                        "sp": holdups["condenser_holdup"], "kc": kc_drum, "action": "direct"}
    kc_sump = kc_sump or ("0.5 1/min" if sump == "boilup" else "4 1/h")
    c[f"{col}_sump"] = {"type": "pid", "pv": f"{col}.M[1]", "output": f"{col}.{sump}",
                        "sp": holdups["reboiler_holdup"], "kc": kc_sump, "action": "direct"}


def open_quality_loops(spec, col):
    for name in QUALITY_LOOPS[col]:
        del spec["controllers"][name]


def fmt(v, digits=4):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def amplitude(t, y, t_from):
    """Half the peak-to-peak of `y` after `t_from`."""
    ys = [v for ti, v in zip(t, y) if ti >= t_from]
    return 0.5 * (max(ys) - min(ys))


def at_time(cols, when):
    """The recorded effluent temperature nearest `when` [h]."""
    i = min(range(len(cols["time"])), key=lambda k: abs(cols["time"][k] - when))
    return cols["effluent.T"][i]


def crossing(t, y, level):
    """First time `y` rises through `level`."""
    for i in range(1, len(y)):
        if y[i - 1] < level <= y[i]:
            return t[i - 1] + (t[i] - t[i - 1]) * (level - y[i - 1]) / (y[i] - y[i - 1])
    return None


# ===== the study ==============================================================================

def base_case(s, md):
    v = s.steady(BASE)
    F = lambda st: v[f"{st}.F"] * KMOLH  # noqa: E731
    x = lambda st, c: v[f"{st}.x[{c}]"]  # noqa: E731
    streams = ["feed_A", "feed_B", "reactor_feed", "effluent", "recycle", "bottoms1", "product", "heavies"]
    rows = [[st, fmt(F(st)), fmt(v[f"{st}.T"]), *(fmt(x(st, c)) for c in "ABRS")] for st in streams]
    # Balances over the plant: A + B -> R and 2B -> S conserve the A atoms (A + R), the B atoms
    # (B + R + 2S) and the mass (MW 40, 60, 100, 120).
    mw = {"A": 40.0, "B": 60.0, "R": 100.0, "S": 120.0}
    inv = {"A + R": {"A": 1, "R": 1}, "B + R + 2S": {"B": 1, "R": 1, "S": 2}, "mass": mw}
    balance = {}
    for name, w in inv.items():
        def flow(st):
            return F(st) * sum(w.get(c, 0) * x(st, c) for c in "ABRS")
        fed, out = flow("feed_A") + flow("feed_B"), flow("product") + flow("heavies")
        balance[name] = abs(fed - out) / fed
    # Reactor energy balance: F_in h_in − F h + Q − V Σ Δh_k r_k = 0.
    q_rxn = v["reactor.V"] * (80e3 * v["reactor.rate[1]"] + 50e3 * v["reactor.rate[2]"])
    e_in = v["reactor_feed.F"] * v["reactor_feed.h"] + v["reactor.Q"] + q_rxn
    balance["reactor energy"] = abs(e_in - v["effluent.F"] * v["effluent.h"]) / q_rxn
    residence = v["reactor.M"] / v["effluent.F"] / 60
    s.results["base"] = {
        "product_kmol_h": F("product"), "product_purity": x("product", "R"), "recycle_kmol_h": F("recycle"),
        "fresh_B_kmol_h": F("feed_B"), "reactor_T": v["effluent.T"], "reactor_duty_MW": -v["reactor.Q"] / 1e6,
        "residence_min": residence, "balances": balance,
        "selectivity": v["reactor.rate[1]"] / (v["reactor.rate[1]"] + 2 * v["reactor.rate[2]"]),
    }
    md += ["## 1. Base case", "",
           f"`plantwide steady flowsheets/two_column_plant.json` converges the plant with its full control "
           f"structure (sequential-modular pass on the recycle, then whole-plant Newton). The reactor makes "
           f"{fmt(F('product'))} kmol/h of R at {fmt(100 * x('product', 'R'))} % purity from 100 kmol/h of A; "
           f"{fmt(100 * s.results['base']['selectivity'])} % of the B consumed becomes R. The recycle is "
           f"{fmt(F('recycle'))} kmol/h, twice the fresh A: column 1 is the plant's largest load.", "",
           table(["stream", "F [kmol/h]", "T [K]", "x A", "x B", "x R", "x S"], rows), "",
           f"Reactor: {fmt(v['reactor.V'])} m³ of liquid, residence time {fmt(residence)} min, "
           f"{fmt(v['effluent.T'])} K, heat removed {fmt(-v['reactor.Q'] / 1e6)} MW through the jacket "
           f"(coolant {fmt(v['reactor.Tj'])} K).", "",
           "Balances over the whole plant (relative, from the converged streams): "
           + ", ".join(f"{k} {v_:.1e}" for k, v_ in balance.items()) + ".", ""]
    return v


def column_structures(s, md):
    md += ["## 2. Column control structures", "",
           "For each column the steady-state gains of the two end-quality variables to the two free "
           "inputs are taken at the base case, inside the whole plant: the other column and the reactor "
           "keep their loops, the recycle stays closed (the plantwide gains, not the column's alone). "
           "Level loops are placed as each structure says; the quality loops of the column studied are "
           "open. Sensors: column 1 stages 21 and 11 (the `sensors` SVD choice, below); column 2 stage 6 "
           "for the bottom end and an analyzer on the product's S for the top end, because column 2's top "
           "section is flat to 0.1 K over 15 trays (a temperature there cannot see 0.05 % S).", ""]
    all_rows = {}
    for col in ("column1", "column2"):
        rows, res = [], {}
        for name, ((drum, sump), (u1, u2)) in STRUCTURES.items():
            def edit(spec, col=col, drum=drum, sump=sump):
                open_quality_loops(spec, col)
                set_levels(spec, col, drum, sump)
            f = s.variant(f"{col}_{name}_open", edit)
            inputs = [f"{col}.{u1}@kmol/h", f"{col}.{u2}@kmol/h"]
            g = s.gains(f, inputs, list(ENDS[col]))
            p = s.gains(f, inputs, list(ENDS[col]), method="perturb")
            diff = None
            if "gain" in p:
                diff = max(abs(a - b) / abs(a) for ra, rb in zip(g["gain"], p["gain"]) for a, b in zip(ra, rb))
            res[name] = {"gain": g["gain"], "rga11": g["rga"][0][0], "niederlinski": g["niederlinski"],
                         "condition_number": g["condition_number"], "perturb_vs_linear": diff,
                         "perturb_step": p.get("step")}
            gm = g["gain"]
            rows.append([name, f"{u1}, {u2}", f"{fmt(gm[0][0])}, {fmt(gm[0][1])}; {fmt(gm[1][0])}, {fmt(gm[1][1])}",
                         fmt(g["rga"][0][0]), fmt(g["niederlinski"]), fmt(g["condition_number"]),
                         f"{diff:.1e} (step {p['step']:.0e})" if diff is not None else "not re-converged"])
        s.results[col] = res
        all_rows[col] = rows
        lv = os.path.join(s.inputs, f"{col}_LV_open.json")
        sens = s.pw("sensors", lv, "--column", col, "--inputs", f"{col}.reflux,{col}.boilup", "--json", parse_json=True)
        s.results[f"sensors_{col}"] = sens["svd_stages"]
        md += [f"`plantwide sensors` on {col} (LV inputs, quality loops open): SVD criterion stages "
               f"{', '.join(str(x) for x in sens['svd_stages'])}, slope criterion stages "
               f"{', '.join(str(x) for x in sens['slope']['stages'])}.", ""]
    md += ["### Column 1 (A, B overhead to the reactor; R, S to column 2)", "",
           f"Outputs {ENDS['column1'][0]}, {ENDS['column1'][1]} [K]; inputs in kmol/h.", "",
           table(["structure", "inputs (top, bottom)", "gain [K/(kmol/h)]", "λ11", "NI", "cond.", "perturb vs linear"],
                 all_rows["column1"]), ""]
    c1 = s.results["column1"]
    md += [f"- **LV is unworkable as a dual-temperature structure**: λ11 = {fmt(c1['LV']['rga11'])} and "
           f"NI = {fmt(c1['LV']['niederlinski'])}: the two temperatures move together with L and V "
           f"(both gains of one sign in each row), so each loop undoes the other; with one loop in manual the "
           f"other's gain changes by the factor λ11.",
           f"- **DV** (λ11 = {fmt(c1['DV']['rga11'])}, NI = {fmt(c1['DV']['niederlinski'])}) and "
           f"**LB** (λ11 = {fmt(c1['LB']['rga11'])}, NI = {fmt(c1['LB']['niederlinski'])}) are nearly decoupled. "
           "LB's large condition number is input scaling (a kmol/h of bottoms moves the split, a kmol/h of reflux "
           "does not); DV is better conditioned. They are the two carried to the dynamic study (§5).",
           "- In DV the temperature loop moves the distillate, which *is* the recycle: every correction of "
           "column 1 enters the reactor at once. In LB the distillate is on the drum level, whose averaging "
           "loop filters column 1's upsets before they reach the reactor (§7).", "",
           "### Column 2 (R overhead as product; S bottoms)", "",
           f"Outputs {ENDS['column2'][0]} [-], {ENDS['column2'][1]} [K]; inputs in kmol/h.", "",
           table(["structure", "inputs (top, bottom)", "gain", "λ11", "NI", "cond.", "perturb vs linear"],
                 all_rows["column2"]), ""]
    c2 = s.results["column2"]
    lv2 = os.path.join(s.inputs, "column2_LV_open.json")
    lin2 = c2["LV"]["gain"]
    explicit = {}
    for h in ("1e-4", "1e-5", "1e-6"):
        g = s.pw("gains", lv2, "--inputs", "column2.reflux@kmol/h,column2.boilup@kmol/h", "--outputs",
                 ",".join(ENDS["column2"]), "--method", "perturb", "--step", h, "--json", parse_json=True)
        diff = max(abs(a - b) / abs(a) for ra, rb in zip(lin2, g["gain"]) for a, b in zip(ra, rb))
        check = g["perturbation"]
        explicit[h] = {"perturb_vs_linear": diff, "step": check["step"], "attempts": check["attempts"],
                       "richardson": check["max_relative_difference"]}
    c2["LV_explicit_steps"] = explicit
    db = s.variant("column2_DB_open", lambda spec: (open_quality_loops(spec, "column2"),
                                                    set_levels(spec, "column2", "reflux", "boilup")))
    dbg = s.gains(db, ["column2.distillate@kmol/h", "column2.bottoms@kmol/h"], list(ENDS["column2"]))
    s.results["column2"]["DB_error"] = dbg.get("error")
    md += [f"- **LV is unworkable**: λ11 = {fmt(c2['LV']['rga11'])}, NI = {fmt(c2['LV']['niederlinski'])}. "
           "With 5 kmol/h of bottoms under 250 kmol/h of boilup, any imbalance of L and V lands in the tiny "
           "bottoms stream (Richardson's rule: the sump level must be on the large stream).",
           f"- **DV** pairs the wrong way round (λ11 = {fmt(c2['DV']['rga11'])}): the distillate sets the "
           "bottoms temperature and the boilup the top purity, an inverted pairing that a plant operator would "
           "not accept.",
           f"- **LB** is decoupled: λ11 = {fmt(c2['LB']['rga11'])}, NI = {fmt(c2['LB']['niederlinski'])}. "
           "Its condition number is only the ratio of units (mole fraction against kelvin).",
           f"- DB (both products on flow, L and V on the levels) has no steady state of its own; `plantwide gains` "
           f"says: *{dbg.get('error', 'converged')}*.", "",
           "Chosen: **LB on both columns** (drum level by distillate, sump level by boilup, top end by reflux, "
           "bottom end by bottoms flow). The 'perturb vs linear' column is the largest relative difference "
           "between the book's perturb-and-reconverge gains (central differences at h and h/2, Richardson-extrapolated; "
           "the relative step the command chose and verified in brackets) and the linearization. The two methods agree. "
           "An explicit `--step` is only the first attempt: the command shrinks a step too large for the curvature of "
           "the high-purity columns until the gains at h and h/2 agree; column 2 LV with "
           + ", ".join(f"--step {h} used {e['step']:.1e} ({e['attempts']} attempt(s)) and differs by "
                       f"{e['perturb_vs_linear']:.1e}" for h, e in explicit.items()) + ".", ""]


def screening(s, md):
    """Sections 2-3 redone by `plantwide screen`: every inventory configuration of each column, then the
    plantwide pairings of the four qualities with the throughput choices, the fig. 6-6 band and a dynamic test."""
    res, sections = {}, []
    for col in ("column1", "column2"):
        r = s.pw("screen", BASE, "--column", col, "--outputs", ",".join(ENDS[col]), "--steady-only", "--json",
                 parse_json=True)
        rows = [[c["rank"] if c["rank"] is not None else "–", c["name"],
                 fmt(c["rga"][0][0]) if c["rga"] else "–", fmt(c["niederlinski"]) if c["niederlinski"] else "–",
                 fmt(c["minimized_condition_number"]) if c["minimized_condition_number"] else "–", c["verdict"]]
                for c in r["structures"]]
        res[col] = {c["name"]: {"rank": c["rank"], "rga11": c["rga"][0][0] if c["rga"] else None}
                    for c in r["structures"]}
        sections += [f"### {col}: {ENDS[col][0]}, {ENDS[col][1]}", "",
                     table(["rank", "structure", "λ11", "NI", "γ*", "verdict"], rows), ""]
    md += ["## 2b. The same questions, screened by `plantwide screen`", "",
           "`plantwide screen --column` builds all seven inventory configurations of a column through the library "
           "(level loops moved, the column's quality loops opened, ratio stations for L/D and V/B), converges each "
           "from the plant's own steady state — the closed-loop flows, where the variants above hold the file's "
           f"nominal ones, hence λ11 of column 1 LB {fmt(res['column1']['LB']['rga11'])} here against "
           f"{fmt(s.results['column1']['LB']['rga11'])} above — and ranks them by λ11. Inside the recycle plant "
           "column 1's DB is regular (its feed follows D + B through the reactor level loop) and ranks first at "
           "steady state; column 2's DB is singular.", ""] + sections
    mvs = "column1.reflux,column1.bottoms,column2.reflux,column2.bottoms,fresh_A.F"
    p = s.pw("screen", BASE, "--cvs", ",".join(ENDS["column1"] + ENDS["column2"]), "--mvs", mvs,
             "--throughput", "fresh_A.F,column1.reflux,column1.bottoms",
             "--disturbances", "reactor_B.sp=+10%,feed_cooler.T_out=+3.4 K", "--watch", "bottoms1.x[B]=0:0.0025",
             "--candidates", "6", "--json", parse_json=True)
    rows = []
    for c in sorted(p["structures"], key=lambda c: (c["rank"] is None, c["rank"] or 0)):
        d = c["dynamic"]
        score = "–" if d is None else ("failed" if d["failure"] else fmt(d["score"]))
        rows.append([c["rank"] if c["rank"] is not None else "–", c["throughput"] or "–",
                     "; ".join(f"{q['cv']} ← {q['mv']} ({fmt(q['relative_gain'])})" for q in c["pairs"]),
                     fmt(c["niederlinski"]), fmt(c["rga_number"]), score])
    best = next(c for c in p["structures"] if c["rank"] == 1)
    res["pairings"] = {"best_throughput": best["throughput"], "best_mvs": [q["mv"] for q in best["pairs"]],
                       "enumerated": p["enumerated"], "pruned": p["pruned"]}
    s.results["screen"] = res
    md += ["### Plantwide pairings", "",
           "The four quality loops opened, the four column flows and fresh A as MVs, each of fresh A, column 1's "
           "reflux and its bottoms tried as the throughput manipulator (held while the others are paired); "
           f"{p['enumerated']} complete pairings reach the end of the branch and bound ({p['pruned']} partial ones cut "
           f"at a non-positive relative gain), {sum(c['passed'] for c in p['structures'])} pass NI > 0, DIC's necessary "
           "conditions and the fig. 6-6 band (column 1 bottoms B within 0 … 0.0025 over ± each disturbance with the CVs "
           "held); the best six by RGA number are tuned by BLT "
           "(1 min measurement delay) and stepped by the reactor B setpoint +10 % and the feed cooler +3.4 K (1 % of its 340 K). "
           "Dynamic score: mean IAE over the best candidate's, per CV and disturbance.", "",
           table(["rank", "throughput", "pairs (relative gain)", "NI", "RGA number", "dynamic score"], rows), "",
           f"Best: throughput **{best['throughput']}**, "
           + ", ".join(f"{q['cv']} ← {q['mv']}" for q in best["pairs"])
           + " — the structure chosen in §2 (LB on both columns) and §3 (P1), found from one command.", ""]


def production_rate(s, md):
    md += ["## 3. Where to set production", "",
           "Candidates: (P1) the fresh-A flow, reactor level by effluent; (P2) the reactor temperature "
           "setpoint with P1's inventory loops; (P3) the reactor effluent flow, reactor level by fresh A "
           "(a flow fixed inside the recycle loop, Luyben's rule). Gains of the R production, the recycle and "
           "column 1's boilup to each:", ""]

    def p3_edit(spec):
        c = spec["controllers"]
        c["reactor_level"] = {"type": "pid", "pv": "reactor.level", "output": "fresh_A.F", "sp": "2.5 m",
                              "kc": "100 kmol/h/m", "tau_i": "20 min", "action": "reverse"}
    p3 = s.variant("production_effluent_flow", p3_edit)
    outs = ["product.F@kmol/h", "recycle.F@kmol/h", "column1_sump.op@kmol/h"]
    cands = [("P1", BASE, "fresh_A.F@kmol/h"), ("P2", BASE, "reactor_temperature.sp"),
             ("P3", p3, "reactor.outflow@kmol/h")]
    rows, res = [], {}
    for name, f, u in cands:
        g = s.gains(f, [u], outs)
        if "gain" not in g:
            res[name] = {"error": g["error"]}
            rows.append([name, u.split("@")[0], "–", "–", "–", "–"])
            continue
        gp, gr, gv = (g["gain"][i][0] for i in range(3))
        res[name] = {"product": gp, "recycle": gr, "boilup": gv, "recycle_per_product": gr / gp}
        rows.append([name, u.split("@")[0], fmt(gp), fmt(gr), fmt(gv), fmt(gr / gp)])
    s.results["production"] = res
    md += [table(["", "manipulator", "∂R/∂u", "∂recycle/∂u", "∂V1/∂u", "Δrecycle per Δproduct"], rows), "",
           "(flows in kmol/h, temperatures in K.)", ""]
    pts = "5" if s.short else "9"
    s.pw("sensitivity", BASE, "--disturb", "fresh_A.F=-20%:+20%", "--outputs", "product.F@kmol/h,recycle.F@kmol/h",
         "--points", pts, "--csv", s.fig("snowball_P1.csv"), "--plot", s.fig("snowball_P1.png"))
    with open(s.fig("snowball_P1.csv")) as f:
        r = list(csv.DictReader(f))
    prod = [float(x["product.F [kmol/h]"]) for x in r]
    rec = [float(x["recycle.F [kmol/h]"]) for x in r]
    s.results["production_sweep"] = {"product": [prod[0], prod[-1]], "recycle": [rec[0], rec[-1]]}
    r1, sw = res["P1"], s.results["production_sweep"]
    md += [f"- **P2 is unworkable**: with the fresh A on flow control every mole of A leaves as R, so the reactor "
           f"temperature moves production by {fmt(res['P2']['product'])} kmol/h per K; it moves only the recycle "
           f"({fmt(res['P2']['recycle'])} kmol/h per K). The reactor temperature is the lever on the recycle, "
           "not on production.",
           f"- **P1 snowballs**: each extra kmol/h of product needs {fmt(r1['recycle_per_product'])} kmol/h more "
           f"recycle, because the reactor holdup and temperature are fixed and only higher reactant concentrations "
           f"can make more R. Over −20 … +20 % of fresh A the product goes from {fmt(sw['product'][0])} to "
           f"{fmt(sw['product'][1])} kmol/h and the recycle from {fmt(sw['recycle'][0])} to "
           f"{fmt(sw['recycle'][1])} kmol/h.",
           "- **P3**: " + (f"production follows the effluent flow at {fmt(res['P3']['product'])} kmol/h of R per kmol/h, "
                           f"with {fmt(res['P3']['recycle_per_product'])} kmol/h of recycle per kmol/h of product — "
                           "the same steady states as P1, reached the other way round: the fresh A follows the reactor "
                           "level. The difference is dynamic (a flow fixed inside the recycle loop cannot snowball), "
                           "but the production target is then set indirectly and the fresh feed, the plant's "
                           "measured raw-material rate, floats." if "error" not in res["P3"] else
                           f"`plantwide` finds no steady state of this structure from a cold start (*{res['P3']['error']}*); "
                           "it is not evaluated here."),
           "- Chosen: **P1**, production set by the fresh-A flow — the fresh feed is measured and fixed, and the "
           f"±10 % range it must cover costs about ±{fmt(abs(r1['recycle']) * 10)} kmol/h of recycle, within "
           "column 1's capacity; the snowball makes larger rate changes expensive in column 1 and is the reason "
           "to hold reactor temperature and holdup as the secondary production handles.", "",
           "![recycle against fresh A](two_column_plant/snowball_P1.png)", ""]


def sensitivity_66(s, md):
    md += ["## 4. Sensitivity of column 1's bottoms (book figure 6-6)", "",
           "Each disturbance is moved ±10 % with the chosen structure holding its controlled variables "
           "(stage temperatures, reactor temperature and B content), the plant re-converged at each point. "
           "Feed rate: the fresh-A flow (the column's feed moves with it); feed temperature: the column-1 "
           "feed cooler's outlet, ±10 % of its Celsius value; feed composition: the reactor's B content "
           "(the B fraction of column 1's feed).", ""]
    t_out = s.base["units"]["feed_cooler"]["T_out"]
    tc = float(t_out.split()[0]) - 273.15
    lo, hi = 273.15 + 0.9 * tc, 273.15 + 1.1 * tc
    pts = "5" if s.short else "11"
    s.pw("sensitivity", BASE, "--disturb", "fresh_A.F=-10%:+10%", "--disturb", f"feed_cooler.T_out={lo:.2f}K:{hi:.2f}K",
         "--disturb", "reactor_B.sp=-10%:+10%", "--outputs", "bottoms1.x[B]", "--points", pts,
         "--csv", s.fig("sensitivity.csv"), "--plot", s.fig("sensitivity.png"))
    with open(s.fig("sensitivity.csv")) as fh:
        rows = list(csv.DictReader(fh))
    by = {}
    for r in rows:
        by.setdefault(r["disturbance"], []).append(float(r["bottoms1.x[B] [-]"]))
    curves = {k: [min(v), max(v)] for k, v in by.items()}
    s.results["sensitivity"] = curves
    lo_all, hi_all = min(c[0] for c in curves.values()), max(c[1] for c in curves.values())
    table_rows = [[d, f"{fmt(curves[d][0])} … {fmt(curves[d][1])}"] for d in curves]
    md += [table(["disturbance (±10 %)", "x_B in column 1 bottoms"], table_rows), "",
           f"Base {fmt(by['fresh_A.F'][len(by['fresh_A.F']) // 2])}. Holding two stage temperatures does not hold the "
           "composition exactly (a four-component mixture has more than one composition at a given temperature): "
           f"over all three disturbances the bottoms B stays within {fmt(lo_all)} … {fmt(hi_all)}, i.e. the R "
           f"product's B content within about {fmt(100 * hi_all * 105.2 / 100.1)} % — the structure is acceptable at "
           "steady state. The feed rate is the disturbance the temperatures hold worst (the curve of fig. 6-6 with "
           "the largest slope). DV holds the same two temperatures, so at steady state its curves are the same; "
           "the two structures differ only dynamically (§5).", "",
           "![figure 6-6](two_column_plant/sensitivity.png)", ""]


def dv_flowsheet(s):
    """Column 1 under DV: drum level by reflux, sump level by bottoms, T21 by distillate, T11 by boilup."""
    if hasattr(s, "_dv"):
        return s._dv

    def edit(spec):
        set_levels(spec, "column1", "reflux", "bottoms", kc_drum="13 1/h", kc_sump="4 1/h")
        c = spec["controllers"]
        c["column1_top_T"] = {"type": "pid", "pv": "column1.T[21]", "output": "column1.distillate",
                              "sp": c["column1_top_T"]["sp"], "kc": "3 kmol/h/K", "tau_i": "30 min", "action": "reverse"}
        c["column1_bottom_T"] = {"type": "pid", "pv": "column1.T[11]", "output": "column1.boilup",
                                 "sp": c["column1_bottom_T"]["sp"], "kc": "30 kmol/h/K", "tau_i": "10 min",
                                 "action": "reverse"}
    s._dv = s.variant("column1_DV", edit)
    return s._dv


RECORD = ["effluent.T", "effluent.x[B]", {"path": "recycle.F", "unit": "kmol/h"},
          {"path": "feed_B.F", "unit": "kmol/h"}, "column1.T[21]", "column1.T[11]", "bottoms1.x[B]",
          "product.x[B]", "product.x[S]", {"path": "product.F", "unit": "kmol/h"}]


def scenario(s, name, duration, events, record=RECORD, interval="5 min", extra=None):
    sc = {"format_version": 1, "name": name, "duration": duration, "events": events,
          "analyzers": {"reactor_B": {"sample_time": "5 min", "dead_time": "5 min"},
                        "column2_top_S": {"sample_time": "5 min", "dead_time": "5 min"}},
          "record": {"interval": interval, "time_unit": "h", "paths": record}}
    sc.update(extra or {})
    return s.write(name.replace(" ", "_") + ".scenario.json", sc)


def dynamics(s, md):
    md += ["## 5. Dynamic responses of the two best column-1 structures", "",
           "LB (chosen) and DV on column 1, column 2 LB in both; analyzers on the reactor's B and on the "
           "product's S sample every 5 min with 5 min dead time. Upsets at 1 h: fresh A +10 % (production "
           "rate) and the reactor B setpoint +10 % (0.35 → 0.385, the composition of column 1's feed).", ""]
    dur = s.hours(16, 6)
    prod = scenario(s, "production step", dur, [{"type": "step", "at": "1 h", "path": "fresh_A.F", "by": "10 kmol/h"}])
    comp = scenario(s, "feed composition step", dur, [{"type": "step", "at": "1 h", "path": "reactor_B.sp", "by": 0.035}])
    rows, res = [], {}
    for tag, f in (("LB", BASE), ("DV", dv_flowsheet(s))):
        for up, sc in (("production", prod), ("composition", comp)):
            summ, cols = s.run(f, sc, f"dynamics_{tag}_{up}")
            paths = {p["path"]: p for p in summ["paths"]}
            xb = paths["bottoms1.x[B]"]
            rec = paths["recycle.F"]
            tt = paths["effluent.T"]
            res[f"{tag}_{up}"] = {"xB_max_dev": xb["max_deviation"], "xB_iae_h": xb["iae"] / 3600,
                                  "recycle_max_dev_kmol_h": rec["max_deviation"] * KMOLH,
                                  "reactor_T_max_dev": tt["max_deviation"],
                                  "settling_h": (paths["column1.T[11]"].get("settling_time") or float("nan")) / 3600}
            r = res[f"{tag}_{up}"]
            rows.append([tag, up, fmt(r["xB_max_dev"]), fmt(r["xB_iae_h"]), fmt(r["recycle_max_dev_kmol_h"]),
                         fmt(r["reactor_T_max_dev"]), fmt(r["settling_h"])])
    s.results["dynamics"] = res
    md += [table(["column 1", "upset", "max Δx_B bottoms", "IAE x_B [h]", "max Δrecycle [kmol/h]", "max ΔT reactor [K]",
                  "T11 settles [h]"], rows), "",
           "![LB, production step](two_column_plant/dynamics_LB_production.png)", ""]
    lb, dv = res["LB_production"], res["DV_production"]
    better = "LB" if lb["xB_iae_h"] <= dv["xB_iae_h"] else "DV"
    s.results["dynamics_better"] = better
    md += [f"Over the production step the bottoms impurity's IAE is {fmt(lb['xB_iae_h'])} h under LB and "
           f"{fmt(dv['xB_iae_h'])} h under DV; the recycle moves by at most {fmt(lb['recycle_max_dev_kmol_h'])} "
           f"(LB) and {fmt(dv['recycle_max_dev_kmol_h'])} kmol/h (DV). Two structures with similar steady-state "
           f"measures (§2) differ dynamically, as the book warns: {better} gives the smaller bottoms IAE, while LB "
           f"moves the recycle {fmt(dv['recycle_max_dev_kmol_h'] - lb['recycle_max_dev_kmol_h'])} kmol/h less. "
           "LB is kept: its bottoms control is comparable and it is the structure under which the reflux drum "
           "filters the recycle (§7).", ""]


def surge_tank(s, md):
    md += ["## 6. Is a surge tank needed between the columns?", "",
           "Under LB the bottoms temperature loop of column 1 moves the bottoms flow, which is column 2's feed. "
           "A 5 m³ tank (2 m² × 5 m, about 29 min of holdup at 105 kmol/h) with a P-only averaging level loop "
           "(40 kmol/h per m) is put between them and the plant run with and without it. Upset: column 1's "
           "feed temperature oscillating ±3 K with a 1 h period (a cycling upstream cooler).", ""]

    def edit(spec):
        spec["units"]["surge"] = {"type": "tank", "area": "2 m2", "height": "5 m", "P": "1.2 bar",
                                  "outflow": {"type": "flow", "flow": "105.2 kmol/h"}}
        spec["streams"]["bottoms1"] = {"from": "column1.bottoms", "to": "surge"}
        spec["streams"]["column2_feed"] = {"from": "surge", "to": "column2.feed"}
        spec["controllers"]["surge_level"] = {"type": "pid", "pv": "surge.level", "output": "surge.outflow",
                                              "sp": "2.5 m", "kc": "40 kmol/h/m", "action": "direct"}
    with_tank = s.variant("surge_tank", edit)
    dur = s.hours(8, 5)
    rec = [{"path": "bottoms1.F", "unit": "kmol/h"}, "product.x[B]", "product.x[S]", "column2.T[6]"]
    sc = scenario(s, "feed temperature cycling", dur,
                  [{"type": "sinusoid", "at": "1 h", "path": "feed_cooler.T_out", "amplitude": "3 K", "period": "1 h"}],
                  record=rec, interval="2 min")
    rec2 = rec + [{"path": "column2_feed.F", "unit": "kmol/h"}]
    sc2 = scenario(s, "feed temperature cycling with tank", dur,
                   [{"type": "sinusoid", "at": "1 h", "path": "feed_cooler.T_out", "amplitude": "3 K", "period": "1 h"}],
                   record=rec2, interval="2 min")
    _, a = s.run(BASE, sc, "surge_without")
    _, b = s.run(with_tank, sc2, "surge_with")
    t0 = float(dur.split()[0]) - 2.0
    t = a["time"]
    amp_in = amplitude(b["time"], b["bottoms1.F"], t0)
    amp_out = amplitude(b["time"], b["column2_feed.F"], t0)
    # A P-only level loop on a flow-set outflow is exactly first order: F_out/F_in = 1/(τs + 1) with
    # τ = A ρ / Kc (ρ the liquid molar density in the tank).
    v = s.steady(with_tank)
    rho = v["surge.M"] / v["surge.V"]
    tau_h = 2.0 * rho / 1000.0 / 40.0
    closed = 1.0 / math.sqrt(1.0 + (2 * math.pi * tau_h) ** 2)
    res = {"amp_bottoms_kmol_h": amp_in, "amp_column2_feed_kmol_h": amp_out, "attenuation": amp_out / amp_in,
           "first_order_closed_form": closed, "tau_h": tau_h,
           "product_xB_amp_without": amplitude(t, a["product.x[B]"], t0),
           "product_xB_amp_with": amplitude(b["time"], b["product.x[B]"], t0),
           "product_xS_amp_without": amplitude(t, a["product.x[S]"], t0),
           "product_xS_amp_with": amplitude(b["time"], b["product.x[S]"], t0)}
    s.results["surge"] = res
    md += [table(["", "without tank", "with tank"], [
        ["column 2 feed flow amplitude [kmol/h]", fmt(amplitude(t, a["bottoms1.F"], t0)), fmt(amp_out)],
        ["product x_S amplitude", fmt(res["product_xS_amp_without"]), fmt(res["product_xS_amp_with"])],
        ["product x_B amplitude", fmt(res["product_xB_amp_without"]), fmt(res["product_xB_amp_with"])]]), "",
        f"The tank passes {fmt(100 * res['attenuation'])} % of the flow swing (the first-order filter's closed form "
        f"1/√(1 + (ωτ)²) with τ = {fmt(60 * tau_h)} min gives {fmt(100 * closed)} %). The product's S content, "
        f"which column 2 controls, swings {fmt(res['product_xS_amp_without'] / max(res['product_xS_amp_with'], 1e-30))} "
        "times less with the tank. The B in the product comes from column 1's bottoms composition, which a "
        "tank mixes but does not remove. Conclusion: the tank is worth installing if column 1's bottoms flow "
        "cycles faster than about an hour; against slow (production-rate) changes column 2's own loops "
        "suffice.", "", "![with tank](two_column_plant/surge_with.png)", ""]


SIZE_SPEC = ["--disturbance", "fresh_A.F=+10%", "--level-band", "0.3 m", "--max-outflow-rate", "0.2 kmol/h/min"]
SIZE_CANDIDATES = "column1.drum,column1.sump,bottoms1"
KMOLH_MIN = 3.6 * 60  # mol/s² -> kmol/h per min


def surge_sizing(s, md):
    """Sections 6-7's questions for a production step, answered by `plantwide size`."""
    r = s.pw("size", BASE, "--candidates", SIZE_CANDIDATES, *SIZE_SPEC, "--json",
             "--plot", s.fig("surge_candidates.png"), parse_json=True)
    s.pw("size", BASE, "--vessel", "column1.drum", *SIZE_SPEC, "--plot", s.fig("drum_designs.png"))
    md += ["## 6b. Where is surge capacity needed for a production step? (`plantwide size`)", "",
           "`plantwide size --candidates` sizes each place for the same specification and ranks them by the band "
           "volume the optimal averaging controller needs there. The specification: production stepped by +10 % "
           "(fresh A 100 → 110 kmol/h), level within ±0.3 m of its setpoint, the flow leaving the vessel changing "
           "by at most 0.2 kmol/h per minute. The candidates: column 1's reflux drum (its distillate is the "
           "recycle to the reactor), its base (held by the boilup under LB), and a new surge tank on `bottoms1` "
           "between the columns. Each design (P, critically damped PI, optimal) is sized by its closed form and "
           "verified by a nonlinear run of the whole plant; a design the run shows short is corrected and run "
           "again.", ""]
    rows, res = [], {}
    for c in r["candidates"]:
        z = c.get("vessel") or c.get("candidate")
        if "designs" not in c:
            rows.append([z, "–", "–", "–", "–", "–", "–", "–"])
            res[z] = {"failure": c.get("failure")}
            continue
        d = {x["controller"]: x for x in c["designs"]}
        res[z] = {"kind": c["kind"], "flow_change_kmol_h": c["flow_change"] * KMOLH,
                  "current_rate_kmol_h_min": c["current"]["max_outflow_rate"] * KMOLH_MIN,
                  "needs_surge": c["needs_surge"], "liquid_molar_volume": c["liquid_molar_volume"],
                  "designs": {k: {"area": x["area"], "closed_form_area": x["closed_form_area"],
                                  "band_volume": x["band_volume"], "refinements": x["refinements"],
                                  "normal_holdup_kmol": (x.get("normal_holdup") or 0) / 1000,
                                  "meets": x["verified"]["meets"], "failure": x["verified"]["failure"],
                                  "max_level_deviation": x["verified"]["max_level_deviation"],
                                  "max_rate_kmol_h_min": x["verified"]["max_outflow_rate"] * KMOLH_MIN}
                              for k, x in d.items()}}
        verdict = lambda k: (fmt(d[k]["band_volume"]) + (" ✓" if d[k]["verified"]["meets"] else " ✗"))
        rows.append([f"{c['rank']}. {z}", c["kind"], fmt(res[z]["flow_change_kmol_h"]),
                     fmt(res[z]["current_rate_kmol_h_min"]), "yes" if c["needs_surge"] else "no",
                     verdict("optimal"), verdict("pi"), verdict("p")])
    s.results["sizing"] = res
    md += [table(["candidate", "kind", "Δ outflow [kmol/h]", "now: max rate [kmol/h/min]", "needs surge",
                  "optimal [m³]", "PI [m³]", "P [m³]"], rows), "",
           "Band volumes; ✓ the nonlinear run holds both limits, ✗ it does not (or stopped).", ""]
    md += sizing_conclusions(res)
    md += ["![candidates](two_column_plant/surge_candidates.png)", "",
           "![drum designs](two_column_plant/drum_designs.png)", ""]


def sizing_conclusions(res):
    """The answers, read from the sizing's numbers."""
    out = []
    b = res.get("bottoms1", {})
    if "designs" in b:
        need = "needs" if b["needs_surge"] else "does not need"
        out.append(f"**Between the columns.** Without a tank column 2's feed changes by at most "
                   f"{fmt(b['current_rate_kmol_h_min'])} kmol/h/min after the step (its flow moves by "
                   f"{fmt(b['flow_change_kmol_h'])} kmol/h, smoothed by column 1's own holdups and loops): the plant "
                   f"{need} a surge tank there for this specification. A tank that guaranteed it for a sharper upset "
                   f"would hold {fmt(b['designs']['optimal']['band_volume'])} m³ of band with the optimal controller, "
                   f"{fmt(b['designs']['p']['band_volume'])} m³ with P-only. (§6: against a 1-h cycle of column 1's "
                   "feed temperature a tank does attenuate the flow swing.)")
        out.append("")
    d = res.get("column1.drum", {})
    if "designs" in d:
        need = "too small" if d["needs_surge"] else "big enough"
        p = d["designs"]["p"]
        out.append(f"**Column 1's reflux drum.** With its file controller (P-only, 10 1/h on 40 kmol) the recycle to the "
                   f"reactor changes by up to {fmt(d['current_rate_kmol_h_min'])} kmol/h/min: the drum is {need} "
                   f"to keep the step out of the reactor at 0.2 kmol/h/min. The distillate must move by "
                   f"{fmt(d['flow_change_kmol_h'])} kmol/h; P-only needs a normal holdup of {fmt(p['normal_holdup_kmol'])} "
                   f"kmol (band {fmt(p['band_volume'])} m³), the optimal controller "
                   f"{fmt(d['designs']['optimal']['normal_holdup_kmol'])} kmol, against 40 kmol now: "
                   f"{fmt(p['normal_holdup_kmol'] / 40)} and "
                   f"{fmt(d['designs']['optimal']['normal_holdup_kmol'] / 40)} times the drum. Holding the recycle "
                   "that smooth is a large vessel; §7 shows the reactor's loops absorb what today's drum passes.")
        out.append("")
    sump = res.get("column1.sump", {})
    if "designs" in sump:
        failed = {k: x["failure"] for k, x in sump["designs"].items() if not x["meets"]}
        limits = "; ".join(f"{k}: {f.split('at a limit then: ', 1)[-1].removesuffix(')')}" for k, f in failed.items()
                           if f and "at a limit then" in f)
        out.append(f"**Column 1's base.** Under LB the base level is held by the boilup, which must move by "
                   f"{fmt(sump['flow_change_kmol_h'])} kmol/h — at 0.2 kmol/h/min a ramp of "
                   f"{fmt(sump['flow_change_kmol_h'] / 0.2 / 60)} h. {len(failed)} of 3 designs fail their "
                   f"run, the integrator stopping with loops at their limits ({limits}): slowing the boilup starves "
                   "column 1, whose bottoms-temperature loop closes the bottoms flow, and column 2 loses its feed. "
                   "The base is no place for surge in this structure; its level loop must stay tight.")
        out.append("")
    return out


def reflux_drum(s, md):
    md += ["## 7. Is column 1's reflux drum big enough?", "",
           "The distillate is the recycle; the drum's averaging level loop (P-only, tuned so that half the drum "
           "absorbs the whole nominal distillate flow: Kc = D/(M/2)) is all that stands between column 1's "
           "upsets and the reactor. Upset: column 1's feed temperature −5 K at 1 h.", ""]
    dur = s.hours(6, 3)
    sc = scenario(s, "column 1 feed temperature step", dur,
                  [{"type": "step", "at": "1 h", "path": "feed_cooler.T_out", "by": "-5 K"}],
                  record=[{"path": "recycle.F", "unit": "kmol/h"}, "column1.M[32]", "effluent.T", "effluent.x[B]",
                          "effluent.x[A]"], interval="1 min")
    d_nom = 197.6
    rows, res = [], {}
    for minutes in (1, 5, 15):
        m = d_nom / 60 * minutes * (272.3 + 197.6) / 197.6  # minutes of reflux + distillate
        kc = d_nom / (m / 2)
        sets = [f"column1.condenser_holdup={m:.2f}kmol", f"column1_drum.sp={m:.2f}kmol", f"column1_drum.kc={kc:.4f} 1/h"]
        summ, cols = s.run(BASE, sc, f"drum_{minutes}min", plot=(minutes == 5), sets=sets)
        p = {q["path"]: q for q in summ["paths"]}
        res[f"{minutes}min"] = {"holdup_kmol": m, "recycle_max_dev_kmol_h": abs(p["recycle.F"]["max_deviation"]) * KMOLH,
                                "reactor_T_max_dev": abs(p["effluent.T"]["max_deviation"]),
                                "reactor_xB_max_dev": abs(p["effluent.x[B]"]["max_deviation"])}
        r = res[f"{minutes}min"]
        rows.append([f"{minutes} min", fmt(m), fmt(kc), fmt(r["recycle_max_dev_kmol_h"]), fmt(r["reactor_T_max_dev"]),
                     fmt(r["reactor_xB_max_dev"])])
    s.results["drum"] = res
    md += [table(["drum (on L + D)", "holdup [kmol]", "Kc [1/h]", "max Δrecycle [kmol/h]", "max ΔT reactor [K]",
                  "max Δx_B reactor"], rows), "",
           f"The design drum (5 min) lets {fmt(res['5min']['recycle_max_dev_kmol_h'])} kmol/h of the upset through "
           f"to the reactor against {fmt(res['1min']['recycle_max_dev_kmol_h'])} kmol/h with a 1-minute drum; the "
           f"reactor temperature moves {fmt(res['5min']['reactor_T_max_dev'])} K. Tripling the drum to 15 min "
           f"cuts the recycle swing to {fmt(res['15min']['recycle_max_dev_kmol_h'])} kmol/h. The 5-minute drum is "
           "big enough: the reactor's temperature loop absorbs what passes.", "",
           "![drum 5 min](two_column_plant/drum_5min.png)", ""]


def safety(s, md):
    md += ["## 8. Reactor safety", "",
           "At 350 K the reactor is open-loop unstable: with the temperature loop in manual the heat released "
           "rises faster with temperature than the jacket removes it. Upset: at 0.5 h the temperature loop is put "
           "in manual (bumpless) and at 1 h the cooling water warms by 5 K.", ""]
    dur = s.hours(4, 2.5)
    rec = ["effluent.T", "reactor.Tj", "effluent.x[A]", "effluent.x[B]", "reactor.level",
           {"path": "recycle.F", "unit": "kmol/h"}, "reactor_temperature.op"]
    base_ev = [{"type": "mode", "at": "0.5 h", "controller": "reactor_temperature", "mode": "manual"},
               {"type": "step", "at": "1 h", "path": "reactor.coolant_T", "by": "5 K"}]
    sc = scenario(s, "cooling upset no action", dur, base_ev, record=rec, interval="30 s")
    summ, a = s.run(BASE, sc, "safety_no_action")
    trip_T = 360.0
    t_trip = crossing(a["time"], a["effluent.T"], trip_T)
    peak_none = max(a["effluent.T"])
    at = f"{t_trip:.4f} h"
    trip_ev = base_ev + [{"type": "feed_lost", "at": at, "unit": "fresh_A"},
                         {"type": "mode", "at": at, "controller": "reactor_B", "mode": "manual", "output": "0 kmol/h"},
                         {"type": "mode", "at": at, "controller": "reactor_temperature", "mode": "manual",
                          "output": "20 kg/s"}]
    # After the trip the columns are being shut down (not modelled): the runs end 45 min after it.
    dur_trip = f"{t_trip + 0.75:.4f} h"
    sc2 = scenario(s, "cooling upset trip", dur_trip, trip_ev, record=rec, interval="30 s")
    _, b = s.run(BASE, sc2, "safety_trip")
    # Maximum cooling alone, feeds kept: the quenched reactor stops converting, so the unreacted A and
    # B go round the recycle. Column 1's top loop is recorded to show where that ends.
    cool_ev = base_ev + [trip_ev[-1]]
    rec_cool = rec + [{"path": "column1.reflux", "unit": "kmol/h"}, {"path": "column1.distillate", "unit": "kmol/h"}]
    sc3 = scenario(s, "cooling upset max cooling only", dur_trip, cool_ev, record=rec_cool, interval="30 s")
    cool_summary, c = s.run(BASE, sc3, "safety_cooling_only", allow_fail=True)
    after = lambda cols: max(v for ti, v in zip(cols["time"], cols["effluent.T"]) if ti >= t_trip)  # noqa: E731
    res = {"trip_T": trip_T, "t_trip_h": t_trip, "peak_no_action": peak_none, "peak_trip": after(b),
           "final_trip": b["effluent.T"][-1], "peak_cooling_only": after(c), "min_cooling_only": min(c["effluent.T"]),
           "cooling_only_end_min": 60 * (c["time"][-1] - t_trip), "cooling_only_failed": "error" in cool_summary,
           "cooling_only_recycle_max": max(c["recycle.F"]), "cooling_only_reflux_end": c["column1.reflux"][-1],
           "cooling_only_level_max": max(c["reactor.level"])}
    md += [table(["action at " + fmt(trip_T) + " K", "peak T [K]", "T at the end [K]", "end of the run"], [
        ["none", fmt(peak_none), fmt(at_time(a, t_trip + 0.75)), "45 min after the crossing"],
        ["maximum cooling, feeds kept", fmt(res["peak_cooling_only"]), fmt(c["effluent.T"][-1]),
         f"{fmt(res['cooling_only_end_min'])} min after: column 1's reflux near zero" if res["cooling_only_failed"]
         else "45 min after"],
        ["stop both feeds + maximum cooling", fmt(res["peak_trip"]), fmt(res["final_trip"]), "45 min after"]]), "",
        f"The temperature crosses {fmt(trip_T)} K {fmt(60 * (t_trip - 1.0))} min after the upset. Without action it "
        f"runs away to {fmt(peak_none)} K and then cycles (runaway until the reactants are spent, quench, refill). "
        "Opening the coolant fully (20 kg/s) stops the excursion at "
        f"{fmt(res['peak_cooling_only'])} K, but with the feeds kept it quenches the reactor to "
        f"{fmt(res['min_cooling_only'])} K: the reaction stops, the unreacted A and B go round the recycle "
        f"(up to {fmt(res['cooling_only_recycle_max'])} kmol/h; the distillate valve is fully open at 400), the "
        f"reactor level rises to {fmt(res['cooling_only_level_max'])} m of 4 m, and column 1's top-temperature loop, "
        "flooded with light material, cuts the reflux from 272 to "
        f"{fmt(res['cooling_only_reflux_end'])} kmol/h"
        + (f": with the top section running dry the integration stops {fmt(res['cooling_only_end_min'])} min after "
           f"the action (`plantwide run`: *{cool_summary['error'].split('; the trends')[0]}*; the trends up to "
           "there are plotted below)." if res["cooling_only_failed"] else ".")
        + " Cooling alone trades a runaway for a plant upset; the trip must also **stop both feeds**. That holds "
        f"the peak at {fmt(res['peak_trip'])} K (a little above cooling alone: the cold fresh feeds no longer "
        "absorb heat) and leaves the columns to be shut down in order.", "",
        "![trip](two_column_plant/safety_trip.png)", "",
        "![maximum cooling only](two_column_plant/safety_cooling_only.png)", ""]
    # Can a recycle change start an excursion? Recycle flow: the drum level setpoint cut by a quarter
    # (the drum empties into the reactor); recycle composition: column 1's top temperature setpoint
    # +2 K (more B, less A in the recycle).
    md += ["**Can a recycle change start an excursion?** Two recycle upsets at 1 h, with the temperature loop "
           "in automatic and in manual: the drum level setpoint cut from 40 to 30 kmol (10 kmol of A and B "
           "pushed into the reactor over a few minutes) and column 1's top temperature setpoint +2 K (a "
           "B-richer recycle); each run lasts 1 h after the upset.", ""]
    rows, rr = [], {}
    for up, ev in (("recycle flow surge", {"type": "step", "at": "1 h", "path": "column1_drum.sp", "by": "-10 kmol"}),
                   ("recycle composition", {"type": "step", "at": "1 h", "path": "column1_top_T.sp", "by": "2 K"})):
        for mode in ("auto", "manual"):
            evs = [ev] if mode == "auto" else [{"type": "mode", "at": "0.5 h", "controller": "reactor_temperature",
                                                "mode": "manual"}, ev]
            name = f"recycle_{up.split()[1]}_{mode}"
            sc = scenario(s, name, "2 h", evs, record=rec, interval="30 s")
            _, cols = s.run(BASE, sc, name, plot=False)
            peak = max(cols["effluent.T"])
            low = min(cols["effluent.T"])
            rr[name] = {"peak": peak, "min": low}
            rows.append([up, mode, fmt(peak), fmt(low)])
    res["recycle"] = rr
    s.results["safety"] = res
    md += [table(["recycle upset", "temperature loop", "max T [K]", "min T [K]"], rows), "",
           "With the loop in automatic neither recycle upset moves the reactor by more than "
           f"{fmt(max(abs(rr[k]['peak'] - 350) for k in rr if k.endswith('auto')))} K. With the loop in manual "
           "the same upsets start an excursion, because the reactor is open-loop unstable: any change in the "
           "recycle — flow or composition — can start one unless the temperature loop is in automatic and has "
           "coolant in reserve (base coolant flow 6 kg/s of 20).", ""]


def commands(s, md):
    md += ["## Appendix: the commands", "",
           "Every number above comes from these `plantwide` runs (paths relative to `docs/`; the variant "
           "flowsheets and scenarios are in `docs/two_column_plant/inputs/`).", "", "```sh"]
    md += s.commands
    md += ["```", ""]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--plantwide", default=os.path.join(ROOT, "target", "release", "plantwide"),
                    help="the plantwide binary (default: target/release/plantwide)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs"), help="output directory (default docs/)")
    ap.add_argument("--short", action="store_true", help="shorter dynamic horizons and fewer sweep points")
    a = ap.parse_args()
    s = Study(os.path.abspath(a.plantwide), os.path.abspath(a.out), a.short)
    md = ["# The two-column reactor plant: a control study", "",
          "*Generated by `python3 tools/two_column_study.py` from `flowsheets/two_column_plant.json`"
          + (" (short horizons)" if a.short else "") + "; do not edit by hand.*", "",
          "The plant of *Practical Distillation Control* ch. 6 (Vogel, fig. 6-5): fresh A and B react in a cooled "
          "CSTR (A + B → R wanted, 2B → S not), column 1 returns unreacted A and B to the reactor and sends R and "
          "S to column 2, which makes R overhead. This report answers the chapter's questions in its order: which "
          "structure for each column, where to set production, how the chosen structure holds column 1's bottoms "
          "against disturbances (fig. 6-6), how the best structures behave dynamically, whether a surge tank is "
          "needed between the columns, whether column 1's reflux drum keeps column upsets out of the reactor, "
          "and how the reactor is kept safe. The base case is documented in `flowsheets/README.md`.", ""]
    base_case(s, md)
    column_structures(s, md)
    screening(s, md)
    production_rate(s, md)
    sensitivity_66(s, md)
    dynamics(s, md)
    surge_tank(s, md)
    surge_sizing(s, md)
    reflux_drum(s, md)
    safety(s, md)
    commands(s, md)
    with open(os.path.join(s.out, "two_column_plant.md"), "w") as f:
        f.write("\n".join(md))
    with open(os.path.join(s.dir, "results.json"), "w") as f:
        json.dump(s.results, f, indent=1)
    print(f"wrote {os.path.join(s.out, 'two_column_plant.md')} ({len(s.commands)} plantwide commands)")


if __name__ == "__main__":
    main()
