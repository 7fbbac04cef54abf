//! `plantwide check FILE`: validate and summarize; values in the `--units` system (default SI).

use std::path::Path;

use plantwide::io::report;
use plantwide::solve::{DofProbe, dof_check};
use plantwide::units::UnitSystem;

use super::CliError;

pub fn run(file: &Path, system: UnitSystem) -> Result<(), CliError> {
    let plant = super::steady::load_plant(file, &[])?;
    out!("{}", report::check::summary(&plant, file, system));
    // Before the degrees of freedom: an inconsistent inventory control is one reason they fail.
    out!("{}", report::inventory::text(&plantwide::flowsheet::inventory::check(&plant)));
    let u = plant.input_values();
    let x = plant.initial_guess();
    // The numerical probe judges one point: a singular Jacobian at the cold-start guess (a dry tray,
    // a closed valve) proves nothing until the plant also fails to converge from there.
    let at_guess = dof_check(&plant, &u, &x, DofProbe::Numerical);
    if let Err(e @ plantwide::solve::DofError::Count { .. }) = at_guess {
        return Err(CliError::user(e.to_string()));
    }
    let solved = super::steady::converge(&plant, &u);
    let numerical = match (at_guess, &solved) {
        (Ok(()), _) => true,
        (Err(e), Ok(_)) => {
            out!("{}", report::check::singular_at_guess(&e));
            false
        }
        (Err(e), Err(_)) => return Err(CliError::user(e.to_string())),
    };
    out!("{}", report::check::degrees_of_freedom(numerical));
    plantwide::solve::sequential::plan(&plant, &u, &x).describe(&plant).iter().for_each(|l| outln!("{l}"));
    // Residence times at the steady state or, when the plant does not converge, at the guess.
    let (x, converged) = match solved {
        Ok(s) => (s.x, true),
        Err(_) => (x, false),
    };
    out!("{}", report::check::residence(&plant, &x, converged, system));
    Ok(())
}
