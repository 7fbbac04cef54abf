//! The only code that changes how an assembled plant is wired: input values, held inputs (a loop in
//! manual, a sampled controller between scans), held measurements (an analyzer's sample-and-hold),
//! and structure variants (another pairing, another inventory configuration) assembled anew from
//! an edited description.
//!
//! Invariants kept by every method: each block's `reads` has one entry per local input or signal;
//! an input is `driven_by` a controller output exactly when some block reads that output variable
//! in its place; a held measurement is an input of its own (`<ctrl>.analyzer`), appended after the
//! declared inputs, so the indices of the declared inputs never move.

use crate::FlowsheetSpec;
use crate::overrides::{Override, OverrideError};
use crate::path::VarPath;
use crate::plant::{BlockKind, InputInfo, Plant, Read};

/// Why a plant cannot be rewired as asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum WiringError {
    /// No block of that name, or it is not a controller.
    #[error("{file}: no controller `{name}`{hint}")]
    NoController {
        /// Flowsheet file.
        file: String,
        /// The name asked for.
        name: String,
        /// A suggestion (`; did you mean …?`) or empty.
        hint: String,
    },
    /// The controller does not read a plant variable as its measurement (it has no signal, or an
    /// analyzer already holds it).
    #[error(
        "{file}: controller `{name}` does not read a plant variable as its measurement (already held by an analyzer?)"
    )]
    NoMeasurement {
        /// Flowsheet file.
        file: String,
        /// The controller.
        name: String,
    },
}

impl Plant {
    /// Set the value (SI) of input `i`: a free input's value, or the value a held input keeps.
    pub fn set_input_value(&mut self, i: usize, value: f64) {
        self.inputs[i].value = value;
    }

    /// Set the values (SI) of all inputs, in input order (`u.len()` = number of inputs).
    pub fn set_input_values(&mut self, u: &[f64]) {
        self.inputs.iter_mut().zip(u).for_each(|(info, v)| info.value = *v);
    }

    /// Index of the controller named `name`.
    pub fn controller(&self, name: &str) -> Result<usize, WiringError> {
        match self.block_index(name) {
            Some(b) if self.blocks[b].kind == BlockKind::Controller => Ok(b),
            _ => Err(WiringError::NoController {
                file: self.file.clone(),
                name: name.to_string(),
                hint: crate::error::did_you_mean(
                    name,
                    self.blocks.iter().filter(|b| b.kind == BlockKind::Controller).map(|b| b.name.as_str()),
                ),
            }),
        }
    }

    /// The inputs driven by an output variable of block `b`, in input order.
    pub fn inputs_driven_by(&self, b: usize) -> Vec<usize> {
        (0..self.inputs.len()).filter(|&i| self.inputs[i].driven_by.is_some_and(|v| self.vars[v].block == b)).collect()
    }

    /// The plant variable controller `b` reads as its measurement (its first signal), if it reads one.
    pub fn measured_var(&self, b: usize) -> Option<usize> {
        let block = &self.blocks[b];
        if block.kind != BlockKind::Controller || block.layout.n_signals == 0 {
            return None;
        }
        match block.reads.get(block.layout.n_inputs) {
            Some(&Read::Var(v)) => Some(v),
            _ => None,
        }
    }

    /// The plant variables controller `b` reads as its signals, in order, with their positions
    /// among the signals (a model predictive controller's CVs; a PID's measurement first).
    pub fn measured_vars(&self, b: usize) -> Vec<(usize, usize)> {
        let block = &self.blocks[b];
        if block.kind != BlockKind::Controller {
            return Vec::new();
        }
        let signals = block.reads.iter().skip(block.layout.n_inputs).take(block.layout.n_signals);
        signals
            .enumerate()
            .filter_map(|(k, r)| match *r {
                Read::Var(v) => Some((k, v)),
                _ => None,
            })
            .collect()
    }

    /// Hold input `i`: every block reads the input's own value instead of the controller output
    /// that drives it. Returns that output variable, or `None` if the input was free already.
    pub fn hold_input(&mut self, i: usize) -> Option<usize> {
        let op = self.inputs[i].driven_by.take()?;
        let slen = self.stream_layout.len();
        for b in &mut self.blocks {
            if let Some(k) = b.input_ids.iter().position(|&id| id == i) {
                let pos = if b.kind == BlockKind::Unit { b.layout.n_inlets * slen + k } else { k };
                b.reads[pos] = Read::Input(i);
            }
        }
        Some(op)
    }

    /// Give input `i` back to the controller output variable `op` that drove it before
    /// [`Plant::hold_input`]: every block reads `op` again (a repaired valve, a restored feed).
    pub fn release_input(&mut self, i: usize, op: usize) {
        self.inputs[i].driven_by = Some(op);
        let slen = self.stream_layout.len();
        for b in &mut self.blocks {
            if let Some(k) = b.input_ids.iter().position(|&id| id == i) {
                let pos = if b.kind == BlockKind::Unit { b.layout.n_inlets * slen + k } else { k };
                b.reads[pos] = Read::Var(op);
            }
        }
    }

    /// Put block `b`'s loop in manual at state `x`: every input its outputs drive is held at the
    /// output's value in `x`. Returns the pairs (held input, output variable).
    pub fn manual(&mut self, b: usize, x: &[f64]) -> Vec<(usize, usize)> {
        let pairs: Vec<(usize, usize)> =
            self.inputs_driven_by(b).into_iter().filter_map(|i| self.hold_input(i).map(|op| (i, op))).collect();
        for &(i, op) in &pairs {
            self.inputs[i].value = x[op];
        }
        pairs
    }

    /// Hold controller `b`'s measurement: a new input `<ctrl>.analyzer` with `value` is read in
    /// place of the measured variable. Returns (the new input, the variable it stands for).
    pub fn hold_measurement(&mut self, b: usize, value: f64) -> Result<(usize, usize), WiringError> {
        let v = self
            .measured_var(b)
            .ok_or_else(|| WiringError::NoMeasurement { file: self.file.clone(), name: self.blocks[b].name.clone() })?;
        let input = self.inputs.len();
        let path: String = VarPath::new(&self.blocks[b].name, "analyzer").into();
        self.inputs.push(InputInfo {
            path: path.clone(),
            dim: self.vars[v].spec.dim,
            value,
            driven_by: None,
            block: b,
        });
        self.input_index.insert(path, input);
        let pos = self.blocks[b].layout.n_inputs;
        self.blocks[b].reads[pos] = Read::Input(input);
        Ok((input, v))
    }

    /// A structure variant: this plant's description with `overrides` applied (fields of units and
    /// controllers: another measurement or manipulated input of a controller, another pairing, a
    /// unit's parameters; and input values), assembled again. Input values this plant changed since
    /// it was assembled carry over by path where the variant keeps the input; the others take the
    /// variant's own (so a field edit that changes an input's default, `mode` → `auto`, holds).
    pub fn variant(&self, overrides: &[Override]) -> Result<Plant, OverrideError> {
        let edits: Vec<StructureEdit> = overrides.iter().cloned().map(StructureEdit::Set).collect();
        self.restructure(&edits)
    }

    /// A structure variant with controllers added or removed as well as fields set: `edits` applied
    /// in order to this plant's description (so a field of a controller added earlier in `edits`
    /// can be set), assembled again, input values carried over as in [`Plant::variant`].
    pub fn restructure(&self, edits: &[StructureEdit]) -> Result<Plant, OverrideError> {
        let mut spec = FlowsheetSpec::clone(&self.spec);
        let mut inputs = Vec::new();
        for e in edits {
            match e {
                StructureEdit::Set(o) if crate::overrides::resolve_input(self, &o.path).is_some() => {
                    inputs.push(o.clone());
                }
                StructureEdit::Set(o) => crate::overrides::set_field(&mut spec, &o.path, &o.value)?,
                StructureEdit::AddController { name, spec: c } => add_controller(&mut spec, name, c)?,
                StructureEdit::InsertOnStream { stream, unit, spec: u, outlet } => {
                    insert_on_stream(&mut spec, stream, unit, u, outlet)?;
                }
                StructureEdit::SetController { name, spec: c } => {
                    if spec.units.contains_key(name) {
                        return Err(OverrideError::Structure {
                            controller: name.clone(),
                            why: "the name is a unit's of the flowsheet".into(),
                        });
                    }
                    spec.controllers.insert(name.clone(), (**c).clone());
                }
                StructureEdit::RemoveController(name) => {
                    if spec.controllers.shift_remove(name).is_none() {
                        let hint = crate::error::did_you_mean(name, spec.controllers.keys().map(String::as_str));
                        return Err(OverrideError::Structure {
                            controller: name.clone(),
                            why: format!("there is no such controller to remove{hint}"),
                        });
                    }
                }
            }
        }
        let mut plant = crate::assemble(&spec, &self.file)?;
        for info in plant.inputs.iter_mut() {
            let Some(&j) = self.input_index.get(&info.path) else { continue };
            if self.assembled_inputs.get(j) != Some(&self.inputs[j].value) {
                info.value = self.inputs[j].value;
            }
        }
        crate::overrides::apply_inputs(&mut plant, &inputs)?;
        Ok(plant)
    }
}

/// One change of a plant's description for [`Plant::restructure`].
#[derive(Debug, Clone, PartialEq)]
pub enum StructureEdit {
    /// Set a field of a unit or controller, or an input's value (as [`Plant::variant`] does).
    Set(Override),
    /// Add a controller, described as the file's `controllers` section holds it (a typed
    /// description: a ratio station's `RatioConfig`, a PID's `PidConfig`).
    AddController {
        /// Its name (not yet a controller's).
        name: String,
        /// Its description.
        spec: Box<plantwide_model::ControllerSpec>,
    },
    /// Remove a controller: the inputs it drove read their own values again.
    RemoveController(String),
    /// Describe controller `name` anew (or add it): a typed description, as the file's
    /// `controllers` section holds it (a tuned PID's new settings).
    SetController {
        /// Its name.
        name: String,
        /// Its description.
        spec: Box<plantwide_model::ControllerSpec>,
    },
    /// Put a new unit with one inlet and one outlet (a surge tank) on a stream: `stream` now ends
    /// at `unit`, and a new stream `outlet` runs from `unit` to where `stream` went.
    InsertOnStream {
        /// The stream cut.
        stream: String,
        /// The new unit's name (not yet a unit's or controller's).
        unit: String,
        /// Its description, as the file's `units` section holds it.
        spec: Box<plantwide_model::UnitSpec>,
        /// The new stream's name (not yet a stream's).
        outlet: String,
    },
}

fn insert_on_stream(
    spec: &mut crate::FlowsheetSpec,
    stream: &str,
    unit: &str,
    u: &plantwide_model::UnitSpec,
    outlet: &str,
) -> Result<(), OverrideError> {
    let fail = |why: String| OverrideError::Structure { controller: unit.to_string(), why };
    if spec.units.contains_key(unit) || spec.controllers.contains_key(unit) {
        return Err(fail("the name is taken by a unit or controller of the flowsheet".into()));
    }
    if spec.streams.contains_key(outlet) {
        return Err(fail(format!("the outlet stream's name `{outlet}` is taken")));
    }
    let Some(cut) = spec.streams.get_mut(stream) else {
        let hint = crate::error::did_you_mean(stream, spec.streams.keys().map(String::as_str));
        return Err(fail(format!("there is no stream `{stream}` to put it on{hint}")));
    };
    let to = std::mem::replace(&mut cut.to, unit.to_string());
    let tear = std::mem::take(&mut cut.tear);
    spec.units.insert(unit.to_string(), u.clone());
    spec.streams.insert(outlet.to_string(), crate::spec::StreamSpec { from: unit.to_string(), to, tear });
    Ok(())
}

fn add_controller(
    spec: &mut crate::FlowsheetSpec,
    name: &str,
    c: &plantwide_model::ControllerSpec,
) -> Result<(), OverrideError> {
    let fail = |why: String| OverrideError::Structure { controller: name.to_string(), why };
    if spec.controllers.contains_key(name) || spec.units.contains_key(name) {
        return Err(fail("the name is taken by a unit or controller of the flowsheet".into()));
    }
    spec.controllers.insert(name.to_string(), c.clone());
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::overrides::{Override, load_str_with};

    pub(super) const TANK: &str = r#"{
      "format_version": 1, "name": "t", "components": ["water"], "thermo": {"vle": "ideal"},
      "units": {
        "inflow": {"type": "feed", "F": "50 mol/s", "T": "300 K", "P": "2 bar", "z": {"water": 1.0}},
        "tank": {"type": "tank", "area": "0.1 m2", "height": "2 m", "outflow": {"type": "flow", "flow": "50 mol/s"}},
        "out": {"type": "product"}
      },
      "streams": {"a": {"from": "inflow", "to": "tank"}, "b": {"from": "tank", "to": "out"}},
      "controllers": {"lc": {"type": "pid", "pv": "tank.level", "output": "tank.outflow", "sp": "1 m",
                             "kc": "50 mol/s/m", "tau_i": "200 s", "action": "direct", "mode": "auto"}}
    }"#;

    #[test]
    fn a_variant_keeps_changed_inputs_and_takes_the_edits_defaults() {
        let plant = load_str_with(TANK, "t.json", &[]).unwrap();
        let auto = plant.input("lc.auto").unwrap();
        let feed = plant.input("inflow.F").unwrap();
        assert_eq!(plant.inputs()[auto].value, 1.0);
        // A field edit that changes an input's default: the variant is in manual.
        let manual = plant.variant(&[Override::new("lc.mode", "manual")]).unwrap();
        assert_eq!(manual.inputs()[manual.input("lc.auto").unwrap()].value, 0.0);
        // An input this plant changed carries over; an input override applies on top.
        let mut changed = plant.clone();
        changed.set_input_value(feed, 55.0);
        let v = changed.variant(&[Override::new("lc.mode", "manual")]).unwrap();
        assert_eq!(v.inputs()[v.input("inflow.F").unwrap()].value, 55.0);
        let v = changed.variant(&[Override::new("inflow.F", "60 mol/s")]).unwrap();
        assert_eq!(v.inputs()[v.input("inflow.F").unwrap()].value, 60.0);
        // Through load_with the same: the edit's default holds.
        let p = load_str_with(TANK, "t.json", &[Override::new("lc.mode", "manual")]).unwrap();
        assert_eq!(p.inputs()[p.input("lc.auto").unwrap()].value, 0.0);
    }
}

#[cfg(test)]
mod variant_tests {
    use crate::overrides::{Override, load_str_with};

    #[test]
    fn a_variant_moves_a_controllers_output_to_another_input() {
        // The same tank with its level held by the inflow instead of the outflow (reverse action):
        // the inventory configuration of the vessel changed, everything else as it was.
        let text = super::tests::TANK;
        let plant = load_str_with(text, "t.json", &[]).unwrap();
        let moved = [Override::new("lc.output", "inflow.F"), Override::new("lc.action", "reverse")];
        let v = plant.variant(&moved).unwrap();
        let driven = |p: &crate::Plant, path: &str| p.inputs()[p.input(path).unwrap()].driven_by;
        assert!(driven(&plant, "tank.outflow").is_some() && driven(&plant, "inflow.F").is_none());
        assert!(driven(&v, "inflow.F").is_some() && driven(&v, "tank.outflow").is_none());
        assert_eq!(v.n_vars(), plant.n_vars());
        // A move to a path that is no input is refused by the assembly, naming it.
        let err = plant.variant(&[Override::new("lc.output", "tank.nothing")]).unwrap_err();
        assert!(err.to_string().contains("tank.nothing"), "{err}");
    }
}

#[cfg(test)]
mod restructure_tests {
    use crate::StructureEdit;
    use crate::overrides::{Override, load_str_with};

    #[test]
    fn controllers_are_added_and_removed_and_a_new_ones_field_set() {
        let plant = load_str_with(super::tests::TANK, "t.json", &[]).unwrap();
        let driven = |p: &crate::Plant, path: &str| p.inputs()[p.input(path).unwrap()].driven_by;
        // The level loop removed: the outflow reads its own value again.
        let open = plant.restructure(&[StructureEdit::RemoveController("lc".into())]).unwrap();
        assert!(open.controller("lc").is_err() && driven(&open, "tank.outflow").is_none());
        // A ratio station on the outflow, then its ratio set: the outflow follows the inflow.
        let ratio: Box<plantwide_model::ControllerSpec> = Box::new(
            serde_json::from_value(
                serde_json::json!({"type": "ratio", "wild": "a.F", "output": "tank.outflow", "ratio": 1.0}),
            )
            .unwrap(),
        );
        let edits = [
            StructureEdit::RemoveController("lc".into()),
            StructureEdit::AddController { name: "rs".into(), spec: ratio.clone() },
            StructureEdit::Set(Override::new("rs.ratio", "0.9")),
        ];
        let v = plant.restructure(&edits).unwrap();
        assert!(driven(&v, "tank.outflow").is_some());
        assert_eq!(v.inputs()[v.input("rs.ratio").unwrap()].value, 0.9);
        // Bad edits are named: a taken name, an unknown controller to remove (a description that
        // is no controller no longer compiles: the edit is typed).
        let bad = [
            (StructureEdit::AddController { name: "tank".into(), spec: ratio }, "controller `tank`: the name is taken"),
            (StructureEdit::RemoveController("lcc".into()), "no such controller to remove"),
        ];
        for (e, msg) in bad {
            let err = plant.restructure(&[e]).unwrap_err().to_string();
            assert!(err.contains(msg), "{err}");
        }
    }

    #[test]
    fn a_tank_put_on_a_stream_receives_it_and_feeds_its_old_destination() {
        use crate::StructureEdit;
        let plant = load_str_with(super::tests::TANK, "t.json", &[]).unwrap();
        let tank = serde_json::json!({"type": "tank", "area": "1 m2", "height": "2 m",
                                      "outflow": {"type": "flow", "flow": "50 mol/s"}});
        let tank = Box::new(serde_json::from_value(tank).unwrap());
        let level = serde_json::json!({"type": "pid", "pv": "surge.level", "output": "surge.outflow", "sp": "1 m",
                                       "kc": "50 mol/s/m", "action": "direct"});
        let level = Box::new(serde_json::from_value(level).unwrap());
        let edits = [
            StructureEdit::InsertOnStream { stream: "b".into(), unit: "surge".into(), spec: tank, outlet: "b2".into() },
            StructureEdit::AddController { name: "surge_level".into(), spec: level },
        ];
        let v = plant.restructure(&edits).unwrap();
        assert_eq!(v.spec().streams["b"].to, "surge");
        assert_eq!((v.spec().streams["b2"].from.as_str(), v.spec().streams["b2"].to.as_str()), ("surge", "out"));
        assert!(v.var("surge.level").is_some() && v.n_vars() > plant.n_vars());
        // A stream that does not exist, or a name already taken, is refused by name.
        let again = |stream: &str, unit: &str| StructureEdit::InsertOnStream {
            stream: stream.into(),
            unit: unit.into(),
            spec: Box::new(serde_json::from_value(serde_json::json!({"type": "product"})).unwrap()),
            outlet: "c".into(),
        };
        let err = plant.restructure(&[again("bb", "surge")]).unwrap_err().to_string();
        assert!(err.contains("no stream `bb`"), "{err}");
        let err = plant.restructure(&[again("b", "tank")]).unwrap_err().to_string();
        assert!(err.contains("taken"), "{err}");
    }
}
