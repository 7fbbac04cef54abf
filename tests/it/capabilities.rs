//! What units declare of themselves (`crates/model/src/capability.rs`), checked against their
//! structure on every shipped flowsheet, so that a unit which forgets a declaration fails here
//! rather than giving a silently wrong certificate or energy balance.

use plantwide::flowsheet::{BlockKind, Plant, load_file};
use plantwide::model::{Boundary, DutySource};

fn shipped() -> Vec<(String, Plant)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("flowsheets");
    let mut plants = Vec::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if path.extension().is_some_and(|e| e == "json") && !name.ends_with("schema.json") {
            plants.push((name, load_file(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))));
        }
    }
    assert!(plants.len() >= 15, "{} flowsheets", plants.len());
    plants
}

/// A source has no inlet and a sink no outlet; every unit without an inlet is a source and every
/// one without an outlet a sink (material cannot appear or vanish elsewhere).
#[test]
fn boundaries_are_where_material_enters_and_leaves() {
    for (file, plant) in shipped() {
        for b in plant.blocks().iter().filter(|b| b.kind == BlockKind::Unit) {
            let (ins, outs) = (b.unit.inlet_ports().len(), b.unit.outlet_ports().len());
            let expected = match (ins, outs) {
                (0, _) => Boundary::Source,
                (_, 0) => Boundary::Sink,
                _ => Boundary::Interior,
            };
            assert_eq!(b.unit.boundary(), expected, "{file}: unit `{}` ({})", b.name, b.unit.type_name());
        }
    }
}

/// Every heat duty a unit carries (an own variable `Q` or `Qc`, an input named `duty` or
/// `…_duty`) is one it declares, so that `compare`'s energy use cannot leave it out; a coupled condenser duty is
/// declared through its condenser's booking.
#[test]
fn every_heat_duty_is_declared() {
    use plantwide::model::Booking;
    for (file, plant) in shipped() {
        for (bi, b) in plant.blocks().iter().enumerate() {
            let duties = b.unit.duties();
            let declared: Vec<&str> = duties
                .iter()
                .flat_map(|d| {
                    let source = match &d.source {
                        DutySource::Var(n) | DutySource::Input(n) => n.as_ref(),
                    };
                    let coupled = match d.booking {
                        Booking::Removed { coupled } => Some(coupled),
                        _ => None,
                    };
                    std::iter::once(source).chain(coupled)
                })
                .collect();
            let local = |path: &str| path.strip_prefix(&format!("{}.", b.name)).map(str::to_string);
            let vars = plant.vars().iter().filter(|v| v.block == bi).filter_map(|v| local(&v.path));
            let inputs = plant.inputs().iter().filter(|i| i.block == bi).filter_map(|i| local(&i.path));
            // An input `duty` is a heat input unless the unit carries it in a declared `Q` (a
            // heater or a CSTR in duty mode: `Q` equals it, and booking both would count it twice).
            let carried = duties.iter().any(|d| d.source == DutySource::Var("Q".into()));
            let heat_input = |n: &String| n.ends_with("_duty") || (n == "duty" && !carried);
            let duties = vars.filter(|n| n == "Q" || n == "Qc").chain(inputs.filter(heat_input));
            for name in duties {
                assert!(
                    declared.contains(&name.as_str()),
                    "{file}: `{}.{name}` is a duty `{}` does not declare",
                    b.name,
                    b.unit.type_name()
                );
            }
        }
    }
}

/// Every liquid inventory a unit declares (a column's drum and base) is addressable: its stage's
/// holdup, temperature and composition are variables, and what leaves it is a variable or an
/// input of the unit. At column A's steady state the drum's and the base's throughputs are those
/// of the column's balance: reflux + distillate = V[N−1] and bottoms + boilup = L[2].
#[test]
fn every_declared_inventory_is_addressable_and_balances() {
    let mut seen = 0;
    for (file, plant) in shipped() {
        for (name, u) in &plant.spec().units {
            for inv in u.config().inventories() {
                seen += 1;
                let var = |f: String| plant.var(format!("{name}.{f}"));
                assert!(var(format!("M[{}]", inv.stage)).is_some(), "{file}: {name}.{}", inv.name);
                assert!(var(format!("T[{}]", inv.stage)).is_some(), "{file}: {name}.{}", inv.name);
                for p in &inv.leaving {
                    let found = var(p.clone()).is_some() || plant.input(format!("{name}.{p}")).is_some();
                    assert!(
                        found,
                        "{file}: `{name}.{p}` leaving {name}.{} is neither a variable nor an input",
                        inv.name
                    );
                }
            }
        }
    }
    assert!(seen >= 2 * 8, "{seen} inventories on the shipped flowsheets");
    let (plant, ss) = crate::harness::converge("column_a.json");
    let residence = plantwide::studies::size::residence::residence_times(&plant, &ss.x);
    let at = |p: &str| crate::harness::value(&plant, &ss.x, p);
    let through = |v: &str| residence.iter().find(|r| r.vessel == v).map(|r| r.throughput).unwrap();
    let n = plant.vars().iter().filter(|v| v.path.starts_with("column.M[")).count();
    approx::assert_relative_eq!(through("column.drum"), at(&format!("column.V[{}]", n - 1)), max_relative = 1e-9);
    approx::assert_relative_eq!(through("column.sump"), at("column.L[2]"), max_relative = 1e-9);
}

/// A flash drum's and a tank's heat input `duty` is a utility `compare` books (it was left out
/// until they declared it): with 50 kW put into the drum of the flash recycle, the booked heating
/// is the heater's 0.8 MW plus those 50 kW, and the surge tank's 20 kW is its only duty.
#[test]
fn a_vessels_heat_input_is_booked_as_heating() {
    use plantwide::flowsheet::{Override, load_with};
    use plantwide::solve::{NewtonSettings, steady_state};
    let booked = |file: &str, sets: &[(&str, &str)]| {
        let overrides: Vec<Override> = sets.iter().map(|(p, v)| Override::new(*p, *v)).collect();
        let path = crate::harness::flowsheet(file);
        let plant = load_with(std::path::Path::new(&path), &overrides).unwrap_or_else(|e| panic!("{e}"));
        let u = plant.input_values();
        let ss = steady_state(&plant, &u, None, &NewtonSettings::default()).unwrap_or_else(|e| panic!("{e}"));
        plantwide::studies::compare::energy(&plant, &ss.x, &u)
    };
    let e = booked("flash_recycle.json", &[("drum.duty", "50 kW")]);
    approx::assert_relative_eq!(e.heating, 0.8e6 + 50e3, max_relative = 1e-12);
    assert!(e.duties.iter().any(|d| d.path == "drum.duty" && d.duty == 50e3), "{:?}", e.duties);
    let e = booked("surge_tank.json", &[("tank.duty", "20 kW")]);
    approx::assert_relative_eq!(e.heating, 20e3, max_relative = 1e-12);
}
