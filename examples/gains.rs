//! Steady-state gains, relative gain array and Niederlinski index of column A (Skogestad &
//! Postlethwaite 2005 §12.4) in its LV configuration, by linearization at the steady state:
//! G(0) = −C J⁻¹ B (exact Jacobians, one sparse LU), the route of `plantwide gains`.
//!
//! `cargo run --example gains`. Published (eq. 12.17): G(0) ≈ [0.878 −0.864; 1.082 −1.096]
//! (kmol/min of reflux and boilup to the mole fractions of light in distillate and bottoms),
//! λ11 ≈ 35.1.

use std::path::Path;

use plantwide::analysis::faer::Mat;
use plantwide::analysis::linear::Linearization;
use plantwide::analysis::measures::{niederlinski, rga};
use plantwide::analysis::select::{select_inputs, select_outputs};
use plantwide::flowsheet::load_with;
use plantwide::solve::{StrategySettings, converge};

fn main() -> anyhow::Result<()> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("flowsheets/column_a.json");
    let plant = load_with(&file, &[])?;
    let sol = converge(&plant, &StrategySettings::default())?;
    let names = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    // `PATH@unit`: the gains are reported in these display units.
    let inputs = select_inputs(&plant, &names(&["column.reflux@kmol/min", "column.boilup@kmol/min"]))?;
    let outputs = select_outputs(&plant, &names(&["distillate.x[light]", "bottoms.x[light]"]))?;
    let ii: Vec<usize> = inputs.iter().map(|s| s.index).collect();
    let oo: Vec<usize> = outputs.iter().map(|s| s.index).collect();
    let si = Linearization::new(&plant, &sol.x, &sol.u).steady_gain(&ii, &oo)?;
    // SI gains to display units: G_ij · f_uj / f_yi.
    let g = Mat::from_fn(si.nrows(), si.ncols(), |i, j| si[(i, j)] * inputs[j].factor / outputs[i].factor);
    let lambda = rga(g.as_ref())?;
    for (i, o) in outputs.iter().enumerate() {
        let row: Vec<String> = (0..g.ncols()).map(|j| format!("{:>9.4}", g[(i, j)])).collect();
        let rel: Vec<String> = (0..g.ncols()).map(|j| format!("{:>8.3}", lambda[(i, j)])).collect();
        println!("{:<22} gain {}   RGA {}", o.label().path, row.join(" "), rel.join(" "));
    }
    println!("Niederlinski index (diagonal pairing): {:.4}", niederlinski(g.as_ref(), &[0, 1])?);
    Ok(())
}
