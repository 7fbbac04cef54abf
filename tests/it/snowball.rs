//! The snowball effect (Luyben 1994; validation-cases.md §4) through `plantwide sensitivity`:
//! structure 1 (fresh feed fixed, reactor holdup constant) snowballs and its recycle follows the
//! closed form of the same model; structure 2 (reactor effluent fixed, level by fresh feed) keeps
//! the column load constant when production moves.

use crate::harness;

const XD: f64 = 0.95;
const XB: f64 = 0.0105;

/// Run a sweep and return its rows as (change %, [outputs…]).
fn sweep(file: &str, disturb: &str, outputs: &str, points: &str) -> Vec<(f64, Vec<f64>)> {
    let csv =
        std::env::temp_dir().join(format!("snowball-{}-{}.csv", std::process::id(), file.replace(['/', '.'], "_")));
    let out = harness::command()
        .args([
            "sensitivity",
            &harness::flowsheet(file),
            "--disturb",
            disturb,
            "--outputs",
            outputs,
            "--points",
            points,
        ])
        .arg("--csv")
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let _ = std::fs::remove_file(&csv);
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[3].parse().unwrap(), f[4..].iter().map(|v| v.parse().unwrap()).collect())
        })
        .collect()
}

/// Reactor composition z implied by the recycle D and fresh feed F0 through the column balance
/// (xD, xB held by the column's composition loops).
fn z_from(d: f64, f0: f64) -> f64 {
    (d * XD + f0 * XB) / (d + f0)
}

#[test]
fn fixed_fresh_feed_snowballs_as_the_closed_form_says() {
    let rows = sweep("reactor_column_recycle.json", "fresh.F=-20%:+20%", "feed.F@lbmol/h,recycle.F@lbmol/h", "9");
    let base = rows.iter().find(|(c, _)| c.abs() < 1e-9).unwrap();
    let (f0_b, d_b) = (base.1[0], base.1[1]);
    assert!((f0_b - 239.5).abs() < 1e-9 && (d_b - 260.5).abs() < 0.1 * 260.5 / 100.0, "design point D = {d_b}");
    // Reaction A → B consumes k·M·z; with M fixed, the A balance F0 (1 − xB) = k M z gives z, and
    // the column balance D = F0 (z − xB)/(xD − z) gives the recycle.
    let km = f0_b * (1.0 - XB) / z_from(d_b, f0_b);
    for (change, v) in &rows {
        let (f0, d) = (v[0], v[1]);
        let z = f0 * (1.0 - XB) / km;
        let d_closed = f0 * (z - XB) / (XD - z);
        assert!((d - d_closed).abs() < 0.005 * d_closed, "{change} %: D = {d}, closed form {d_closed}");
    }
    // The snowball: +20 % fresh feed raises the recycle by far more than 20 %.
    let top = rows.last().unwrap();
    assert!(top.1[1] / d_b > 1.8, "recycle ratio {}", top.1[1] / d_b);
}

#[test]
fn fixed_effluent_does_not_snowball() {
    let rows = sweep(
        "reactor_column_recycle_fixed_effluent.json",
        "reactor_level.sp=-20%:+20%",
        "feed.F@lbmol/h,recycle.F@lbmol/h,effluent.F@lbmol/h,reactor.M",
        "5",
    );
    let base = rows.iter().find(|(c, _)| c.abs() < 1e-9).unwrap();
    let (f0_b, d_b, m_b) = (base.1[0], base.1[1], base.1[3]);
    let km_b = f0_b * (1.0 - XB) / z_from(d_b, f0_b);
    for (change, v) in &rows {
        let (f0, d, f, m) = (v[0], v[1], v[2], v[3]);
        // The column load stays at its fixed value whatever the production rate.
        assert!((f - 500.0).abs() < 1e-6, "{change} %: effluent {f}");
        // Closed form at fixed F: F (1 − xB)(xD − z) = k M z (xD − xB).
        let km = km_b * m / m_b;
        let z = f * (1.0 - XB) * XD / (km * (XD - XB) + f * (1.0 - XB));
        let f0_closed = km * z / (1.0 - XB);
        assert!((f0 - f0_closed).abs() < 0.005 * f0_closed, "{change} %: F0 = {f0}, closed form {f0_closed}");
        assert!((d - (f - f0_closed)).abs() < 0.005 * d, "{change} %: D = {d}");
    }
    // Production moves by ±10 % while the recycle moves the other way by a similar fraction.
    let (lo, hi) = (&rows[0].1, &rows[rows.len() - 1].1);
    assert!(hi[0] > 1.08 * f0_b && lo[0] < 0.9 * f0_b);
    assert!(hi[1] < d_b && lo[1] > d_b);
}
