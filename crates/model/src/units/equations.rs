//! A unit written as equations in the flowsheet file (issue 57): parameters with units, its own
//! differential and algebraic variables, equations as text, inlet and outlet ports and inputs.
//!
//! ```json
//! {"type": "equations",
//!  "parameters": {"area": "0.5 m2", "rho": "1e4 mol/m3", "k": "2 mol/(s*m)"},
//!  "variables": {"M": {"kind": "differential", "unit": "mol", "guess": 5000},
//!                "level": {"kind": "algebraic", "unit": "m", "guess": 1, "lower": 0}},
//!  "equations": ["der(M) = in.F - out.F", "level*area*rho = M"],
//!  "ports": {"inlets": ["in"],
//!            "outlets": {"out": {"F": "k*level", "T": "in.T", "P": "in.P", "x[A]": "in.x[A]", "x[B]": "in.x[B]"}}}}
//! ```
//!
//! # Names in equations
//! Parameters and inputs by their names, own variables by theirs, and every port's stream
//! quantities as `<port>.F`, `<port>.T`, `<port>.P`, `<port>.h` and `<port>.x[<component>]`.
//!
//! # Layout and the mass matrix
//! Own variables are the outlet streams (`[F, T, P, h, x…]` each, ports in name order), then the
//! `variables` in name order. Every name is bound to its slot of the unit's *local vector*, so the
//! compiled tapes read [`UnitIo::local`] directly (no copy) with an empty `dx`.
//!
//! The engine's DAE is semi-explicit, `M x' = f(x)`: the residual of a differential variable is
//! its time derivative. So each differential variable needs exactly one equation
//! `der(x) = rhs` with `rhs` free of `der()`; its residual is `rhs` (not `der(x) − rhs`), written
//! at the variable's own row, where the mass matrix has its 1. Every other equation is algebraic,
//! residual `lhs − rhs`, placed at the row of the algebraic unknown a perfect matching assigns it
//! (as `check_structure` in dynamic mode, the closed outlet enthalpies included): so the unit is
//! square and its rows pair with unknowns. In dynamic mode a differential variable is a known
//! state, so `der(x) = rhs` can only take `der(x)`: its row is always `x`'s own.
//!
//! # Ports
//! Inlets are read as known values. Each outlet maps some of its stream quantities to
//! expressions, each the equation `out.Q = expr`; a quantity it does not map (`F`, `T`, `P`,
//! `x[c]`) is an unknown the `equations` must determine (`U = M*out.h` gives `out.T`), else the set
//! is refused as structurally singular naming it. An unmapped `h` is closed by the unit as the
//! liquid enthalpy `h = h_L(T, x)` of the thermodynamic package (the expression layer has no
//! thermodynamic functions yet): one more equation of the set, which the matching places like
//! the others (with `U = M*out.h` it takes `out.T`'s row and the balance `h`'s).
//!
//! # Material
//! `holdup` gives each component's amount \[mol\] as an expression (for a dynamic run's
//! conservation check) and `reacts: true` makes the steady-state certificate check mass instead
//! of each component; without them the unit is taken to hold nothing and to conserve every
//! component.
//!
//! # Checks at load
//! Names, dimensions (both sides, each outlet mapping against its stream quantity), the `der()`
//! form, a structurally singular set (dynamic mode), and each equation evaluated at the guesses
//! (variables at their `guess`, inlets at 1 mol/s, 300 K, 1 bar, h = 0, uniform x): a division by
//! zero or a logarithm of a non-positive number there is refused with its position.

use std::collections::BTreeMap;

use plantwide_expr::{Equation, Expression, SymbolTable, parse_equation};
use plantwide_units::{Dimension, QuantityValue, Unit as UnitOfMeasure, parse_quantity};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::stream::{F, H, P, T, Z0};
use crate::{BuildCx, FieldError, InputSpec, LocalLayout, Scalar, UnitIo, UnitModel, VarSpec};

/// Whether a variable of an equations unit has a time derivative.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum EqVarKind {
    /// Given by one equation `der(x) = rhs`.
    Differential,
    /// Determined by the algebraic equations.
    Algebraic,
}

/// One variable of an equations unit; `guess`, `nominal`, `lower` and `upper` are in `unit`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EqVariableConfig {
    /// Differential or algebraic.
    pub kind: EqVarKind,
    /// Unit of the values below and hence the variable's dimension (`"mol"`, `"K"`,
    /// `"mol/m3"`; default dimensionless).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// Typical magnitude, for scaling (default: |guess|, or 1 if that is 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal: Option<f64>,
    /// Initial guess (default: the nominal, else 0 … within the bounds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guess: Option<f64>,
    /// Lower bound Newton honours (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    /// Upper bound Newton honours (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
}

/// The ports of an equations unit.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EqPortsConfig {
    /// Inlet port names; their stream quantities (`in.F`, `in.x[A]`, …) are known values.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inlets: Vec<String>,
    /// Outlet ports by name, each mapping some of its stream quantities (`F`, `T`, `P`, `x[<c>]`,
    /// `h`) to expressions; the equations determine the others, and an unmapped `h` is the liquid
    /// enthalpy at the outlet's `T` and `x`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub outlets: BTreeMap<String, BTreeMap<String, String>>,
}

/// Flowsheet description of a unit written as equations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct EquationsConfig {
    /// Constants by name, with units (`"0.5 m3"`, `"80 kJ/mol"`; a bare number is dimensionless).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub parameters: BTreeMap<String, QuantityValue>,
    /// Manipulable inputs by name, with units and their value when no controller drives them.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub inputs: BTreeMap<String, QuantityValue>,
    /// The unit's own variables by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub variables: BTreeMap<String, EqVariableConfig>,
    /// Equations as text (`"der(M) = in.F - out.F"`).
    pub equations: Vec<String>,
    /// Inlet and outlet ports.
    #[serde(default)]
    pub ports: EqPortsConfig,
    /// Names of the variables that can be measured (default none listed).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outputs: Vec<String>,
    /// The amount (mol) of each component the unit holds, as an expression (`{"A": "NA"}`;
    /// unlisted components hold none); without it the unit holds no material, and a dynamic
    /// run's conservation check would miss what it accumulates.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub holdup: BTreeMap<String, String>,
    /// Whether the equations turn components into one another (default false): the steady-state
    /// certificate then checks the plant's mass balance, not each component's.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reacts: bool,
}

impl crate::registry::UnitConfig for EquationsConfig {
    fn ports() -> &'static str {
        "the inlets and outlets its `ports` name"
    }
}

/// How a compiled equation writes its residual.
#[derive(Debug, Clone, PartialEq)]
enum Row {
    /// `der(x) = rhs`: the residual is `rhs` (the time derivative of own variable `row`).
    Derivative { row: usize, rhs: Expression },
    /// `lhs = rhs`: the residual is `lhs − rhs`.
    Algebraic { row: usize, eq: Equation },
}

/// A unit written as equations.
#[derive(Debug, Clone)]
pub struct Equations {
    inlets: Vec<String>,
    outlets: Vec<String>,
    internal: Vec<VarSpec>,
    guesses: Vec<f64>,
    inputs: Vec<InputSpec>,
    rows: Vec<Row>,
    /// The field each row comes from (`equations[2]`, `ports.outlets.out.F`).
    fields: Vec<String>,
    /// The outlets' mappings `out.Q = expr` by the local index of `out.Q`, for the guess.
    maps: Vec<(usize, Equation)>,
    /// Outlet enthalpies closed by the unit as `h = h_L(T, x)`: `(row, outlet)`, the row the
    /// matching gave the equation (not necessarily `h`'s own: `U = M*out.h` may take that one).
    default_h: Vec<(usize, usize)>,
    /// Names of own rows, for diagnostics.
    row_names: BTreeMap<usize, String>,
    outputs: Vec<String>,
    reacts: bool,
    /// Per component, the expression of its holdup \[mol\] (`None`: none held); empty: no holdup.
    holdup: Vec<Option<Expression>>,
}

/// Stream quantities of a port, with their offsets in a stream block and dimensions.
fn stream_names(port: &str, components: &[String]) -> Vec<(String, usize, Dimension)> {
    let mut v = vec![
        (format!("{port}.F"), F, Dimension::MOLAR_FLOW),
        (format!("{port}.T"), T, Dimension::TEMPERATURE),
        (format!("{port}.P"), P, Dimension::PRESSURE),
        (format!("{port}.h"), H, Dimension::MOLAR_ENERGY),
    ];
    v.extend(components.iter().enumerate().map(|(i, c)| (format!("{port}.x[{c}]"), Z0 + i, Dimension::DIMENSIONLESS)));
    v
}

impl Equations {
    /// Build from the flowsheet description.
    pub fn build(c: &EquationsConfig, mut cx: BuildCx<'_>, _links: ()) -> Result<Equations, Vec<FieldError>> {
        let comps = cx.components.to_vec();
        let nc = comps.len();
        let len = Z0 + nc;
        let outlets: Vec<String> = c.ports.outlets.keys().cloned().collect();
        let inlets = c.ports.inlets.clone();
        let n_out = outlets.len();
        let n_own = n_out * len + c.variables.len();
        let inlets_at = n_own;
        let inputs_at = inlets_at + inlets.len() * len;
        let mut symbols = SymbolTable::new();
        let declare = |cx: &mut BuildCx<'_>, field: &str, r: Result<(), plantwide_expr::SymbolError>| {
            if let Err(e) = r {
                cx.error(field, e.to_string());
            }
        };
        for (name, q) in &c.parameters {
            let field = format!("parameters.{name}");
            let parsed = match q {
                QuantityValue::Number(x) => Ok(plantwide_units::Quantity::new(*x, Dimension::DIMENSIONLESS)),
                QuantityValue::Text(s) => parse_quantity(s),
            };
            match parsed {
                Ok(q) => declare(&mut cx, &field, symbols.add_parameter(name, q.value_si, q.dim)),
                Err(e) => cx.error(&field, e.to_string()),
            }
        }
        let mut inputs = Vec::new();
        for (k, (name, q)) in c.inputs.iter().enumerate() {
            let field = format!("inputs.{name}");
            let parsed = match q {
                QuantityValue::Number(x) => Ok(plantwide_units::Quantity::new(*x, Dimension::DIMENSIONLESS)),
                QuantityValue::Text(s) => parse_quantity(s),
            };
            match parsed {
                Ok(q) => {
                    let r = symbols.add_variable(name, inputs_at + k, q.dim, plantwide_expr::VarKind::Algebraic);
                    declare(&mut cx, &field, r);
                    inputs.push(InputSpec { name: name.clone(), dim: q.dim, value: q.value_si });
                }
                Err(e) => {
                    cx.error(&field, e.to_string());
                    inputs.push(InputSpec { name: name.clone(), dim: Dimension::DIMENSIONLESS, value: f64::NAN });
                }
            }
        }
        for (k, port) in outlets.iter().enumerate() {
            for (name, off, dim) in stream_names(port, &comps) {
                let r = symbols.add_variable(&name, k * len + off, dim, plantwide_expr::VarKind::Algebraic);
                declare(&mut cx, &format!("ports.outlets.{port}"), r);
            }
        }
        for (k, port) in inlets.iter().enumerate() {
            if outlets.contains(port) {
                cx.error(&format!("ports.inlets[{k}]"), format!("`{port}` is also an outlet"));
                continue;
            }
            for (name, off, dim) in stream_names(port, &comps) {
                let r = symbols.add_variable(&name, inlets_at + k * len + off, dim, plantwide_expr::VarKind::Algebraic);
                declare(&mut cx, &format!("ports.inlets[{k}]"), r);
            }
        }
        // Own variables, after the outlet streams.
        let mut internal = Vec::new();
        let mut guesses = Vec::new();
        let mut differential = Vec::new();
        for (i, (name, v)) in c.variables.iter().enumerate() {
            let field = format!("variables.{name}");
            let unit = match v.unit.as_deref().map(UnitOfMeasure::parse).transpose() {
                Ok(u) => u,
                Err(e) => {
                    cx.error(&format!("{field}.unit"), e.to_string());
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
                cx.error(&format!("{field}.nominal"), format!("must be finite and nonzero (got {nominal} {dim})"));
            }
            if lower > upper {
                cx.error(&field, format!("lower bound {lower} {dim} is above the upper bound {upper} {dim}"));
            }
            let guess = v.guess.map_or(nominal, si).clamp(lower.min(upper), upper.max(lower));
            let index = n_out * len + i;
            let kind = match v.kind {
                EqVarKind::Differential => {
                    differential.push(index);
                    plantwide_expr::VarKind::Differential
                }
                EqVarKind::Algebraic => plantwide_expr::VarKind::Algebraic,
            };
            declare(&mut cx, &field, symbols.add_variable(name, index, dim, kind));
            let spec = match v.kind {
                EqVarKind::Differential => VarSpec::differential(name.clone(), dim, nominal),
                EqVarKind::Algebraic => VarSpec::algebraic(name.clone(), dim, nominal),
            };
            internal.push(spec.bounded(lower, upper));
            guesses.push(guess);
        }
        if !cx.errors.is_empty() {
            return Err(cx.errors);
        }

        // Compile the equations: the file's, then the outlets' mappings.
        let mut compiled: Vec<(String, Equation, Option<Expression>)> = Vec::new();
        let mut der_of: BTreeMap<usize, String> = BTreeMap::new();
        for (k, text) in c.equations.iter().enumerate() {
            let field = format!("equations[{k}]");
            let eq = match Equation::new(text, &symbols) {
                Ok(eq) => eq,
                Err(e) => {
                    cx.error(&field, e.render());
                    continue;
                }
            };
            let rhs = match eq.derivatives() {
                [] => None,
                &[i] => match der_form(text, &symbols) {
                    Some(rhs) => {
                        if let Some(other) = der_of.insert(i, field.clone()) {
                            let name = symbols.variable_name(i).unwrap_or("?");
                            cx.error(&field, format!("`der({name})` is already given by {other}: a differential variable has exactly one equation `der({name}) = …`"));
                        }
                        Some(rhs)
                    }
                    None => {
                        let name = symbols.variable_name(i).unwrap_or("x");
                        cx.error(&field, format!("write the equation of a differential variable as `der({name}) = <expression without der()>`: the engine's model is M x' = f(x)\n{text}"));
                        continue;
                    }
                },
                _ => {
                    cx.error(
                        &field,
                        format!("an equation may hold one `der()`, as `der(x) = <expression without der()>`\n{text}"),
                    );
                    continue;
                }
            };
            compiled.push((field, eq, rhs));
        }
        for &i in &differential {
            if !der_of.contains_key(&i) {
                let name = symbols.variable_name(i).unwrap_or("?");
                cx.error(
                    &format!("variables.{name}"),
                    format!("differential variable `{name}` needs one equation `der({name}) = …`"),
                );
            }
        }
        let mut default_h = Vec::new();
        let mut maps = Vec::new();
        for (k, port) in outlets.iter().enumerate() {
            let map = &c.ports.outlets[port];
            for (name, _, _) in stream_names(port, &comps) {
                let q = &name[port.len() + 1..];
                if q == "h" && !map.contains_key("h") {
                    default_h.push(k);
                }
            }
            for (q, expr) in map {
                let field = format!("ports.outlets.{port}.{q}");
                if !stream_names(port, &comps).iter().any(|(n, _, _)| n[port.len() + 1..] == **q) {
                    let known: Vec<String> = stream_names(port, &comps)
                        .into_iter()
                        .map(|(n, _, _)| n[port.len() + 1..].to_owned())
                        .collect();
                    cx.error(&field, format!("`{q}` is not a stream quantity (those are {})", known.join(", ")));
                    continue;
                }
                let text = format!("{port}.{q} = {expr}");
                let Some(&(_, off, _)) = stream_names(port, &comps).iter().find(|(n, _, _)| n[port.len() + 1..] == **q)
                else {
                    continue;
                };
                match Equation::new(&text, &symbols) {
                    Ok(eq) if eq.derivatives().is_empty() => {
                        maps.push((k * len + off, eq.clone()));
                        compiled.push((field, eq, None));
                    }
                    Ok(_) => cx.error(&field, format!("a port's quantity may not read `der()`\n{text}")),
                    Err(e) => cx.error(&field, e.render()),
                }
            }
        }
        let mut outputs = Vec::new();
        for (k, name) in c.outputs.iter().enumerate() {
            match symbols.get(name) {
                Some(plantwide_expr::Symbol::Variable { index, .. }) if *index < n_own => outputs.push(name.clone()),
                _ => {
                    let hint = symbols.suggest(name).map(|s| format!("; did you mean `{s}`?")).unwrap_or_default();
                    cx.error(&format!("outputs[{k}]"), format!("`{name}` is not a variable of the unit{hint}"));
                }
            }
        }
        let mut holdup = Vec::new();
        if !c.holdup.is_empty() {
            holdup = vec![None; nc];
            for (name, text) in &c.holdup {
                let field = format!("holdup.{name}");
                let Some(i) = comps.iter().position(|c| c == name) else {
                    cx.error(&field, format!("`{name}` is not a component (components: {})", comps.join(", ")));
                    continue;
                };
                match Expression::new(text, &symbols) {
                    Ok(e) if e.dimension() == Dimension::AMOUNT && e.derivatives().is_empty() => holdup[i] = Some(e),
                    Ok(e) => {
                        cx.error(&field, format!("a holdup is an amount (mol) without der(), found {}", e.dimension()))
                    }
                    Err(e) => cx.error(&field, e.render()),
                }
            }
        }
        if !cx.errors.is_empty() {
            return Err(cx.errors);
        }

        // Rows: a perfect matching of equations to the unknowns in dynamic mode (derivatives of the
        // differential variables, the algebraic own variables), the closed outlet enthalpies
        // `h = h_L(T, x)` included as rows of their own that read `h`, `T` and `x`: so `U = M*out.h`
        // determines `out.T`. (As `check_structure`, with those extra rows.)
        let h_rows: Vec<usize> = default_h.iter().map(|&k| k * len + H).collect();
        let is_differential = |i: usize| symbols.variable_kind(i) == Some(plantwide_expr::VarKind::Differential);
        let mut incidence: Vec<Vec<usize>> = compiled
            .iter()
            .map(|(_, eq, _)| {
                let alg = eq.variables().iter().copied().filter(|&i| i < n_own && !is_differential(i));
                alg.chain(eq.derivatives().iter().copied()).collect()
            })
            .collect();
        for &r in &h_rows {
            incidence.push([r, r - H + T].into_iter().chain((0..nc).map(|i| r - H + Z0 + i)).collect());
        }
        let matching = plantwide_expr::maximum_matching(n_own, &incidence);
        if !matching.is_perfect() {
            let name = |i: usize| {
                let base = symbols.variable_name(i).map_or_else(|| format!("x[{i}]"), str::to_owned);
                if is_differential(i) { format!("der({base})") } else { base }
            };
            let text = |e: usize| match compiled.get(e) {
                Some((_, eq, _)) => eq.text().to_owned(),
                None => format!("{}.h = h_L(T, x)", outlets[h_rows[e - compiled.len()] / len]),
            };
            let list = |v: Vec<String>| {
                if v.is_empty() {
                    "none".to_owned()
                } else {
                    v.iter().map(|s| format!("`{s}`")).collect::<Vec<_>>().join(", ")
                }
            };
            cx.error(
                "equations",
                format!(
                    "the equations are structurally singular ({} equations, {n_own} unknowns); left without an unknown: {}; left without an equation: {}",
                    incidence.len(),
                    list(matching.unmatched_equations().into_iter().map(text).collect()),
                    list(matching.unmatched_unknowns().into_iter().map(name).collect()),
                ),
            );
            return Err(cx.errors);
        }
        let assigned: Vec<usize> =
            matching.unknown_of.iter().take(compiled.len()).map(|u| u.unwrap_or_default()).collect();
        let mut row_names = BTreeMap::new();
        let mut rows = Vec::new();
        let mut fields = Vec::new();
        let n_compiled = assigned.len();
        for ((field, eq, rhs), row) in compiled.into_iter().zip(assigned) {
            row_names.insert(row, format!("{field}: {}", eq.text()));
            fields.push(field);
            rows.push(match rhs {
                Some(rhs) => Row::Derivative { row, rhs },
                None => Row::Algebraic { row, eq },
            });
        }
        let default_h: Vec<(usize, usize)> = default_h
            .iter()
            .enumerate()
            .map(|(e, &k)| (matching.unknown_of[n_compiled + e].unwrap_or_default(), k))
            .collect();
        for &(row, k) in &default_h {
            row_names.insert(row, format!("{}.h = h_L(T, x)", outlets[k]));
        }

        // Evaluate every equation at the guesses: a zero denominator or a logarithm out of its
        // domain there would stop Newton at its first step.
        let layout = LocalLayout {
            stream: crate::StreamLayout { n_comp: nc },
            n_outlets: n_out,
            n_internal: internal.len(),
            n_inlets: inlets.len(),
            n_inputs: inputs.len(),
            n_signals: 0,
        };
        let mut local = vec![0.0; layout.len()];
        for k in 0..inlets.len() {
            representative_stream(&mut local[inlets_at + k * len..inlets_at + (k + 1) * len]);
        }
        inputs.iter().enumerate().for_each(|(k, i)| local[inputs_at + k] = i.value);
        let unit = Equations {
            inlets,
            outlets,
            internal,
            guesses,
            inputs,
            rows,
            fields,
            maps,
            default_h,
            row_names,
            outputs,
            reacts: c.reacts,
            holdup,
        };
        let mut own = vec![0.0; n_own];
        unit.guess(&UnitIo { local: &local, layout: &layout, thermo: cx.thermo, time: 0.0 }, &mut own);
        local[..n_own].copy_from_slice(&own);
        for (row, field) in unit.rows.iter().zip(&unit.fields) {
            let result = match row {
                Row::Derivative { rhs, .. } => rhs.check_at(&local, &[]),
                Row::Algebraic { eq, .. } => eq.check_at(&local, &[]),
            };
            if let Err(e) = result {
                cx.error(field, format!("at the guess: {}", e.render()));
            }
        }
        cx.finish(unit)
    }

    /// The names the file declares measurable (`outputs`).
    pub fn outputs(&self) -> &[String] {
        &self.outputs
    }

    /// Structural nonzeros `(row, local column)`: what each row's tape reads.
    fn row_reads(&self, layout: &LocalLayout) -> Vec<(usize, usize)> {
        let len = layout.stream.len();
        let mut p = Vec::new();
        for row in &self.rows {
            let (r, vars) = match row {
                Row::Derivative { row, rhs } => (*row, rhs.variables()),
                Row::Algebraic { row, eq } => (*row, eq.variables()),
            };
            p.extend(vars.iter().map(|&j| (r, j)));
        }
        for &(row, k) in &self.default_h {
            let o = k * len;
            p.extend([(row, o + H), (row, o + T)]);
            p.extend((0..layout.stream.n_comp).map(|i| (row, o + Z0 + i)));
        }
        p
    }
}

/// A stream at 1 mol/s, 300 K, 1 bar, h = 0 and uniform composition, for checks at load.
fn representative_stream(s: &mut [f64]) {
    let nc = s.len() - Z0;
    s[F] = 1.0;
    s[T] = 300.0;
    s[P] = 1e5;
    s[H] = 0.0;
    s[Z0..].iter_mut().for_each(|x| *x = 1.0 / nc as f64);
}

/// The right-hand side of `text` compiled alone if `text` reads `der(name) = rhs` with `rhs`
/// free of `der()`.
fn der_form(text: &str, symbols: &SymbolTable) -> Option<Expression> {
    let ast = parse_equation(text).ok()?;
    if !matches!(ast.lhs.kind, plantwide_expr::ast::ExprKind::Der { .. }) {
        return None;
    }
    let rhs = Expression::new(ast.rhs.span.slice(text), symbols).ok()?;
    rhs.derivatives().is_empty().then_some(rhs)
}

impl UnitModel for Equations {
    fn type_name(&self) -> &'static str {
        "equations"
    }
    fn inlet_ports(&self) -> Vec<String> {
        self.inlets.clone()
    }
    fn outlet_ports(&self) -> Vec<String> {
        self.outlets.clone()
    }
    fn boundary(&self) -> crate::Boundary {
        // By its ports, as the flowsheet's boundaries go: no inlet (a port-less model too) is a
        // source, no outlet a sink.
        match (self.inlets.is_empty(), self.outlets.is_empty()) {
            (true, _) => crate::Boundary::Source,
            (false, true) => crate::Boundary::Sink,
            (false, false) => crate::Boundary::Interior,
        }
    }
    fn internal_vars(&self) -> Vec<VarSpec> {
        self.internal.clone()
    }
    fn inputs(&self) -> Vec<InputSpec> {
        self.inputs.clone()
    }
    fn reacts(&self) -> bool {
        self.reacts
    }
    fn holdup(&self, io: &UnitIo<'_, f64>) -> Option<Vec<f64>> {
        if self.holdup.is_empty() {
            return None;
        }
        Some(self.holdup.iter().map(|e| e.as_ref().map_or(0.0, |e| e.value(io.local, &[]))).collect())
    }
    fn equation_name(&self, k: usize, own_names: &[String]) -> String {
        match (self.row_names.get(&k), own_names.get(k)) {
            (Some(text), Some(own)) => format!("{text} (row of {own})"),
            (Some(text), None) => text.clone(),
            (None, _) => format!("equation {k}"),
        }
    }
    fn pattern(&self, layout: &LocalLayout) -> Option<Vec<(usize, usize)>> {
        Some(self.row_reads(layout))
    }
    fn eval<S: Scalar>(&self, io: &UnitIo<'_, S>, r: &mut [S]) {
        for row in &self.rows {
            match row {
                Row::Derivative { row, rhs } => r[*row] = rhs.value(io.local, &[]),
                Row::Algebraic { row, eq } => r[*row] = eq.residual(io.local, &[]),
            }
        }
        for &(row, k) in &self.default_h {
            let out = io.outlet(k);
            r[row] = out.h() - io.thermo.h_liq(out.t(), out.z());
        }
    }
    fn guess(&self, io: &UnitIo<'_, f64>, own: &mut [f64]) {
        let len = io.layout.stream.len();
        let n_out = self.outlets.len();
        own[n_out * len..].copy_from_slice(&self.guesses);
        // Outlets: a copy of the first inlet (else a representative stream), then each mapping
        // evaluated at that guess, then the liquid enthalpy where the unit closes it.
        for k in 0..n_out {
            let s = &mut own[k * len..(k + 1) * len];
            if self.inlets.is_empty() {
                representative_stream(s);
            } else {
                s.copy_from_slice(io.inlet(0).v);
            }
        }
        let mut local = io.local.to_vec();
        local[..own.len()].copy_from_slice(own);
        for (i, eq) in &self.maps {
            // `out.Q = expr`: the residual is out.Q − expr, so out.Q − residual is expr.
            let v = local[*i] - eq.residual(&local, &[]);
            if v.is_finite() {
                local[*i] = v;
            }
        }
        for &(_, k) in &self.default_h {
            let o = k * len;
            local[o + H] = io.thermo.h_liq(local[o + T], &local[o + Z0..o + len]);
        }
        own.copy_from_slice(&local[..own.len()]);
    }
}

#[cfg(test)]
mod tests {
    use super::super::outflow::test_support::{at_guess, build_unit, solve_own};
    use super::*;
    use crate::Unit;
    use crate::testing::{binary_package, jacobian_error};

    /// A surge tank as equations: holdup `M` \[mol\], level from a constant molar density, outflow
    /// proportional to the level.
    const TANK: &str = r#"{
        "parameters": {"area": "0.5 m2", "rho": "1e4 mol/m3", "k": "2 mol/(s*m)"},
        "variables": {"M": {"kind": "differential", "unit": "kmol", "guess": 5, "lower": 0},
                      "level": {"kind": "algebraic", "unit": "m", "guess": 1, "lower": 0}},
        "equations": ["der(M) = in.F - out.F", "level*area*rho = M"],
        "ports": {"inlets": ["in"],
                  "outlets": {"out": {"F": "k*level", "T": "in.T", "P": "in.P",
                                      "x[light]": "in.x[light]", "x[heavy]": "in.x[heavy]"}}},
        "outputs": ["level"],
        "holdup": {"light": "M*out.x[light]", "heavy": "M*out.x[heavy]"}
    }"#;

    fn feed(thermo: &plantwide_thermo::ThermoPackage) -> [f64; 6] {
        [10.0, 320.0, 2e5, thermo.h_liq(320.0, &[0.4, 0.6]), 0.4, 0.6]
    }

    #[test]
    fn tank_residuals_and_exact_jacobian() {
        let thermo = binary_package();
        let u = build_unit(TANK, &thermo, Equations::build);
        let vars: Vec<String> = UnitModel::internal_vars(&u).iter().map(|v| v.name.clone()).collect();
        assert_eq!(vars, ["M", "level"]);
        assert_eq!(UnitModel::internal_vars(&u)[0].kind, crate::VarKind::Differential);
        assert_eq!(UnitModel::internal_vars(&u)[0].nominal, 5000.0);
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        // Own: out [F, T, P, h, x_l, x_h] = 0..6, M = 6, level = 7; inlet 8..14.
        let (m, level, fout) = (4000.0, 1.3, 2.9);
        local[6] = m;
        local[7] = level;
        local[0] = fout;
        local[1] = 330.0;
        let n = local.len();
        let (mut r, mut jac) = (vec![0.0; 8], vec![0.0; 8 * n]);
        u.jacobian(&UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }, &mut r, &mut jac);
        let (area, rho, k) = (0.5, 1e4, 2.0);
        assert_eq!(r[6], 10.0 - fout, "der(M) row: the time derivative, in − out");
        assert_eq!(r[7], level * area * rho - m);
        assert_eq!(r[0], fout - k * level);
        assert_eq!(r[1], 330.0 - 320.0);
        assert_eq!(r[3], local[3] - thermo.h_liq(330.0, &local[4..6]));
        let mut want = vec![0.0; 8 * n];
        let mut set = |row: usize, col: usize, v: f64| want[row * n + col] = v;
        set(6, 8, 1.0); // ∂(in.F − out.F)/∂in.F
        set(6, 0, -1.0);
        set(7, 7, area * rho);
        set(7, 6, -1.0);
        set(0, 0, 1.0);
        set(0, 7, -k);
        for (row, own, inlet) in [(1, 1, 9), (2, 2, 10), (4, 4, 12), (5, 5, 13)] {
            set(row, own, 1.0);
            set(row, inlet, -1.0);
        }
        for row in [0, 1, 2, 4, 5, 6, 7] {
            for col in 0..n {
                assert_eq!(jac[row * n + col], want[row * n + col], "∂r{row}/∂x{col}");
            }
        }
        let err = jacobian_error(&u, &lay, &thermo, &local, 8);
        assert!(err < 1e-8, "{err}");
        // The declared pattern holds every nonzero.
        let pattern = UnitModel::pattern(&u, &lay).unwrap();
        for row in 0..8 {
            for col in 0..n {
                if jac[row * n + col] != 0.0 {
                    assert!(pattern.contains(&(row, col)), "({row}, {col}) missing from the pattern");
                }
            }
        }
    }

    #[test]
    fn boundary_follows_the_ports() {
        let thermo = binary_package();
        let boundary = |json: &str| UnitModel::boundary(&build_unit(json, &thermo, Equations::build));
        assert_eq!(boundary(TANK), crate::Boundary::Interior);
        let sink = r#"{"variables": {"M": {"kind": "differential", "unit": "mol", "guess": 1}},
                       "equations": ["der(M) = in.F"], "ports": {"inlets": ["in"]}}"#;
        assert_eq!(boundary(sink), crate::Boundary::Sink);
        let portless = r#"{"parameters": {"tau": "1 s"}, "variables": {"y": {"kind": "differential", "guess": 1}}, "equations": ["der(y) = -y/tau"]}"#;
        assert_eq!(boundary(portless), crate::Boundary::Source);
    }

    #[test]
    fn tank_steady_state() {
        let thermo = binary_package();
        let u = build_unit(TANK, &thermo, Equations::build);
        let (lay, mut local) = at_guess(&u, &thermo, &feed(&thermo));
        assert_eq!(local[0], 2.0, "outlet flow guessed from its mapping at the guessed level");
        let norm = solve_own(&u, &lay, &thermo, &mut local);
        assert!(norm < 1e-12, "{norm}");
        // F_out = F_in = k·level, M = level·area·rho.
        assert!((local[7] - 5.0).abs() < 1e-12 && (local[6] - 25_000.0).abs() < 1e-9, "{:?}", &local[..8]);
        assert!((local[3] - thermo.h_liq(320.0, &[0.4, 0.6])).abs() < 1e-9);
        let n = UnitModel::holdup(&u, &UnitIo { local: &local, layout: &lay, thermo: &thermo, time: 0.0 }).unwrap();
        assert!((n[0] - 10_000.0).abs() < 1e-8 && (n[1] - 15_000.0).abs() < 1e-8, "{n:?}");
    }

    fn build_err(json: &str) -> Vec<FieldError> {
        let thermo = binary_package();
        let names = ["light".to_string(), "heavy".to_string()];
        let mut v: serde_json::Value = serde_json::from_str(TANK).unwrap();
        let patch: serde_json::Value = serde_json::from_str(json).unwrap();
        for (k, x) in patch.as_object().unwrap() {
            v[k] = x.clone();
        }
        let c: EquationsConfig = serde_json::from_value(v).unwrap();
        Equations::build(&c, BuildCx::new(&names, &thermo, "units.u"), ()).unwrap_err()
    }

    #[test]
    fn errors_name_the_field_and_the_position() {
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "level*area = M"]}"#);
        assert_eq!(e[0].path, "units.u.equations[1]");
        assert!(e[0].message.contains("found m3 and mol\nlevel*area = M\n^^^^^^^^^^^^^^"), "{}", e[0].message);
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "levl*area*rho = M"]}"#);
        assert!(e[0].message.contains("did you mean `level`"), "{}", e[0].message);
        let e = build_err(r#"{"equations": ["2*der(M) = in.F - out.F", "level*area*rho = M"]}"#);
        assert_eq!(e[0].path, "units.u.equations[0]");
        assert!(
            e[0].message.contains("write the equation of a differential variable as `der(M) ="),
            "{}",
            e[0].message
        );
        let e = build_err(r#"{"equations": ["level*area*rho = M"]}"#);
        assert_eq!(e[0].path, "units.u.variables.M");
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "der(M) = in.F", "level*area*rho = M"]}"#);
        assert!(e[0].message.contains("already given by equations[0]"), "{}", e[0].message);
        // Structurally singular: level is read by no equation once its equation names only M.
        let e = build_err(r#"{"equations": ["der(M) = in.F - out.F", "M = area*rho*in.F/k"]}"#);
        assert_eq!(e[0].path, "units.u.equations");
        assert!(e[0].message.contains("structurally singular"), "{}", e[0].message);
        // A zero denominator at the guess (level = 1 m).
        let e = build_err(
            r#"{"parameters": {"area": "0.5 m2", "rho": "1e4 mol/m3", "k": "2 mol/(s*m)", "l0": "1 m"},
                "equations": ["der(M) = in.F - out.F", "area*rho = M/(level - l0)"]}"#,
        );
        assert_eq!(e[0].path, "units.u.equations[1]");
        assert!(e[0].message.starts_with("at the guess:"), "{}", e[0].message);
        let e = build_err(
            r#"{"ports": {"inlets": ["in"], "outlets": {"out": {"F": "k*level", "T": "in.T", "P": "in.P"}}}}"#,
        );
        assert!(e[0].path == "units.u.equations" && e[0].message.contains("`out.x[light]`"), "{}", e[0].message);
        let e = build_err(r#"{"holdup": {"light": "level"}}"#);
        assert!(e[0].path == "units.u.holdup.light" && e[0].message.contains("found m"), "{}", e[0].message);
        let e = build_err(r#"{"outputs": ["levle"]}"#);
        assert!(e[0].message.contains("did you mean `level`"), "{}", e[0].message);
        assert!(serde_json::from_str::<EquationsConfig>(r#"{"equations": [], "volume": 1}"#).is_err());
    }
}

#[cfg(test)]
mod timing {
    use std::time::Instant;

    use super::super::cstr::Cstr;
    use super::super::outflow::test_support::{at_guess, build_unit};
    use super::*;
    use crate::Unit;
    use crate::testing::binary_package;

    /// The reactor of a flowsheet file, its components renamed to the test package's.
    fn reactor(rel: &str) -> String {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel);
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let mut r = v["units"]["reactor"].clone();
        r.as_object_mut().unwrap().remove("type");
        r.to_string()
            .replace("[A]", "[light]")
            .replace("[B]", "[heavy]")
            .replace("\"A\":", "\"light\":")
            .replace("\"B\":", "\"heavy\":")
    }

    fn per_call(u: &dyn Unit, thermo: &plantwide_thermo::ThermoPackage) -> f64 {
        let feed = [10.0, 300.0, 2e6, thermo.h_liq(300.0, &[1.0, 0.0]), 1.0, 0.0];
        let (lay, local) = at_guess(u, thermo, &feed);
        let (n, m) = (local.len(), lay.n_own());
        let (mut r, mut jac) = (vec![0.0; m], vec![0.0; m * n]);
        let io = UnitIo { local: &local, layout: &lay, thermo, time: 0.0 };
        let reps = 20_000;
        let t0 = Instant::now();
        for _ in 0..reps {
            u.residual(&io, &mut r);
            u.jacobian(&io, &mut r, &mut jac);
        }
        t0.elapsed().as_secs_f64() / reps as f64
    }

    /// Issue 57 asks the equation version's residual + Jacobian within 3× of the built-in's.
    #[test]
    #[ignore = "timing: cargo test -p plantwide-model --lib timing -- --ignored --nocapture"]
    fn cstr_residual_and_jacobian_time() {
        let mut thermo = binary_package();
        thermo.components[1] =
            plantwide_thermo::Component::hypothetical("heavy", 1.0, 0.05, 3.0e4, 350.0, 150.0, 1.0e-4);
        let builtin = build_unit(&reactor("flowsheets/cstr_multiplicity.json"), &thermo, Cstr::build);
        let eqs = build_unit(&reactor("tests/data/cstr_equations.json"), &thermo, Equations::build);
        let (tb, te) = (per_call(&builtin, &thermo), per_call(&eqs, &thermo));
        eprintln!(
            "residual + Jacobian: built-in cstr {:.2} µs, equations {:.2} µs, ratio {:.2}",
            tb * 1e6,
            te * 1e6,
            te / tb
        );
    }
}
