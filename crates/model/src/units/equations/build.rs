//! Building an equations unit from its description, in steps: declare every name (parameters,
//! inputs, ports, variables, tables, thermodynamic functions), compile the equations and the
//! outlets' mappings, match equations to unknowns, and evaluate everything at the guess.

use std::collections::BTreeMap;

use plantwide_expr::{Equation, Expression, Interpolation, SymbolError, SymbolTable, Table, TableError, VarKind};
use plantwide_units::{Dimension, QuantityValue, Unit as UnitOfMeasure, parse_quantity};

use super::thermo::PortFunction;
use super::{EqInterpolation, EqTableConfig, EqVarKind, Equations, EquationsConfig, Row, der_form, stream_names};
use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, VarSpec};

/// An equation compiled from the file: its field, the equation, and for `der(x) = rhs` the
/// right-hand side alone.
type Compiled = (String, Equation, Option<Expression>);

/// What the steps share: the local layout and the names declared so far.
struct Builder<'c, 'a> {
    cx: BuildCx<'a>,
    comps: Vec<String>,
    /// Length of a stream block.
    len: usize,
    outlets: Vec<String>,
    inlets: Vec<String>,
    n_own: usize,
    inlets_at: usize,
    inputs_at: usize,
    symbols: SymbolTable,
    c: &'c EquationsConfig,
}

impl Equations {
    /// Build from the flowsheet description.
    pub fn build(c: &EquationsConfig, cx: BuildCx<'_>, _links: ()) -> Result<Equations, Vec<FieldError>> {
        let comps = cx.components.to_vec();
        let len = Z0 + comps.len();
        let outlets: Vec<String> = c.ports.outlets.keys().cloned().collect();
        let n_own = outlets.len() * len + c.variables.len();
        let inlets_at = n_own;
        let inputs_at = inlets_at + c.ports.inlets.len() * len;
        let inlets = c.ports.inlets.clone();
        let symbols = SymbolTable::new();
        let mut b = Builder { cx, comps, len, outlets, inlets, n_own, inlets_at, inputs_at, symbols, c };
        b.declare_parameters();
        let inputs = b.declare_inputs();
        b.declare_ports();
        let (internal, guesses, differential) = b.declare_variables();
        b.declare_tables();
        b.declare_thermo();
        if !b.cx.errors.is_empty() {
            return Err(b.cx.errors);
        }
        let mut compiled = b.compile_equations(&differential);
        let maps = b.compile_outlet_maps(&mut compiled);
        let outputs = b.check_outputs();
        let duties = b.check_duties();
        let holdup = b.compile_holdup();
        if !b.cx.errors.is_empty() {
            return Err(b.cx.errors);
        }
        let Some((rows, fields, row_names)) = b.assign_rows(compiled) else { return Err(b.cx.errors) };
        let unit = Equations {
            inlets: b.inlets.clone(),
            outlets: b.outlets.clone(),
            internal,
            guesses,
            inputs,
            rows,
            fields,
            maps,
            row_names,
            outputs,
            duties,
            reacts: c.reacts,
            holdup,
        };
        b.cx.finish(unit)
    }
}

/// A quantity given as text with a unit, or as a bare (dimensionless) number.
fn quantity(q: &QuantityValue) -> Result<plantwide_units::Quantity, plantwide_units::UnitError> {
    match q {
        QuantityValue::Number(x) => Ok(plantwide_units::Quantity::new(*x, Dimension::DIMENSIONLESS)),
        QuantityValue::Text(s) => parse_quantity(s),
    }
}

impl Builder<'_, '_> {
    fn declare(&mut self, field: &str, r: Result<(), SymbolError>) {
        if let Err(e) = r {
            self.cx.error(field, e.to_string());
        }
    }

    fn declare_parameters(&mut self) {
        for (name, q) in &self.c.parameters {
            let field = format!("parameters.{name}");
            match quantity(q) {
                Ok(q) => {
                    let r = self.symbols.add_parameter(name, q.value_si, q.dim);
                    self.declare(&field, r);
                }
                Err(e) => self.cx.error(&field, e.to_string()),
            }
        }
    }

    fn declare_inputs(&mut self) -> Vec<InputSpec> {
        let mut inputs = Vec::new();
        for (k, (name, q)) in self.c.inputs.iter().enumerate() {
            let field = format!("inputs.{name}");
            match quantity(q) {
                Ok(q) => {
                    let r = self.symbols.add_variable(name, self.inputs_at + k, q.dim, VarKind::Algebraic);
                    self.declare(&field, r);
                    inputs.push(InputSpec { name: name.clone(), dim: q.dim, value: q.value_si });
                }
                Err(e) => {
                    self.cx.error(&field, e.to_string());
                    inputs.push(InputSpec { name: name.clone(), dim: Dimension::DIMENSIONLESS, value: f64::NAN });
                }
            }
        }
        inputs
    }

    /// Every port's stream quantities, `out.F` … `out.x[c]`, at their local slots.
    fn declare_ports(&mut self) {
        for k in 0..self.outlets.len() {
            let port = self.outlets[k].clone();
            for (name, off, dim) in stream_names(&port, &self.comps) {
                let r = self.symbols.add_variable(&name, k * self.len + off, dim, VarKind::Algebraic);
                self.declare(&format!("ports.outlets.{port}"), r);
            }
        }
        for k in 0..self.inlets.len() {
            let port = self.inlets[k].clone();
            if self.outlets.contains(&port) {
                self.cx.error(&format!("ports.inlets[{k}]"), format!("`{port}` is also an outlet"));
                continue;
            }
            for (name, off, dim) in stream_names(&port, &self.comps) {
                let r = self.symbols.add_variable(&name, self.inlets_at + k * self.len + off, dim, VarKind::Algebraic);
                self.declare(&format!("ports.inlets[{k}]"), r);
            }
        }
    }

    /// The own variables, after the outlet streams: their specs, guesses (SI) and the local
    /// indices of the differential ones.
    fn declare_variables(&mut self) -> (Vec<VarSpec>, Vec<f64>, Vec<usize>) {
        let (mut internal, mut guesses, mut differential) = (Vec::new(), Vec::new(), Vec::new());
        for (i, (name, v)) in self.c.variables.iter().enumerate() {
            let field = format!("variables.{name}");
            let unit = match v.unit.as_deref().map(UnitOfMeasure::parse).transpose() {
                Ok(u) => u,
                Err(e) => {
                    self.cx.error(&format!("{field}.unit"), e.to_string());
                    None
                }
            };
            let dim = unit.as_ref().map_or(Dimension::DIMENSIONLESS, UnitOfMeasure::dimension);
            let si = |x: f64| unit.as_ref().map_or(x, |u| u.to_si(x));
            let lower = v.lower.map_or(f64::NEG_INFINITY, si);
            let upper = v.upper.map_or(f64::INFINITY, si);
            let nominal = match (v.nominal, v.guess) {
                (Some(n), _) => si(n).abs(),
                (None, Some(g)) if si(g) != 0.0 => si(g).abs(),
                _ => 1.0,
            };
            if !(nominal.is_finite() && nominal > 0.0) {
                self.cx.error(&format!("{field}.nominal"), format!("must be finite and nonzero (got {nominal} {dim})"));
            }
            if lower > upper {
                self.cx.error(&field, format!("lower bound {lower} {dim} is above the upper bound {upper} {dim}"));
            }
            let index = self.outlets.len() * self.len + i;
            let (kind, spec) = match v.kind {
                EqVarKind::Differential => {
                    differential.push(index);
                    (VarKind::Differential, VarSpec::differential(name.clone(), dim, nominal))
                }
                EqVarKind::Algebraic => (VarKind::Algebraic, VarSpec::algebraic(name.clone(), dim, nominal)),
            };
            let r = self.symbols.add_variable(name, index, dim, kind);
            self.declare(&field, r);
            internal.push(spec.bounded(lower, upper));
            guesses.push(v.guess.map_or(nominal, si).clamp(lower.min(upper), upper.max(lower)));
        }
        (internal, guesses, differential)
    }

    /// The `tables`, each refused with the position of its first bad point.
    fn declare_tables(&mut self) {
        for (name, t) in &self.c.tables {
            let field = format!("tables.{name}");
            if let Some(table) = self.table(&field, name, t) {
                let r = self.symbols.add_table(name, table);
                self.declare(&field, r);
            }
        }
    }

    fn table(&mut self, field: &str, name: &str, t: &EqTableConfig) -> Option<Table> {
        let mut unit = |key: &str, text: &Option<String>| match text.as_deref().map(UnitOfMeasure::parse).transpose() {
            Ok(u) => Some(u),
            Err(e) => {
                self.cx.error(&format!("{field}.{key}"), e.to_string());
                None
            }
        };
        let (xu, yu) = (unit("x_unit", &t.x_unit)?, unit("y_unit", &t.y_unit)?);
        let si = |u: &Option<UnitOfMeasure>, v: &[f64]| -> Vec<f64> {
            v.iter().map(|&v| u.as_ref().map_or(v, |u| u.to_si(v))).collect()
        };
        let dim = |u: &Option<UnitOfMeasure>| u.as_ref().map_or(Dimension::DIMENSIONLESS, UnitOfMeasure::dimension);
        let interpolation = match t.interpolation {
            EqInterpolation::Linear => Interpolation::Linear,
            EqInterpolation::Spline => Interpolation::CubicSpline,
        };
        match Table::new(si(&xu, &t.x), si(&yu, &t.y), interpolation, dim(&xu), dim(&yu)) {
            Ok(table) => Some(table),
            Err(e) => {
                let at = match &e {
                    TableError::NotIncreasing { index, .. } => format!("{field}.x[{index}]"),
                    TableError::NonFinite { index } if !si(&xu, &t.x)[*index].is_finite() => {
                        format!("{field}.x[{index}]")
                    }
                    TableError::NonFinite { index } => format!("{field}.y[{index}]"),
                    TableError::LengthMismatch { .. } => format!("{field}.y"),
                    _ => format!("{field}.x"),
                };
                self.cx.error(&at, format!("table `{name}`: {e}"));
                None
            }
        }
    }

    /// The thermodynamic functions of the ports' states ([`super::thermo`]), under the names a
    /// parameter, variable or table of the file has not taken.
    fn declare_thermo(&mut self) {
        let mut ports: Vec<(String, usize)> =
            self.outlets.iter().enumerate().map(|(k, p)| (p.clone(), k * self.len)).collect();
        ports.extend(self.inlets.iter().enumerate().map(|(k, p)| (p.clone(), self.inlets_at + k * self.len)));
        let pressures: Vec<(String, usize)> = self
            .symbols
            .names()
            .filter_map(|n| match self.symbols.get(n) {
                Some(plantwide_expr::Symbol::Variable { index, dim, .. }) if *dim == Dimension::PRESSURE => {
                    Some((n.to_owned(), *index))
                }
                _ => None,
            })
            .collect();
        for (name, f) in PortFunction::all(self.cx.thermo, ports, &self.comps, pressures) {
            if self.symbols.get(name).is_none() {
                let r = self.symbols.add_function(name, f);
                self.declare("equations", r);
            }
        }
    }

    /// The file's equations; a differential variable's `der(x) = rhs` keeps `rhs` alone.
    fn compile_equations(&mut self, differential: &[usize]) -> Vec<Compiled> {
        let mut compiled = Vec::new();
        let mut der_of: BTreeMap<usize, String> = BTreeMap::new();
        let mut failed_der: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
        for (k, text) in self.c.equations.iter().enumerate() {
            let field = format!("equations[{k}]");
            let eq = match Equation::new(text, &self.symbols) {
                Ok(eq) => eq,
                Err(e) => {
                    self.cx.error(&field, e.render());
                    // Its `der(x)`, if it gives one, is reported there: not again as missing.
                    if let Ok(ast) = plantwide_expr::parse_equation(text)
                        && let plantwide_expr::ast::ExprKind::Der { name, .. } = ast.lhs.kind
                    {
                        failed_der.insert(name);
                    }
                    continue;
                }
            };
            let rhs = match eq.derivatives() {
                [] => None,
                &[i] => match der_form(text, &self.symbols) {
                    Some(rhs) => {
                        if let Some(other) = der_of.insert(i, field.clone()) {
                            let name = self.symbols.variable_name(i).unwrap_or("?");
                            self.cx.error(&field, format!("`der({name})` is already given by {other}: a differential variable has exactly one equation `der({name}) = …`"));
                        }
                        Some(rhs)
                    }
                    None => {
                        let name = self.symbols.variable_name(i).unwrap_or("x");
                        self.cx.error(&field, format!("write the equation of a differential variable as `der({name}) = <expression without der()>`: the engine's model is M x' = f(x)\n{text}"));
                        continue;
                    }
                },
                _ => {
                    let msg =
                        format!("an equation may hold one `der()`, as `der(x) = <expression without der()>`\n{text}");
                    self.cx.error(&field, msg);
                    continue;
                }
            };
            compiled.push((field, eq, rhs));
        }
        for &i in differential {
            let name = self.symbols.variable_name(i).unwrap_or("?");
            if !der_of.contains_key(&i) && !failed_der.contains(name) {
                let msg = format!("differential variable `{name}` needs one equation `der({name}) = …`");
                self.cx.error(&format!("variables.{name}"), msg);
            }
        }
        compiled
    }

    /// Each outlet's mappings `out.Q = expr`, then for each outlet that maps no `h` the closure
    /// `out.h = h_L(out)`; all appended to `compiled`. Returns them by the local index of `out.Q`,
    /// in that order, for the guess.
    fn compile_outlet_maps(&mut self, compiled: &mut Vec<Compiled>) -> Vec<(usize, Equation)> {
        let mut maps = Vec::new();
        let mut closures = Vec::new();
        for (k, port) in self.outlets.clone().iter().enumerate() {
            let map = &self.c.ports.outlets[port];
            let names = stream_names(port, &self.comps);
            let quantity = |q: &str| names.iter().find(|(n, _, _)| n[port.len() + 1..] == *q).map(|&(_, off, _)| off);
            if !map.contains_key("h") {
                let text = format!("{port}.h = h_L({port})");
                match Equation::new(&text, &self.symbols) {
                    Ok(eq) => closures.push((format!("ports.outlets.{port}"), k * self.len + H, eq)),
                    Err(e) => self.cx.error(&format!("ports.outlets.{port}"), e.render()),
                }
            }
            for (q, expr) in map {
                let field = format!("ports.outlets.{port}.{q}");
                let Some(off) = quantity(q) else {
                    let known: Vec<&str> = names.iter().map(|(n, _, _)| &n[port.len() + 1..]).collect();
                    let msg = format!("`{q}` is not a stream quantity (those are {})", known.join(", "));
                    self.cx.error(&field, msg);
                    continue;
                };
                let text = format!("{port}.{q} = {expr}");
                match Equation::new(&text, &self.symbols) {
                    Ok(eq) if eq.derivatives().is_empty() => {
                        maps.push((k * self.len + off, eq.clone()));
                        compiled.push((field, eq, None));
                    }
                    Ok(_) => self.cx.error(&field, format!("a port's quantity may not read `der()`\n{text}")),
                    Err(e) => self.cx.error(&field, e.render()),
                }
            }
        }
        for (field, at, eq) in closures {
            maps.push((at, eq.clone()));
            compiled.push((field, eq, None));
        }
        maps
    }

    fn check_outputs(&mut self) -> Vec<String> {
        let mut outputs = Vec::new();
        for (k, name) in self.c.outputs.iter().enumerate() {
            match self.symbols.get(name) {
                Some(plantwide_expr::Symbol::Variable { index, .. }) if *index < self.n_own => {
                    outputs.push(name.clone())
                }
                _ => {
                    let hint = self.symbols.suggest(name).map(|s| format!("; did you mean `{s}`?")).unwrap_or_default();
                    self.cx.error(&format!("outputs[{k}]"), format!("`{name}` is not a variable of the unit{hint}"));
                }
            }
        }
        outputs
    }

    /// Each name in `duties`: an own variable or an input, in watts.
    fn check_duties(&mut self) -> Vec<crate::capability::Duty> {
        use crate::capability::{Booking, Duty, DutySource};
        let mut duties = Vec::new();
        for (k, name) in self.c.duties.iter().enumerate() {
            let field = format!("duties[{k}]");
            let (index, dim) = match self.symbols.get(name) {
                Some(plantwide_expr::Symbol::Variable { index, dim, .. }) => (*index, *dim),
                _ => {
                    let hint = self.symbols.suggest(name).map(|s| format!("; did you mean `{s}`?")).unwrap_or_default();
                    self.cx.error(&field, format!("`{name}` is not a variable or input of the unit{hint}"));
                    continue;
                }
            };
            let source = match index {
                _ if dim != Dimension::POWER => {
                    self.cx.error(&field, format!("`{name}` is in {dim}, not a heat duty (W)"));
                    continue;
                }
                i if i < self.n_own => DutySource::Var(name.clone().into()),
                i if i >= self.inputs_at => DutySource::Input(name.clone().into()),
                _ => {
                    self.cx.error(&field, format!("`{name}` is a port's stream quantity, not a duty of the unit"));
                    continue;
                }
            };
            duties.push(Duty { source, booking: Booking::Utility });
        }
        duties
    }

    fn compile_holdup(&mut self) -> Vec<Option<Expression>> {
        if self.c.holdup.is_empty() {
            return Vec::new();
        }
        let mut holdup = vec![None; self.comps.len()];
        for (name, text) in &self.c.holdup {
            let field = format!("holdup.{name}");
            let Some(i) = self.comps.iter().position(|c| c == name) else {
                let msg = format!("`{name}` is not a component (components: {})", self.comps.join(", "));
                self.cx.error(&field, msg);
                continue;
            };
            match Expression::new(text, &self.symbols) {
                Ok(e) if e.dimension() == Dimension::AMOUNT && e.derivatives().is_empty() => holdup[i] = Some(e),
                Ok(e) => {
                    let msg = format!("a holdup is an amount (mol) without der(), found {}", e.dimension());
                    self.cx.error(&field, msg)
                }
                Err(e) => self.cx.error(&field, e.render()),
            }
        }
        holdup
    }

    /// Rows: a perfect matching of equations to the unknowns in dynamic mode (derivatives of the
    /// differential variables, the algebraic own variables), as `check_structure` does; `None`
    /// (and an error naming what is left unmatched) when the set is structurally singular.
    #[allow(clippy::type_complexity)]
    fn assign_rows(&mut self, compiled: Vec<Compiled>) -> Option<(Vec<Row>, Vec<String>, BTreeMap<usize, String>)> {
        let symbols = &self.symbols;
        let n_own = self.n_own;
        let is_differential = |i: usize| symbols.variable_kind(i) == Some(VarKind::Differential);
        let incidence: Vec<Vec<usize>> = compiled
            .iter()
            .map(|(_, eq, _)| {
                let alg = eq.variables().iter().copied().filter(|&i| i < n_own && !is_differential(i));
                alg.chain(eq.derivatives().iter().copied()).collect()
            })
            .collect();
        let matching = plantwide_expr::maximum_matching(n_own, &incidence);
        if !matching.is_perfect() {
            let name = |i: usize| {
                let base = symbols.variable_name(i).map_or_else(|| format!("x[{i}]"), str::to_owned);
                if is_differential(i) { format!("der({base})") } else { base }
            };
            let unmatched_eqs: Vec<&str> =
                matching.unmatched_equations().into_iter().map(|e| compiled[e].1.text()).collect();
            let unmatched: Vec<String> = matching.unmatched_unknowns().into_iter().map(name).collect();
            let msg = format!(
                "the equations are structurally singular ({} equations, {n_own} unknowns); left without an unknown: {}; left without an equation: {}",
                incidence.len(),
                plantwide_expr::name_list(&unmatched_eqs),
                plantwide_expr::name_list(&unmatched),
            );
            self.cx.error("equations", msg);
            // Each equation left over, at its own field with the whole text marked: every unknown it
            // reads is already determined by the others, so it over-determines them.
            for e in matching.unmatched_equations() {
                let (field, eq, _) = &compiled[e];
                let text = eq.text();
                let caret = plantwide_expr::render_caret(text, plantwide_expr::Span { start: 0, end: text.len() });
                let why = "structurally singular: every unknown this equation reads is already determined by the \
                           others, so it over-determines them (remove it or give it an unknown of its own)";
                self.cx.error(field, format!("{why}\n{caret}"));
            }
            return None;
        }
        let (mut rows, mut fields, mut row_names) = (Vec::new(), Vec::new(), BTreeMap::new());
        for ((field, eq, rhs), row) in compiled.into_iter().zip(&matching.unknown_of) {
            let row = row.unwrap_or_default();
            row_names.insert(row, format!("{field}: {}", eq.text()));
            fields.push(field);
            rows.push(match rhs {
                Some(rhs) => Row::Derivative { row, rhs },
                None => Row::Algebraic { row, eq },
            });
        }
        Some((rows, fields, row_names))
    }
}

/// The stream every stream of a plant starts from before its units are guessed
/// (`Plant::initial_guess`): 1 mol/s, 300 K, 1 atm, uniform composition and its liquid
/// enthalpy.
pub(super) fn cold_start_stream(thermo: &plantwide_thermo::ThermoPackage, s: &mut [f64]) {
    let nc = s.len() - Z0;
    s[F] = 1.0;
    s[T] = 300.0;
    s[P] = 101_325.0;
    s[Z0..].iter_mut().for_each(|x| *x = 1.0 / nc as f64);
    s[H] = thermo.h_liq(300.0, &s[Z0..]);
}
