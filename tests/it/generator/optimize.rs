//! `optimize` and `select` on a plant we did not write, against answers known in closed form.
//!
//! The plant gets a tracking objective: `track = ((B − t)/s)²`, with `B` the bottoms flow, `t` the
//! bottoms flow `steady` finds at 1.05 × the throughput and `s` = 1 mol/s, and the throughput as
//! the degree of freedom within ± 20 %. Then, whatever the plant:
//! - `optimize` finds the throughput 1.05 × nominal (the bottoms flow is monotone in it, the
//!   quality loops holding the products' compositions) and `track` = 0 there;
//! - its reduced Hessian is `2 g²/s²`, `g = ∂B/∂F` (`gains` at the optimum, SI);
//! - `select` with the top setpoint as the disturbance: `Juu = 2 g²/s²`, `Jud = 2 g g_d/s²`, and
//!   holding `B` itself loses exactly `(e/s)²` to its implementation error `e` (the optimal
//!   sensitivity of `B` is zero: controlling it keeps `track` at 0 whatever the disturbance),
//!   and nothing on the nonlinear plant as the disturbance moves.

use serde_json::Value;

use super::cx::Cx;
use super::doc::{J, obj};
use super::exec::Output;
use super::relations::matrix;

/// The bottoms flow's path.
fn bottoms(cx: &Cx<'_>) -> String {
    format!("{}.F", cx.case.roles.products[1])
}

/// The plant with the tracking tag and parameters written in.
fn tracking_plant(cx: &Cx<'_>, target: f64) -> J {
    let mut d = cx.case.closed.clone();
    let parameters = obj([("t_track", J::S(format!("{target:.17e} mol/s"))), ("s_track", J::S("1 mol/s".into()))]);
    d.set(&["parameters"], parameters);
    let tag = J::S(format!("(({} - t_track)/s_track)^2", bottoms(cx)));
    match d.get("tags") {
        Some(_) => d.set(&["tags", "track"], tag),
        None => d.set(&["tags"], obj([("track", tag)])),
    }
    d
}

/// `gains` of the tracking plant at the throughput `f` (SI): ∂B/∂(throughput, disturbance).
fn bottoms_gains(cx: &mut Cx<'_>, file: &str, f: f64, disturbance: &str) -> Option<(Output, Vec<f64>)> {
    let r = &cx.case.roles;
    let set = format!("{}={f:.17e}", r.throughput);
    let inputs = format!("{},{disturbance}", r.throughput);
    let out = cx.pw(&["gains", file, "--inputs", &inputs, "--outputs", &bottoms(cx), "--set", &set, "--json"]);
    let v = cx.succeeded(&out, "gains (tracking plant)", true, &["gain/*/*"])?;
    let g = matrix(&v["gain"])?;
    Some((out, g.first()?.clone()))
}

/// `|a − b| ≤ rel·|b| + abs`.
fn near(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * b.abs() + abs
}

/// The tracking optimum and the self-optimizing analysis of holding the bottoms flow.
pub fn optimize_and_select(cx: &mut Cx<'_>) {
    let r = cx.case.roles.clone();
    let f0 = r.throughput_si;
    let set = format!("{}={:.17e}", r.throughput, 1.05 * f0);
    let out = cx.pw(&["steady", "plant.json", "--set", &set, "--json"]);
    let Some(v) = cx.succeeded(&out, "steady (throughput +5 %)", true, &["values/*"]) else { return };
    let Some(target) = v["values"][bottoms(cx)].as_f64() else { return };
    let file = cx.doc("tracking.json", &tracking_plant(cx, target));
    let vary = format!("{}={:.17e}:{:.17e}", r.throughput, 0.8 * f0, 1.2 * f0);
    let opt = cx.pw(&["optimize", &file, "--objective", "track", "--vary", &vary, "--json"]);
    let promised = ["objective", "values/*", "kkt_residual", "reduced_hessian/matrix/*/*"];
    let Some(o) = cx.succeeded(&opt, "optimize (tracking objective)", true, &promised) else { return };
    let f_opt = o["values"][&r.throughput].as_f64().unwrap_or(f64::NAN);
    let j = o["objective"].as_f64().unwrap_or(f64::NAN);
    cx.check(
        near(f_opt, 1.05 * f0, 1e-6, 0.0) && j.abs() < 1e-10,
        "optimize: misses a known optimum",
        &[&out, &opt],
        || format!("throughput {f_opt:e} against {:e}, track {j:e} against 0", 1.05 * f0),
    );
    let top_sp = format!("{}.sp", r.quality[0]);
    let Some((gout, g)) = bottoms_gains(cx, &file, f_opt, &top_sp) else { return };
    let juu = o["reduced_hessian"]["matrix"][0][0].as_f64().unwrap_or(f64::NAN);
    cx.check(
        near(juu, 2.0 * g[0] * g[0], 1e-6, 0.0),
        "optimize: reduced Hessian is not 2 g²/s²",
        &[&opt, &gout],
        || format!("{juu:e} against 2 g² = {:e}", 2.0 * g[0] * g[0]),
    );
    select_bottoms(cx, (&file, &vary), &top_sp, (&g, target));
}

/// `select` of the bottoms flow against the distillate flow, the top setpoint disturbed.
fn select_bottoms(cx: &mut Cx<'_>, (file, vary): (&str, &str), top_sp: &str, (g, target): (&[f64], f64)) {
    let r = cx.case.roles.clone();
    let (b, d) = (bottoms(cx), format!("{}.F", r.products[0]));
    let xd = cx.value(&format!("{}.x[{}]", r.products[0], r.light)).unwrap_or(0.99);
    let delta = 0.1 * (1.0 - xd).max(1e-4);
    let e = 1e-3 * r.throughput_si;
    let (dist, errors) = (format!("{top_sp}=±{delta:e}"), format!("{b}=±{e:e} mol/s,{d}=±{e:e} mol/s"));
    let cands = format!("{b},{d}");
    let args = [
        "select",
        file,
        "--objective",
        "track",
        "--vary",
        vary,
        "--disturbances",
        &dist,
        "--candidates",
        &cands,
        "--errors",
        &errors,
        "--size",
        "1",
        "--json",
    ];
    let out = cx.pw(&args);
    let promised =
        ["local_model/Juu/*/*", "local_model/Jud/*/*", "subsets/*/worst_case_loss", "subsets/*/nonlinear/*/loss"];
    let Some(v) = cx.succeeded(&out, "select (tracking objective)", true, &promised) else { return };
    let m = &v["local_model"];
    let (juu, jud) = (m["Juu"][0][0].as_f64().unwrap_or(f64::NAN), m["Jud"][0][0].as_f64().unwrap_or(f64::NAN));
    let (want_uu, want_ud) = (2.0 * g[0] * g[0], 2.0 * g[0] * g[1]);
    // Where the setpoint barely moves B (g_d at rounding), Jud is rounding too: judged against
    // 2|g|·B/xD, what a gain of B's own size per unit of the setpoint would give, to 1e-9.
    let rounding = 1e-9 * 2.0 * g[0].abs() * target.abs() / xd.abs().max(1e-12);
    cx.check(
        near(juu, want_uu, 1e-6, 0.0) && near(jud, want_ud, 1e-6, rounding),
        "select: Juu, Jud are not 2g², 2g·g_d",
        &[&out],
        || format!("Juu {juu:e} against {want_uu:e}, Jud {jud:e} against {want_ud:e}"),
    );
    let held = v["subsets"].as_array().and_then(|s| s.iter().find(|s| holds_only(s, &b)));
    let Some(held) = held else {
        cx.check(false, "select: the bottoms flow is not among the ranked subsets", &[&out], || v.to_string());
        return;
    };
    let loss = held["worst_case_loss"].as_f64().unwrap_or(f64::NAN);
    cx.check(near(loss, e * e, 1e-6, 0.0), "select: holding the tracked flow does not lose (e/s)²", &[&out], || {
        format!("loss {loss:e} against {:e}", e * e)
    });
    let nonlinear = nonlinear_losses(held);
    cx.check(
        !nonlinear.is_empty() && nonlinear.iter().all(|l| l.abs() < 1e-9),
        "select: holding the tracked flow loses on the nonlinear plant",
        &[&out],
        || format!("{nonlinear:?}"),
    );
}

/// The subset that holds `path` alone.
fn holds_only(s: &Value, path: &str) -> bool {
    s["measurements"].as_array().is_some_and(|m| m.len() == 1 && m[0].as_str().is_some_and(|p| p.starts_with(path)))
}

/// The nonlinear losses of a subset, every disturbance and sign.
fn nonlinear_losses(s: &Value) -> Vec<f64> {
    s["nonlinear"].as_array().map_or(Vec::new(), |p| p.iter().map(|p| p["loss"].as_f64().unwrap_or(f64::NAN)).collect())
}
