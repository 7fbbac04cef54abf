//! Structural (non)singularity of equation sets.

use plantwide_expr::testing::{CSTR, CSTR_EQUATIONS, cstr_symbols, slot};
use plantwide_expr::{Equation, StructuralError, StructureMode, check_structure};

fn equations(texts: &[&str]) -> Vec<Equation> {
    let s = cstr_symbols(&CSTR);
    texts.iter().map(|t| Equation::new(t, &s).unwrap_or_else(|e| panic!("{}", e.render()))).collect()
}

#[test]
fn cstr_is_structurally_nonsingular() {
    let s = cstr_symbols(&CSTR);
    let eqs = equations(&CSTR_EQUATIONS);
    // Steady state with F and Tj given: the balances determine CA and T.
    let assigned = check_structure(&eqs, &[slot::CA, slot::T], StructureMode::Steady, &s).unwrap();
    let mut sorted = assigned.clone();
    sorted.sort();
    assert_eq!(sorted, vec![slot::CA, slot::T]);
    // Dynamics: each balance determines its derivative.
    let assigned = check_structure(&eqs, &[slot::CA, slot::T], StructureMode::Dynamic, &s).unwrap();
    assert_eq!(assigned, vec![slot::CA, slot::T]);
}

#[test]
fn singular_sets_name_what_is_left_over() {
    let s = cstr_symbols(&CSTR);
    // Two equations read only F, so one of them and one of T, Tj are left over (which of T and
    // Tj is the matching's choice: the first unknown `Tj = T` reads, in index order, is T).
    let eqs = equations(&["F = V*k0", "F*2 = V*k0", "Tj = T"]);
    let err = check_structure(&eqs, &[slot::F, slot::TJ, slot::T], StructureMode::Steady, &s).unwrap_err();
    assert_eq!(
        err,
        StructuralError {
            n_equations: 3,
            n_unknowns: 3,
            unmatched_equations: vec!["F*2 = V*k0".into()],
            unmatched_unknowns: vec!["Tj".into()],
        }
    );
    assert_eq!(
        err.to_string(),
        "the equations are structurally singular (3 equations, 3 unknowns); left without an unknown: \
         `F*2 = V*k0`; left without an equation: `Tj`"
    );
    // In dynamic mode the differential variable's derivative is the unknown.
    let eqs = equations(&["der(CA) = F/V*(CAf - CA)", "F = V*k0"]);
    let err = check_structure(&eqs, &[slot::CA, slot::F, slot::T], StructureMode::Dynamic, &s).unwrap_err();
    assert_eq!(err.unmatched_unknowns, vec!["der(T)".to_owned()]);
    assert!(err.unmatched_equations.is_empty());
}

/// A flooded equation set (10 000 copies of one equation, a fuzz mutant of the evaporator) is
/// named by its first ten and a count: the message stays a few kB, not 300 kB.
#[test]
fn a_flood_of_unmatched_equations_is_named_by_the_first_ten_and_a_count() {
    let many: Vec<String> = (0..10_000).map(|k| format!("x{k} = 1")).collect();
    let text = plantwide_expr::name_list(&many);
    assert!(text.starts_with("`x0 = 1`, `x1 = 1`") && text.ends_with("`x9 = 1`, … and 9990 more"), "{text}");
    assert_eq!(plantwide_expr::name_list(&["a", "b"]), "`a`, `b`");
    assert_eq!(plantwide_expr::name_list::<&str>(&[]), "none");
}
