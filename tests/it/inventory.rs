//! The inventory check (issue 58, item 4): the throughput manipulator and the consistency of
//! inventory control, in `check` and `screen`.
//!
//! The expected verdicts are the rules applied by hand to each plant, written beside each test:
//! the radiation rule (Price & Georgakis 1993: downstream of the TPM, inventory loops manipulate
//! outflows; upstream, inflows), self-consistency (Aske & Skogestad 2009: each inventory's loop
//! moves its own inflow or outflow, or a flow depends on its holdup) and the recycle rule (a
//! recycle's total inventory needs a flow into or out of it set by an inventory inside it).
//! Fixtures: `tests/data/inventory/`.

use plantwide::flowsheet::inventory::{Direction, InventoryCheck, InventoryVerdict, check};
use plantwide::flowsheet::{load_file, load_str};

use crate::harness::{fixture, flowsheet, plantwide};

/// The check of the plant in `path`.
fn checked(path: &str) -> InventoryCheck {
    let plant = load_file(std::path::Path::new(path)).unwrap_or_else(|e| panic!("{e}"));
    check(&plant)
}

/// The check of fixture `tests/data/inventory/NAME.json`.
fn of_fixture(name: &str) -> InventoryCheck {
    checked(&fixture(&format!("data/inventory/{name}.json")))
}

/// The verdict on inventory `path`.
fn on<'a>(c: &'a InventoryCheck, path: &str) -> &'a InventoryVerdict {
    c.inventories.iter().find(|v| v.inventory == path).unwrap_or_else(|| panic!("no inventory {path} in {c:#?}"))
}

/// `(controller, manipulated input, direction, consistent)` of a verdict.
fn loop_of(v: &InventoryVerdict) -> (Option<&str>, Option<&str>, Option<Direction>, bool) {
    (v.controller.as_deref(), v.manipulates.as_deref(), v.direction, v.consistent)
}

/// feed → tank1 → tank2 → product, both levels on their outflows (`tank1.outflow`,
/// `tank2.outflow`). The only flow no level sets is the feed: it is the TPM, both tanks are
/// downstream of it and act with the flow, as the radiation rule asks. Consistent.
#[test]
fn train_with_levels_on_outflows_radiates_from_the_feed() {
    let c = of_fixture("train_outflows");
    assert_eq!(c.consistent, Some(true), "{c:#?}");
    assert_eq!(c.set_from_outside, ["feed.F"]);
    assert_eq!(c.tpm, ["feed.F"]);
    let with = Some(Direction::WithFlow);
    assert_eq!(loop_of(on(&c, "tank1.level")), (Some("lc1"), Some("tank1.outflow"), with, true));
    assert_eq!(loop_of(on(&c, "tank2.level")), (Some("lc2"), Some("tank2.outflow"), with, true));
    assert!(c.recycles.is_empty());
}

/// The same train with tank1's level on its inflow (the feed) and tank1's outflow fixed: the only
/// flow no level sets is `between`, set by `tank1.outflow`. Tank1 is upstream of it and acts
/// against the flow, tank2 downstream and with it: the inventory control radiates from
/// `tank1.outflow`, and from nowhere else.
#[test]
fn train_with_tank1_on_its_inflow_radiates_from_tank1s_outlet() {
    let c = of_fixture("train_tank1_inflow");
    assert_eq!(c.consistent, Some(true), "{c:#?}");
    assert_eq!(c.set_from_outside, ["tank1.outflow"]);
    assert_eq!(c.tpm, ["tank1.outflow"]);
    assert_eq!(loop_of(on(&c, "tank1.level")), (Some("lc1"), Some("feed.F"), Some(Direction::AgainstFlow), true));
    assert_eq!(loop_of(on(&c, "tank2.level")), (Some("lc2"), Some("tank2.outflow"), Some(Direction::WithFlow), true));
}

/// Tank2's level moves the feed, which enters tank1, not tank2: not self-consistent, named.
/// Tank2's outflow is then the only free flow (the TPM), and tank1, upstream of it, acts with the
/// flow (its outflow): the radiation rule needs its inflow. No TPM location is feasible.
#[test]
fn a_level_loop_on_a_flow_that_does_not_touch_its_inventory_is_named() {
    let c = of_fixture("train_nonlocal");
    assert_eq!(c.consistent, Some(false));
    assert_eq!(c.set_from_outside, ["tank2.outflow"]);
    assert!(c.tpm.is_empty(), "{c:#?}");
    let tank2 = on(&c, "tank2.level");
    assert_eq!(loop_of(tank2), (Some("lc2"), Some("feed.F"), None, false));
    let why = tank2.why.as_deref().unwrap_or_default();
    assert!(why.contains("feed.F") && why.contains("neither fills nor drains tank2.level"), "{why}");
    let tank1 = on(&c, "tank1.level");
    assert!(!tank1.consistent);
    let why = tank1.why.as_deref().unwrap_or_default();
    assert!(why.contains("TPM tank2.outflow is not upstream") && why.contains("needs its inflow"), "{why}");
}

/// Tank1 has no level loop and its inflow (the feed) and outflow are both fixed: nothing holds it
/// — two throughput manipulators on one path. The degrees-of-freedom probe, which knows nothing of
/// these rules, refuses the same plant for the same inventory (an independent check).
#[test]
fn an_inventory_between_two_fixed_flows_is_not_consistent() {
    let c = of_fixture("train_tank1_open");
    assert_eq!(c.consistent, Some(false));
    assert_eq!(c.set_from_outside, ["feed.F", "tank1.outflow"]);
    assert!(c.tpm.is_empty());
    let tank1 = on(&c, "tank1.level");
    assert_eq!(loop_of(tank1), (None, None, None, false));
    let why = tank1.why.as_deref().unwrap_or_default();
    assert!(why.contains("no loop measures it") && why.contains("feed.F (free)"), "{why}");
    assert!(on(&c, "tank2.level").consistent);
    let out = plantwide(&["check", &fixture("data/inventory/train_tank1_open.json")]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(!out.status.success() && stderr.contains("The inventory of `tank1` is uncontrolled"), "{stderr}");
    assert!(stdout.contains("tank1.level") && stdout.contains("NOT consistent"), "{stdout}");
}

/// Feed → mixer → heater → flash drum, the drum's liquid all returned to the mixer on level
/// control. The drum's own loop is local (its outflow), but the loop's boundary flows are the feed
/// (free) and the vapour (the heater's duty): no inventory inside the recycle sets a flow across
/// it, so its total inventory is not controlled. The degrees-of-freedom probe refuses it too.
#[test]
fn a_recycle_with_every_flow_on_level_control_is_named() {
    let c = of_fixture("recycle_all_levels");
    assert_eq!(c.consistent, Some(false));
    assert_eq!(
        loop_of(on(&c, "drum.level")),
        (Some("drum_level"), Some("drum.outflow"), Some(Direction::WithFlow), true)
    );
    assert_eq!(c.recycles.len(), 1);
    let r = &c.recycles[0];
    assert_eq!(r.recycle, "mix→heater→drum→mix");
    assert!(!r.consistent);
    let why = r.why.as_deref().unwrap_or_default();
    assert!(why.contains("feed by fresh.F (free)") && why.contains("nothing holds its total inventory"), "{why}");
    let out = plantwide(&["check", &fixture("data/inventory/recycle_all_levels.json")]);
    assert!(!out.status.success(), "the degrees-of-freedom probe accepts it");
}

/// The same loop with half the level-controlled liquid leaving as the bottom product (a splitter):
/// that flow out of the recycle is a share of the flow the drum's level sets, so an inventory inside
/// the loop sets a flow out of it. Consistent.
#[test]
fn a_recycle_with_a_purge_from_a_level_controlled_flow_is_consistent() {
    let c = of_fixture("recycle_purge");
    assert_eq!(c.consistent, Some(true), "{c:#?}");
    assert_eq!(c.tpm, ["fresh.F"]);
    assert!(c.recycles.iter().all(|r| r.consistent), "{:#?}", c.recycles);
}

/// The shipped two-column plant (ch. 6): fresh A is the only free flow, and every level acts on
/// an outflow downstream of it (reactor effluent, both drums' distillates, both sumps' boilups):
/// the inventory loops radiate from fresh_A.F. The recycle mix → reactor → cooler → column 1 → mix
/// is crossed by fresh A (free), fresh B (the reactor's B analyzer) and column 1's bottoms (its
/// tray-temperature loop): no level sets a flow across it, so its total inventory is held only
/// through those quality loops — not self-consistent, and said so.
#[test]
fn two_column_plant_tpm_and_its_recycle() {
    let c = checked(&flowsheet("two_column_plant.json"));
    assert_eq!(c.set_from_outside, ["fresh_A.F"]);
    assert_eq!(c.tpm, ["fresh_A.F"]);
    let with = Some(Direction::WithFlow);
    for (inv, ctrl, mv) in [
        ("reactor.level", "reactor_level", "reactor.outflow"),
        ("column1.drum", "column1_drum", "column1.distillate"),
        ("column1.sump", "column1_sump", "column1.boilup"),
        ("column2.drum", "column2_drum", "column2.distillate"),
        ("column2.sump", "column2_sump", "column2.boilup"),
    ] {
        assert_eq!(loop_of(on(&c, inv)), (Some(ctrl), Some(mv), with, true), "{inv}");
    }
    assert_eq!(c.recycles.len(), 1);
    let r = &c.recycles[0];
    assert_eq!(r.recycle, "mix→reactor→feed_cooler→column1→mix");
    assert!(!r.consistent);
    let why = r.why.as_deref().unwrap_or_default();
    assert!(why.contains("column1_bottom_T") && why.contains("reactor_B") && why.contains("indirectly"), "{why}");
    assert_eq!(c.consistent, Some(false));
}

/// Luyben's fix for the recycle: the reactor effluent fixed (the TPM inside the recycle) and the
/// reactor level on the fresh feed. The feed into the recycle is set by an inventory inside it, so
/// the recycle is consistent; the reactor acts against the flow.
#[test]
fn fixed_reactor_effluent_controls_the_recycle() {
    let c = checked(&flowsheet("reactor_column_recycle_fixed_effluent.json"));
    assert_eq!(c.consistent, Some(true), "{c:#?}");
    assert_eq!(c.tpm, ["reactor.outflow"]);
    assert_eq!(on(&c, "reactor.level").direction, Some(Direction::AgainstFlow));
    assert!(c.recycles.iter().all(|r| r.consistent));
}

/// A steady-state flowsheet without a level loop is not judged, and says why; its drum, drained
/// by a valve under its own head, regulates itself.
#[test]
fn a_plant_without_inventory_loops_is_not_judged() {
    let c = checked(&flowsheet("flash_recycle.json"));
    assert_eq!(c.consistent, None);
    assert!(c.note.as_deref().is_some_and(|n| n.contains("not judged")), "{:?}", c.note);
    let drum = on(&c, "drum.level");
    assert!(drum.consistent && drum.controller.is_none());
    assert!(drum.how.as_deref().is_some_and(|h| h.contains("regulates itself")), "{drum:#?}");
}

/// `check` prints the section; `screen --json` carries it under `inventory`, its other keys kept.
#[test]
fn check_and_screen_show_the_section() {
    let out = plantwide(&["check", &flowsheet("two_column_plant.json")]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(text.contains("throughput manipulator as built: fresh_A.F"), "{text}");
    assert!(text.contains("recycle mix→reactor→feed_cooler→column1→mix: NOT consistent"), "{text}");
    let qualities = "distillate.x[light],bottoms.x[light]";
    let column_a = flowsheet("column_a.json");
    let args = ["screen", &column_a, "--column", "column", "--outputs", qualities, "--steady-only"];
    let out = plantwide(&[&args[..], &["--json"]].concat());
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert!(v.get("verdict").is_some() && v.get("structures").is_some());
    let inv = &v["inventory"];
    assert_eq!(inv["consistent"], true);
    assert_eq!(inv["tpm"], serde_json::json!(["feed_source.F"]));
    assert_eq!(inv["inventories"][0]["direction"], "with flow");
    let text = plantwide(&args);
    assert!(String::from_utf8_lossy(&text.stdout).contains("feasible TPM locations"));
}

/// Plants we did not write: every flowsheet shipped or kept as a fixture (users' files among them)
/// and the generator's drafts. The check never panics, every verdict against consistency says
/// why, and a consistent plant has every inventory and recycle consistent. The
/// generator wires every level to an outflow below one fresh feed, so each of its plants radiates
/// from that feed.
#[test]
fn plants_we_did_not_write_get_an_honest_answer() {
    let mut files = Vec::new();
    for dir in ["flowsheets", "tests/data", "tests/data/generated", "tests/data/newcomer3", "tests/data/inventory"] {
        let dir = std::path::Path::new(crate::harness::ROOT).join(dir);
        for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())).flatten() {
            let p = e.path();
            let name = p.display().to_string();
            if name.ends_with(".json") && !name.contains("scenario") && !name.contains("schema") {
                files.push(name);
            }
        }
    }
    let mut judged = 0;
    for f in &files {
        let Ok(plant) = load_file(std::path::Path::new(f)) else { continue };
        judged += usize::from(honest(&check(&plant), f));
    }
    assert!(judged >= 30, "only {judged} of {} files judged", files.len());
    for seed in 0..12u64 {
        let (_, draft) = crate::generator::families::draft(seed);
        let plant = load_str(&draft.doc.render(), &format!("generated plant {seed}")).unwrap_or_else(|e| panic!("{e}"));
        let c = check(&plant);
        honest(&c, &format!("generated plant {seed}"));
        assert_eq!(c.consistent, Some(true), "generated plant {seed}: {c:#?}");
        assert_eq!(c.tpm.len(), 1, "generated plant {seed}: {c:#?}");
    }
}

/// The check's answer on `what` is coherent; whether it judged the plant.
fn honest(c: &InventoryCheck, what: &str) -> bool {
    for v in &c.inventories {
        assert_eq!(v.consistent, v.why.is_none(), "{what}: {v:#?}");
    }
    for r in &c.recycles {
        assert_eq!(r.consistent, r.why.is_none(), "{what}: {r:#?}");
    }
    if c.consistent == Some(true) {
        assert!(c.inventories.iter().all(|v| v.consistent) && c.recycles.iter().all(|r| r.consistent), "{what}");
    }
    if c.consistent.is_none() {
        assert!(c.note.is_some(), "{what}: not judged without saying why");
    }
    c.consistent.is_some()
}

/// What the units declare names real things on every shipped flowsheet: each flow's port is one of
/// the unit's ports, each inventory is measured by variables the plant has, and each input a law
/// names is one of the unit's inputs.
#[test]
fn declared_flows_name_real_ports_variables_and_inputs() {
    use plantwide::model::{FlowLaw, FlowVia};
    let dir = std::path::Path::new(crate::harness::ROOT).join("flowsheets");
    for e in std::fs::read_dir(dir).expect("flowsheets/").flatten() {
        let file = e.path().display().to_string();
        if !file.ends_with(".json") || file.contains("schema") {
            continue;
        }
        let plant = load_file(&e.path()).unwrap_or_else(|e| panic!("{e}"));
        for b in plant.blocks() {
            let decl = b.unit.material_flows();
            let inputs: Vec<String> = b.unit.inputs().into_iter().map(|i| i.name).collect();
            let port_ok = |v: &FlowVia| match v {
                FlowVia::Inlet(p) => b.unit.inlet_ports().iter().any(|q| q == p),
                FlowVia::Outlet(p) => b.unit.outlet_ports().iter().any(|q| q == p),
                FlowVia::Internal(_) => true,
            };
            for d in &decl.flows {
                assert!(port_ok(&d.via), "{file}: {} declares {:?}", b.name, d.via);
                let named = match &d.law {
                    FlowLaw::Input(i) => Some(i),
                    FlowLaw::Holdup { input } | FlowLaw::UpstreamHoldup { input } => input.as_ref(),
                    FlowLaw::Balance => None,
                };
                assert!(named.is_none_or(|i| inputs.iter().any(|n| n == i)), "{file}: {} law {:?}", b.name, d.law);
            }
            for inv in &decl.inventories {
                assert!(inv.inflows.iter().chain(&inv.outflows).all(port_ok), "{file}: {} {inv:?}", b.name);
                for m in &inv.measured {
                    assert!(plant.var(format!("{}.{m}", b.name)).is_some(), "{file}: {}.{m} is no variable", b.name);
                }
            }
        }
    }
}

/// The study `docs/two_column_tpm.md` shows the command's output as it is: every line of its two
/// `check` sections is printed by `check` on the plant and on its column-1 LV variant.
#[test]
fn the_two_column_study_shows_the_real_output() {
    let doc = std::fs::read_to_string(format!("{}/docs/two_column_tpm.md", crate::harness::ROOT)).expect("the study");
    let sections: Vec<&str> = doc
        .split("```text\n")
        .skip(1)
        .filter_map(|b| b.split("```").next())
        .filter(|b| b.starts_with("inventory control"))
        .collect();
    assert_eq!(sections.len(), 2, "the study's two inventory sections");
    for (file, shown) in [
        (flowsheet("two_column_plant.json"), sections[0]),
        (format!("{}/docs/two_column_tpm/column1_lv.json", crate::harness::ROOT), sections[1]),
    ] {
        let out = plantwide(&["check", &file]);
        let printed = String::from_utf8_lossy(&out.stdout);
        let got: Vec<&str> = printed.lines().collect();
        for line in shown.lines() {
            assert!(got.contains(&line), "{file}: the study shows\n  {line}\nwhich check did not print:\n{printed}");
        }
    }
}
