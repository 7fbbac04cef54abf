//! The inventory section of `plantwide check` and `plantwide screen`: the throughput manipulator
//! candidates and each inventory's and recycle's verdict
//! ([`plantwide_flowsheet::inventory::check`]).

use plantwide_flowsheet::inventory::InventoryCheck;

/// The section in text: a header with the verdict, the TPM as built and the feasible TPM
/// locations, then one line per inventory (its loop, what it moves, which way, the verdict and
/// why) and per recycle.
pub fn text(c: &InventoryCheck) -> String {
    let verdict = match c.consistent {
        Some(true) => "consistent",
        Some(false) => "NOT consistent",
        None => "not judged",
    };
    let mut t = format!(
        "inventory control (radiation rule: Price & Georgakis 1993; consistency: Aske & Skogestad 2009): {verdict}\n"
    );
    if let Some(note) = &c.note {
        t.push_str(&format!("  {note}\n"));
    }
    let list = |v: &[String]| if v.is_empty() { "none".to_string() } else { v.join(", ") };
    match c.set_from_outside.as_slice() {
        [one] => t.push_str(&format!("  throughput manipulator as built: {one}\n")),
        many => t.push_str(&format!("  flows set from outside the inventory control: {}\n", list(many))),
    }
    if c.consistent.is_some() {
        t.push_str(&format!("  feasible TPM locations (the inventory control radiates from them): {}\n", list(&c.tpm)));
    }
    for v in &c.inventories {
        let dash = |s: &Option<String>| s.clone().unwrap_or_else(|| "-".into());
        t.push_str(&format!(
            "  {:<18} {:<18} {:<22} {:<13} {}\n",
            v.inventory,
            dash(&v.controller),
            dash(&v.manipulates),
            v.direction.map_or("-", |d| d.label()),
            if v.consistent { "consistent" } else { "NOT consistent" }
        ));
        if let Some(how) = v.how.as_ref().filter(|_| v.consistent) {
            t.push_str(&format!("      {how}\n"));
        }
        if let Some(why) = &v.why {
            t.push_str(&format!("      why: {why}\n"));
        }
    }
    for r in &c.recycles {
        let state =
            if r.consistent { "its total inventory is set by an inventory inside it" } else { "NOT consistent" };
        t.push_str(&format!("  recycle {}: {state}\n", r.recycle));
        if let Some(why) = &r.why {
            t.push_str(&format!("      why: {why}\n"));
        }
    }
    t
}
