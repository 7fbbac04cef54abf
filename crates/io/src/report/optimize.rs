//! The report of an economic optimum ([`Optimum`]): the objective, the degrees of freedom and
//! constrained variables with their limits, which limits are active and their shadow prices, the
//! reduced Hessian and the KKT residual. `plantwide optimize` prints [`text`] (or the JSON of the
//! [`Optimum`] with `--json`), and [`write_report`] writes both to a folder.

use std::path::Path;

use plantwide_studies::optimize::Optimum;
use plantwide_studies::optimize::sweep::Sweep;

use super::sig6 as sig;
use crate::IoError;

/// The optimum as text.
pub fn text(o: &Optimum) -> String {
    let sense = if o.sense == plantwide_flowsheet::optimization::Sense::Maximize { "maximum" } else { "minimum" };
    let mut t =
        format!("economic optimum ({sense} of `{}`): {} {}\n\n", o.objective_path, sig(o.objective), o.objective_unit);
    t.push_str(&format!(
        "{:<28} {:>14} {:>14} {:>6}  {:>16}  unit\n",
        "limit", "value", "limit", "active", "shadow price"
    ));
    for l in &o.limits {
        let price = if l.active { sig(l.shadow_price) } else { "-".into() };
        t.push_str(&format!(
            "{:<28} {:>14} {:>14} {:>6}  {:>16}  {} ({} per {})\n",
            l.name,
            sig(l.value),
            sig(l.limit),
            if l.active { "yes" } else { "" },
            price,
            l.unit,
            o.objective_unit,
            l.unit
        ));
    }
    t.push_str("\nshadow price: the change of the optimal objective per unit the limit rises\n");
    let h = &o.reduced_hessian;
    if h.free.is_empty() {
        t.push_str(
            "\nno free direction: the active limits fix every degree of freedom (a vertex of the feasible region)\n",
        );
    } else {
        t.push_str(&format!(
            "\nreduced Hessian of the Lagrangian ({} per product of the free inputs' units), along {}:\n",
            o.objective_unit,
            h.free.join(", ")
        ));
        for row in &h.matrix {
            let cells: Vec<String> = row.iter().map(|v| format!("{:>14}", sig(*v))).collect();
            t.push_str(&format!("  {}\n", cells.join(" ")));
        }
        let eig: Vec<String> = h.scaled_eigenvalues.iter().map(|v| sig(*v)).collect();
        t.push_str(&format!("  scaled eigenvalues {} (all positive: a strict local minimum)\n", eig.join(", ")));
    }
    t.push_str(&format!(
        "\nKKT residual {:.2e} (scaled) after {} SQP iterations and {} plant steady states\n",
        o.kkt_residual, o.iterations, o.plant_solves
    ));
    t
}

/// Write `optimum.json`, `optimum.txt` and `optimum.md` into `dir`; the names written.
///
/// # Errors
/// A file that cannot be written.
pub fn write_report(dir: &Path, o: &Optimum) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let text = text(o);
    let md = format!("# Economic optimum\n\n```text\n{text}```\n");
    Ok(vec![
        super::write(dir, "optimum.json", &super::json(o)?)?,
        super::write(dir, "optimum.txt", &text)?,
        super::write(dir, "optimum.md", &md)?,
    ])
}

/// The optimum along a disturbance as text: a row per value, then the active-constraint regions.
pub fn sweep_text(s: &Sweep) -> String {
    let mut t = format!("the optimum along `{}` [{}]\n\n", s.disturbance, s.unit);
    t.push_str(&format!("{:>14}  {:>14}  active limits\n", s.unit, s.objective_unit));
    for p in &s.points {
        let j = p.objective.map_or_else(|| "failed".to_string(), sig);
        let what = p.failure.clone().unwrap_or_else(|| p.active.join(", "));
        t.push_str(&format!("{:>14}  {:>14}  {what}\n", sig(p.value), j));
    }
    t.push_str("\nactive-constraint regions:\n");
    for r in &s.regions {
        let set = if r.active.is_empty() { "(none active)".to_string() } else { r.active.join(", ") };
        t.push_str(&format!("  {} … {} {}: {set}\n", sig(r.from), sig(r.to), s.unit));
    }
    t
}

/// Write `sweep.json`, `sweep.txt` and `sweep.png` (the optimal objective along the disturbance,
/// each region's boundary in the title) into `dir`; the names written.
///
/// # Errors
/// A file that cannot be written or drawn.
pub fn write_sweep(dir: &Path, s: &Sweep) -> Result<Vec<String>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::Draw(format!("{}: {e}", dir.display())))?;
    let xs: Vec<f64> = s.points.iter().map(|p| p.value).collect();
    let ys: Vec<Option<f64>> = s.points.iter().map(|p| p.objective).collect();
    let title = format!("optimum along {} ({} region(s))", s.disturbance, s.regions.len());
    crate::plot::write_line(
        &dir.join("sweep.png"),
        &title,
        (&format!("{} [{}]", s.disturbance, s.unit), &format!("objective [{}]", s.objective_unit)),
        &xs,
        &ys,
    )?;
    Ok(vec![
        super::write(dir, "sweep.json", &super::json(s)?)?,
        super::write(dir, "sweep.txt", &sweep_text(s))?,
        "sweep.png".to_string(),
    ])
}
