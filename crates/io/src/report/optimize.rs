//! The report of an economic optimum ([`Optimum`]): the objective, the degrees of freedom and
//! constrained variables with their limits, which limits are active and their shadow prices, the
//! reduced Hessian and the KKT residual. `plantwide optimize` prints [`text`] (or the JSON of the
//! [`Optimum`] with `--json`), and [`write_report`] writes both to a folder.

use std::path::Path;

use plantwide_studies::optimize::Optimum;

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
