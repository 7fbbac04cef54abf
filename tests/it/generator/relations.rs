//! The relations, as pure functions of the commands' JSON: `Ok` when a relation holds, else what
//! breaks it. Each is tested here on a deliberately broken input, so none of them holds vacuously.

use approx::{abs_diff_eq, relative_eq};
use serde_json::{Map, Value};

/// Members of `v` matching `pattern` (`a/*/b`: `*` any key or index), with their paths.
pub fn matches<'v>(v: &'v Value, pattern: &str) -> Vec<(String, &'v Value)> {
    let mut found = vec![(String::new(), v)];
    for seg in pattern.split('/').filter(|s| !s.is_empty()) {
        let mut next = Vec::new();
        for (path, node) in found {
            let children: Vec<(String, &Value)> = match (node, seg) {
                (Value::Object(m), "*") => m.iter().map(|(k, c)| (k.clone(), c)).collect(),
                (Value::Array(a), "*") => a.iter().enumerate().map(|(i, c)| (i.to_string(), c)).collect(),
                (Value::Object(m), k) => m.get(k).map(|c| (k.to_string(), c)).into_iter().collect(),
                (Value::Array(a), k) => {
                    k.parse::<usize>().ok().and_then(|i| a.get(i)).map(|c| (k.to_string(), c)).into_iter().collect()
                }
                _ => Vec::new(),
            };
            next.extend(children.into_iter().map(|(k, c)| (format!("{path}/{k}"), c)));
        }
        found = next;
    }
    found
}

/// Every member named `key`, anywhere, with its path.
fn members<'v>(v: &'v Value, key: &str, path: &str, out: &mut Vec<(String, &'v Value)>) {
    match v {
        Value::Object(m) => {
            for (k, c) in m {
                let p = format!("{path}/{k}");
                if k == key {
                    out.push((p.clone(), c));
                }
                members(c, key, &p, out);
            }
        }
        Value::Array(a) => a.iter().enumerate().for_each(|(i, c)| members(c, key, &format!("{path}/{i}"), out)),
        _ => {}
    }
}

/// Exit 0 ⇔ every part succeeded: on exit 0 no `failed` list holds anything, no `failure` is
/// set and every promised number is there and finite (JSON writes NaN and ∞ as `null`); on exit
/// 2 with a JSON report, some part is marked failed.
pub fn honest(v: &Value, code: Option<i32>, promised: &[&str]) -> Result<(), String> {
    let mut failed = Vec::new();
    members(v, "failed", "", &mut failed);
    let mut failure = Vec::new();
    members(v, "failure", "", &mut failure);
    let listed: Vec<String> = failed
        .iter()
        .filter(|(_, f)| f.as_array().is_some_and(|a| !a.is_empty()))
        .map(|(p, f)| format!("{p} = {f}"))
        .chain(failure.iter().filter(|(_, f)| !f.is_null()).map(|(p, f)| format!("{p} = {f}")))
        .collect();
    match code {
        Some(0) => {
            if let Some(first) = listed.first() {
                return Err(format!("exit 0 with a failed part: {}", clip(first)));
            }
            for pattern in promised {
                let found = matches(v, pattern);
                if found.is_empty() {
                    return Err(format!("exit 0 without the promised `{pattern}`"));
                }
                if let Some((p, x)) = found.iter().find(|(_, x)| !x.as_f64().is_some_and(f64::is_finite)) {
                    return Err(format!("exit 0 with {p} = {x} where a number is promised"));
                }
            }
            Ok(())
        }
        Some(2) if listed.is_empty() => {
            Err("exit 2 with a report whose parts all succeeded (no `failed`, no `failure`)".into())
        }
        _ => Ok(()),
    }
}

fn clip(s: &str) -> String {
    s.chars().take(400).collect()
}

/// Two steady states (`values` maps, path → SI number) name the same variables with the same
/// values.
pub fn same_values(a: &Map<String, Value>, b: &Map<String, Value>, rel: f64, abs: f64) -> Result<(), String> {
    if let Some(k) = a.keys().find(|k| !b.contains_key(*k)).or_else(|| b.keys().find(|k| !a.contains_key(*k))) {
        return Err(format!("`{k}` is in one answer only ({} against {} values)", a.len(), b.len()));
    }
    let mut worst: Option<(f64, &str, f64, f64)> = None;
    for (k, x) in a {
        let (x, y) = (x.as_f64().unwrap_or(f64::NAN), b[k].as_f64().unwrap_or(f64::NAN));
        let excess = (x - y).abs() / (rel * x.abs().max(y.abs()) + abs);
        if (excess.is_nan() || excess > 1.0) && worst.is_none_or(|w| excess > w.0 || excess.is_nan()) {
            worst = Some((excess, k, x, y));
        }
    }
    match worst {
        None => Ok(()),
        Some((_, k, x, y)) => Err(format!(
            "`{k}`: {x:e} against {y:e} (relative difference {:.2e})",
            (x - y).abs() / x.abs().max(y.abs())
        )),
    }
}

/// A JSON matrix of numbers (`null` as NaN).
pub fn matrix(v: &Value) -> Option<Vec<Vec<f64>>> {
    v.as_array()?
        .iter()
        .map(|row| row.as_array().map(|r| r.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect()))
        .collect()
}

/// `b[i][j] = a[rows[i]][cols[j]]` to `rel` of the largest entry of the row in `a`.
pub fn permuted(a: &[Vec<f64>], b: &[Vec<f64>], rows: &[usize], cols: &[usize], rel: f64) -> Result<(), String> {
    if b.len() != rows.len() || b.iter().any(|r| r.len() != cols.len()) {
        return Err(format!(
            "shape {}×{} against {}×{}",
            b.len(),
            b.first().map_or(0, Vec::len),
            rows.len(),
            cols.len()
        ));
    }
    for (i, &r) in rows.iter().enumerate() {
        for (j, &c) in cols.iter().enumerate() {
            let allowed = rel * a[r][c].abs().max(b[i][j].abs()) + rel * natural_size(a, r, c) * 1e-3;
            if !abs_diff_eq!(a[r][c], b[i][j], epsilon = allowed) {
                return Err(format!("entry ({i}, {j}) is {:e}, the permuted entry ({r}, {c}) {:e}", b[i][j], a[r][c]));
            }
        }
    }
    Ok(())
}

/// The size element `(i, j)` of a gain matrix has by its units: `max_k |G_ik| · max_l |G_lj| /
/// max |G|`, its own size for a matrix of rank one (`G = u vᵀ`). Rows and columns carry units (a
/// gain per watt beside one per mol/s), so a row's largest element does not size the others; an
/// element far below its natural size is a structural zero computed to rounding, whose relative
/// digits are noise (8.35e-13 against 8.36e-13 for a composition's gain to a flow it does not
/// see, on a generated flash train).
pub fn natural_size(g: &[Vec<f64>], i: usize, j: usize) -> f64 {
    let row = g[i].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let col = g.iter().fold(0.0f64, |m, r| m.max(r.get(j).map_or(0.0, |x| x.abs())));
    let all = g.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if all > 0.0 { row * col / all } else { 0.0 }
}

/// A condition number `κ` is computed to a relative error of about `ε κ` (rounding moves the
/// smallest singular value by `ε ‖G‖`): two of them agree within that, or `rel` if larger.
pub fn condition_numbers_agree(a: f64, b: f64, rel: f64) -> bool {
    let rounding = 100.0 * f64::EPSILON * a.abs().max(b.abs());
    relative_eq!(a, b, epsilon = 0.0, max_relative = rel.max(rounding))
}

/// The rows of a relative gain array sum to 1.
pub fn rga_rows_sum_to_one(rga: &[Vec<f64>]) -> Result<(), String> {
    for (i, row) in rga.iter().enumerate() {
        let sum: f64 = row.iter().sum();
        let scale = row.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        if sum.is_nan() || (sum - 1.0).abs() > 1e-8 * scale {
            return Err(format!("row {i} of the RGA sums to {sum}"));
        }
    }
    Ok(())
}

/// Two gain matrices agree element by element to `rel` (an element small against its row's
/// largest is allowed `rel` of that largest, times `floor`).
pub fn gains_agree(a: &[Vec<f64>], b: &[Vec<f64>], rel: f64, floor: f64) -> Result<(), String> {
    let n = a.len();
    let rows: Vec<usize> = (0..n).collect();
    let cols: Vec<usize> = (0..a.first().map_or(0, Vec::len)).collect();
    if b.len() != n {
        return Err("shapes differ".into());
    }
    for i in 0..n {
        for &j in &cols {
            let allowed = rel * a[i][j].abs().max(b[i][j].abs()) + rel * floor * natural_size(a, i, j);
            if !abs_diff_eq!(a[i][j], b[i][j], epsilon = allowed) {
                return Err(format!("G[{i}][{j}]: {:e} against {:e}", a[i][j], b[i][j]));
            }
        }
    }
    let _ = rows;
    Ok(())
}

/// Two routes to the same gains by linear solves (`−C J⁻¹ B` on the sparse Jacobian against
/// `D − C A⁻¹ B` on the state space) agree element by element to `rel` of the element, or to the
/// rounding the solves carry into it. A backward-stable solve of a system of condition number `κ`
/// returns the response to input `j` with an error of about `ε κ` times its largest component, in
/// the units it works in, where output `i` has the size `scales[i]` (1 for a mole fraction, its
/// steady value for a flow): element `(i, j)` is then known to `ε κ s_i max_k |G_kj|/s_k`, however
/// small it is itself. A bottoms purity's gain to the reboiler duty, 1.5e-13 per W beside a
/// bottoms flow's 2.6e-5 per W (generated column 0x9d41ed2c17189e4b), is resolved to 2e-7 of
/// itself. `kappa` is a lower bound on `κ` that the caller measures (the spread of the state
/// matrix's eigenvalues), so the floor is no wider than the conditioning it follows from.
pub fn gains_agree_to_conditioning(
    a: &[Vec<f64>],
    b: &[Vec<f64>],
    rel: f64,
    scales: &[f64],
    kappa: f64,
) -> Result<(), String> {
    if b.len() != a.len() || scales.len() != a.len() || a.iter().zip(b).any(|(x, y)| x.len() != y.len()) {
        return Err("shapes differ".into());
    }
    let n_cols = a.first().map_or(0, Vec::len);
    for j in 0..n_cols {
        // The column's largest response in the solve's units (per unit of each output's scale).
        let largest = (0..a.len()).map(|k| a[k][j].abs().max(b[k][j].abs()) / scales[k]).fold(0.0, f64::max);
        for i in 0..a.len() {
            let rounding = f64::EPSILON * kappa * scales[i] * largest;
            let allowed = rel * a[i][j].abs().max(b[i][j].abs()) + rounding;
            if !abs_diff_eq!(a[i][j], b[i][j], epsilon = allowed) {
                return Err(format!(
                    "G[{i}][{j}]: {:e} against {:e} (rounding of the solves {rounding:e}, κ ≥ {kappa:e})",
                    a[i][j], b[i][j]
                ));
            }
        }
    }
    Ok(())
}

/// The condition number a state matrix has at least: the ratio of its largest to its smallest
/// eigenvalue modulus (`κ(A) = ‖A‖ ‖A⁻¹‖ ≥ |λ|_max/|λ|_min`); 1 without eigenvalues.
pub fn spectral_spread(eigenvalues: &[(f64, f64)]) -> f64 {
    let mags: Vec<f64> = eigenvalues.iter().map(|(re, im)| re.hypot(*im)).filter(|m| *m > 0.0).collect();
    let (lo, hi) = mags.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), m| (lo.min(*m), hi.max(*m)));
    if mags.is_empty() { 1.0 } else { hi / lo }
}

/// The first place where `a` and `b` differ beyond `rel`, members named in `ignore` left out.
pub fn first_difference(a: &Value, b: &Value, rel: f64, ignore: &[&str], path: &str) -> Option<String> {
    first_difference_beyond(a, b, &[], rel, ignore, path)
}

/// How many times the spread of the answers to the same question with its inputs moved by their
/// last bit another answer may differ by (a few samples of that spread see less than its largest).
const JITTER_FACTOR: f64 = 3.0;

/// [`first_difference`], each number allowed to differ by [`JITTER_FACTOR`] times as much as `a`'s differs from the
/// same number of the answers in `jitter` (if more than `rel`): the same question with its inputs
/// moved by their last bit, so the answer's own conditioning. An answer whose figures move by 1 %
/// when a limit moves by 10⁻¹⁶ is ill-conditioned, which this does not judge; what it judges is
/// whether asking in other units moves them more than that.
pub fn first_difference_beyond(
    a: &Value,
    b: &Value,
    jitter: &[&Value],
    rel: f64,
    ignore: &[&str],
    path: &str,
) -> Option<String> {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys: std::collections::BTreeSet<&String> = x.keys().chain(y.keys()).collect();
            keys.into_iter().filter(|k| !ignore.contains(&k.as_str())).find_map(|k| match (x.get(k), y.get(k)) {
                (Some(p), Some(q)) => {
                    let j: Vec<&Value> = jitter.iter().filter_map(|j| j.get(k)).collect();
                    first_difference_beyond(p, q, &j, rel, ignore, &format!("{path}/{k}"))
                }
                _ => Some(format!("{path}/{k} is in one only")),
            })
        }
        (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
            x.iter().zip(y).enumerate().find_map(|(i, (p, q))| {
                let j: Vec<&Value> = jitter.iter().filter_map(|j| j.get(i)).collect();
                first_difference_beyond(p, q, &j, rel, ignore, &format!("{path}/{i}"))
            })
        }
        (Value::Number(p), Value::Number(q)) => {
            let (p, q) = (p.as_f64().unwrap_or(f64::NAN), q.as_f64().unwrap_or(f64::NAN));
            let spread = jitter
                .iter()
                .filter_map(|j| j.as_f64())
                .map(|j| (p - j).abs() / p.abs().max(j.abs()).max(1e-300))
                .fold(0.0, f64::max);
            let allowed = rel.max(JITTER_FACTOR * spread);
            (!relative_eq!(p, q, epsilon = 1e-300, max_relative = allowed)).then(|| {
                let moved =
                    if spread > 0.0 { format!(" (a last-bit change moves it {spread:.1e})") } else { String::new() };
                format!("{path}: {p:e} against {q:e}{moved}")
            })
        }
        _ => (a != b).then(|| format!("{path}: {} against {}", clip(&a.to_string()), clip(&b.to_string()))),
    }
}

/// A pairing screen's candidate as a comparable key: throughput and sorted pairs.
fn candidate_key(s: &Value) -> String {
    let mut pairs: Vec<String> = s["pairs"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|p| format!("{}<-{}", p["cv"].as_str().unwrap_or("?"), p["mv"].as_str().unwrap_or("?")))
                .collect()
        })
        .unwrap_or_default();
    pairs.sort();
    format!("{} [{}]", s["throughput"].as_str().unwrap_or("-"), pairs.join(", "))
}

/// Two pairing screens of the same CVs and MVs listed in other orders found the same candidates,
/// with the same relative gains, filters and ranks.
pub fn same_pairings(a: &Value, b: &Value) -> Result<(), String> {
    let table = |v: &Value| -> std::collections::BTreeMap<String, Value> {
        let list = v["structures"].as_array().cloned().unwrap_or_default();
        list.iter()
            .map(|s| {
                let mut gains: Vec<(String, f64)> = s["pairs"]
                    .as_array()
                    .map(|a| a.iter().map(|p| (p["cv"].to_string(), p["relative_gain"].as_f64().unwrap_or(f64::NAN))).collect())
                    .unwrap_or_default();
                gains.sort_by(|x, y| x.0.cmp(&y.0));
                let row = serde_json::json!({"passed": s["passed"], "rank": s["rank"], "rga_number": s["rga_number"],
                    "niederlinski": s["niederlinski"], "relative_gains": gains.iter().map(|g| g.1).collect::<Vec<_>>()});
                (candidate_key(s), row)
            })
            .collect()
    };
    let (ta, tb) = (table(a), table(b));
    if ta.keys().ne(tb.keys()) {
        return Err(format!(
            "candidates {:?} against {:?}",
            ta.keys().collect::<Vec<_>>(),
            tb.keys().collect::<Vec<_>>()
        ));
    }
    for (k, x) in &ta {
        if let Some(d) = first_difference(x, &tb[k], 1e-6, &[], k) {
            return Err(d);
        }
    }
    Ok(())
}

/// A ranking agrees with its own dynamic evidence: the candidate ranked first has the best score
/// of those whose dynamic test completed, or the verdict says the evidence disagrees.
pub fn ranking_follows_evidence(v: &Value) -> Result<(), String> {
    let list = v["structures"].as_array().cloned().unwrap_or_default();
    let completed = |s: &Value| {
        let d = &s["dynamic"];
        d.is_object()
            && d["failure"].is_null()
            && d["score"].as_f64().is_some()
            && d["runs"].as_array().is_some_and(|r| r.iter().all(|r| r["failure"].is_null()))
    };
    let tested: Vec<&Value> = list.iter().filter(|s| completed(s)).collect();
    let Some(best) = tested
        .iter()
        .min_by(|a, b| a["dynamic"]["score"].as_f64().unwrap().total_cmp(&b["dynamic"]["score"].as_f64().unwrap()))
    else {
        return Ok(());
    };
    let first = list.iter().find(|s| s["rank"].as_u64() == Some(1));
    let verdict = v["verdict"].as_str().unwrap_or("");
    let says = verdict.contains("disagree") || verdict.contains("does not");
    match first {
        Some(f) if std::ptr::eq(f, *best) || (completed(f) && f["dynamic"]["score"] == best["dynamic"]["score"]) => {
            Ok(())
        }
        _ if says => Ok(()),
        Some(f) => Err(format!(
            "rank 1 is {} (score {}), the best dynamic score is {}'s ({}); the verdict: {}",
            candidate_key(f),
            f["dynamic"]["score"],
            candidate_key(best),
            best["dynamic"]["score"],
            clip(verdict)
        )),
        None => Err(format!("{} candidates tested, none ranked first; the verdict: {}", tested.len(), clip(verdict))),
    }
}

/// A run's conservation entry is within its tolerance.
pub fn conserved(run: &Value) -> Result<(), String> {
    let c = &run["conservation"];
    let (worst, tol) = (c["max_relative_error"].as_f64(), c["tolerance"].as_f64());
    match (worst, tol) {
        (Some(w), Some(t)) if w <= t => Ok(()),
        (Some(w), Some(t)) => {
            Err(format!("conservation error {w:e} over its tolerance {t:e} ({})", clip(&c["balances"].to_string())))
        }
        _ => Err(format!("no conservation figures: {}", clip(&c.to_string()))),
    }
}

/// A step and a very short ramp to the same value end at the same state. A ramp of `d` seconds
/// is, to first order, the step delayed by `d/2`, so a path still moving at the end (at `slope`
/// per second, from the step's record) ends `slope·d/2` behind: each path's final value agrees with
/// that to `rel` of how far it moved, plus a tenth of the correction (the slope is a backward
/// difference over one record interval).
pub fn same_end(step: &Value, ramp: &Value, slopes: &[(String, f64)], d: f64, rel: f64) -> Result<(), String> {
    let (a, b) = (step["paths"].as_array(), ramp["paths"].as_array());
    let (Some(a), Some(b)) = (a, b) else { return Err("no `paths` summary".into()) };
    if a.len() != b.len() {
        return Err(format!("{} against {} recorded paths", a.len(), b.len()));
    }
    for (p, q) in a.iter().zip(b) {
        let num = |v: &Value, k: &str| v[k].as_f64().unwrap_or(f64::NAN);
        let (x, y, x0) = (num(p, "last"), num(q, "last"), num(p, "initial"));
        let name = p["path"].as_str().unwrap_or("");
        let slope = slopes.iter().find(|(n, _)| n == name).map_or(0.0, |s| s.1);
        let (shift, moved) = (slope * d / 2.0, (x - x0).abs());
        let expected = x - shift;
        let allowed = rel * 1e-2 * expected.abs().max(y.abs()) + rel * moved + 0.1 * shift.abs() + 1e-12;
        if !abs_diff_eq!(expected, y, epsilon = allowed) {
            return Err(format!(
                "{name}: the step ends at {x:e} (moving {slope:e}/s, so a {d} s ramp is expected at {expected:e}), the ramp at {y:e} (moved {moved:e})"
            ));
        }
    }
    Ok(())
}

/// The slope [per second] of each column of a run's CSV over its last record interval (the
/// header's `time [min]` or `time [s]`).
pub fn end_slopes(csv: &str) -> Vec<(String, f64)> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let rows: Vec<Vec<f64>> = lines.map(|l| l.split(',').map(|c| c.parse().unwrap_or(f64::NAN)).collect()).collect();
    let per_s = if header.first().is_some_and(|h| h.contains("[min]")) { 60.0 } else { 1.0 };
    let [.., r0, r1] = rows.as_slice() else { return Vec::new() };
    let dt = (r1[0] - r0[0]) * per_s;
    header
        .iter()
        .enumerate()
        .skip(1)
        .map(|(j, h)| (h.split(" [").next().unwrap_or(h).to_string(), (r1[j] - r0[j]) / dt))
        .collect()
}

#[cfg(test)]
mod tests {
    /// A rank-one matrix's elements are their own natural size; an element of units-mixed gains
    /// far below it is compared to rounding of that size, and a real difference still shows.
    #[test]
    fn gains_are_compared_at_the_size_their_units_give() {
        let g = vec![vec![2e-3, 4e-9, 6e-6], vec![1e-1, 2e-7, 3e-4]];
        for (i, row) in g.iter().enumerate() {
            for (j, x) in row.iter().enumerate() {
                assert!((natural_size(&g, i, j) - x).abs() <= 1e-15 * x, "({i}, {j})");
            }
        }
        let mut noisy = g.clone();
        noisy[0][1] = 4e-9;
        noisy[1][1] = 2e-7 * (1.0 + 1e-3);
        assert!(gains_agree(&g, &noisy, 1e-4, 1e-3).is_err(), "a 1e-3 difference of a full-size element");
        let mut zero = g.clone();
        zero[0][2] = 8.35e-13;
        let mut zero2 = zero.clone();
        zero2[0][2] = 8.36e-13;
        assert!(gains_agree(&zero, &zero2, 1e-4, 1e-3).is_ok(), "a structural zero's rounding");
        assert!(condition_numbers_agree(7.251842e16, 7.251841e16, 1e-7));
        assert!(!condition_numbers_agree(12.0, 12.1, 1e-7));
    }

    use super::*;
    use serde_json::json;

    #[test]
    fn honesty_catches_a_failed_part_a_null_number_and_an_empty_failure_list() {
        let good = json!({"gain": [[1.0, 2.0]], "failed": [], "x": {"failure": null}});
        assert!(honest(&good, Some(0), &["gain/*/*"]).is_ok());
        assert!(honest(&json!({"failed": ["run 1: diverged"]}), Some(0), &[]).is_err());
        assert!(honest(&json!({"a": [{"failure": "no crossover"}]}), Some(0), &[]).is_err());
        assert!(honest(&json!({"gain": [[1.0, null]]}), Some(0), &["gain/*/*"]).is_err());
        assert!(honest(&json!({"gain": []}), Some(0), &["rga/*/*"]).is_err());
        assert!(honest(&json!({"failed": []}), Some(2), &[]).is_err());
        assert!(honest(&json!({"failed": ["x"]}), Some(2), &[]).is_ok());
    }

    #[test]
    fn steady_states_must_match_value_for_value() {
        let a: Map<String, Value> = serde_json::from_value(json!({"s.F": 1.0, "s.x[a]": 1e-7})).unwrap();
        let mut b = a.clone();
        assert!(same_values(&a, &b, 1e-9, 1e-12).is_ok());
        b.insert("s.x[a]".into(), json!(1.01e-7));
        assert!(same_values(&a, &b, 1e-9, 1e-12).unwrap_err().contains("s.x[a]"));
        b.remove("s.x[a]");
        assert!(same_values(&a, &b, 1e-9, 1e-12).is_err());
    }

    #[test]
    fn a_permutation_must_be_the_right_one() {
        let g = vec![vec![1.0, 2.0], vec![3.0, 4.0]];
        let swapped = vec![vec![4.0, 3.0], vec![2.0, 1.0]];
        assert!(permuted(&g, &swapped, &[1, 0], &[1, 0], 1e-12).is_ok());
        assert!(permuted(&g, &swapped, &[0, 1], &[1, 0], 1e-12).is_err());
        assert!(rga_rows_sum_to_one(&[vec![2.0, -1.0], vec![-1.0, 2.0]]).is_ok());
        assert!(rga_rows_sum_to_one(&[vec![2.0, -1.5]]).is_err());
        assert!(gains_agree(&g, &[vec![1.0, 2.0], vec![3.0, 4.001]], 1e-4, 1e-3).is_err());
    }

    #[test]
    fn a_ranking_must_follow_its_dynamic_scores_or_say_so() {
        let cand = |cv: &str, rank: u64, score: f64| {
            json!({"throughput": null, "pairs": [{"cv": cv, "mv": "m", "relative_gain": 1.0}], "rank": rank,
                   "dynamic": {"score": score, "failure": null, "runs": [{"failure": null}]}})
        };
        let fine = json!({"structures": [cand("a", 1, 1.0), cand("b", 2, 1.4)], "verdict": "recommended: a"});
        assert!(ranking_follows_evidence(&fine).is_ok());
        let wrong = json!({"structures": [cand("a", 1, 1.4), cand("b", 2, 1.0)], "verdict": "recommended: a"});
        assert!(ranking_follows_evidence(&wrong).is_err());
        let said =
            json!({"structures": [cand("a", 1, 1.4), cand("b", 2, 1.0)], "verdict": "…; the evidence disagrees: …"});
        assert!(ranking_follows_evidence(&said).is_ok());
        assert!(same_pairings(&fine, &fine).is_ok());
        let swapped = json!({"structures": [cand("a", 2, 1.0), cand("b", 1, 1.4)], "verdict": "recommended: b"});
        assert!(same_pairings(&fine, &swapped).is_err());
    }

    #[test]
    fn runs_must_conserve_and_a_step_must_end_where_its_ramp_does() {
        assert!(conserved(&json!({"conservation": {"max_relative_error": 1e-12, "tolerance": 1e-9}})).is_ok());
        assert!(conserved(&json!({"conservation": {"max_relative_error": 1e-6, "tolerance": 1e-9}})).is_err());
        let run = |last: f64| json!({"paths": [{"path": "x", "initial": 1.0, "last": last}]});
        assert!(same_end(&run(2.0), &run(2.0 + 1e-9), &[], 1.0, 1e-5).is_ok());
        assert!(same_end(&run(2.0), &run(2.01), &[], 1.0, 1e-5).is_err());
        // Still rising at 1e-3/s: a one-second ramp ends 5e-4 behind the step, not level with it.
        let slopes = end_slopes("time [min],x [1]\n0,1.5\n1,1.94\n2,2.0\n");
        assert!((slopes[0].1 - 1e-3).abs() < 1e-12, "{slopes:?}");
        assert!(same_end(&run(2.0), &run(2.0 - 5e-4), &slopes, 1.0, 1e-5).is_ok());
        assert!(same_end(&run(2.0), &run(2.0), &slopes, 1.0, 1e-5).is_err());
        let a = json!({"name": "a", "gain": [[1.0]]});
        assert!(first_difference(&a, &json!({"name": "b", "gain": [[1.0]]}), 1e-9, &["name"], "").is_none());
        assert!(first_difference(&a, &json!({"name": "a", "gain": [[1.1]]}), 1e-9, &["name"], "").is_some());
    }
}
