//! The thermodynamic package's functions of a port's state, as external functions of the
//! expression layer ([`plantwide_expr::external`]): each call reads the port's `T`, `P` and `x`
//! from the unit's local vector and gives the exact partial derivatives with respect to them,
//! by forward-mode dual numbers through the package's generic property functions (one pass per
//! input), or, for the bubble temperature, by the implicit-function theorem on the bubble-point
//! residual at the converged temperature.

use std::sync::Arc;

use num_dual::Dual64;
use plantwide_expr::{BindError, ExternalCall, ExternalEval, ExternalFunction};
use plantwide_thermo::ThermoPackage;
use plantwide_units::Dimension;

use crate::Scalar;
use crate::stream::{P, T, Z0};

/// A property of a port's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Prop {
    /// Liquid molar enthalpy `h_L(T, x)` \[J/mol\].
    LiquidEnthalpy,
    /// Vapour (ideal-gas) molar enthalpy `h_V(T, x)` \[J/mol\] of the port's composition.
    VapourEnthalpy,
    /// K-value `K_i(T, P, x)` of component `i` \[-\].
    KValue(usize),
    /// Liquid molar density `1/v_L(T, x)` \[mol/m³\].
    LiquidDensity,
    /// Mean molar mass `Σ x_i M_i` \[kg/mol\].
    MolarMass,
    /// Bubble temperature at the port's `P` and normalised `x` \[K\].
    BubbleT,
}

/// The functions: `(name, what it gives)`. `P` in brackets is an optional last argument naming a
/// pressure variable or input of the unit, used instead of the port's `P` (a flash drum's liquid
/// leaves at the valve's downstream pressure but is in equilibrium at the drum's).
pub(super) const FUNCTIONS: [(&str, &str); 6] = [
    ("h_L", "h_L(port): liquid molar enthalpy at the port's T and x [J/mol]"),
    ("h_V", "h_V(port): vapour molar enthalpy at the port's T, its x taken as the vapour [J/mol]"),
    ("K", "K(port, component[, P]): K-value of the component at the port's T, P and x [-]"),
    ("rho_L", "rho_L(port): liquid molar density 1/v_L at the port's T and x [mol/m3]"),
    ("mw", "mw(port): mean molar mass at the port's x [kg/mol]"),
    ("T_bubble", "T_bubble(port[, P]): bubble temperature at the port's P and x/sum(x) [K]"),
];

impl Prop {
    fn dimension(self) -> Dimension {
        match self {
            Prop::LiquidEnthalpy | Prop::VapourEnthalpy => Dimension::MOLAR_ENERGY,
            Prop::KValue(_) => Dimension::DIMENSIONLESS,
            Prop::LiquidDensity => Dimension::DENSITY_MOLAR,
            Prop::MolarMass => Dimension::MOLAR_MASS,
            Prop::BubbleT => Dimension::TEMPERATURE,
        }
    }
    fn reads_t(self) -> bool {
        !matches!(self, Prop::MolarMass | Prop::BubbleT)
    }
    fn reads_p(self) -> bool {
        matches!(self, Prop::KValue(_) | Prop::BubbleT)
    }
}

/// One of [`FUNCTIONS`] bound to the unit's ports and components.
#[derive(Debug)]
pub(super) struct PortFunction {
    name: &'static str,
    thermo: Arc<ThermoPackage>,
    /// Each port's name and the local index of its stream block.
    ports: Arc<Vec<(String, usize)>>,
    components: Arc<Vec<String>>,
    /// The unit's pressure variables and inputs by name, with their local index.
    pressures: Arc<Vec<(String, usize)>>,
}

impl PortFunction {
    /// The thermodynamic functions over `ports` (name, offset of its stream in the local vector).
    pub(super) fn all(
        thermo: &ThermoPackage,
        ports: Vec<(String, usize)>,
        components: &[String],
        pressures: Vec<(String, usize)>,
    ) -> Vec<(&'static str, Arc<dyn ExternalFunction>)> {
        let (thermo, ports, components) = (Arc::new(thermo.clone()), Arc::new(ports), Arc::new(components.to_vec()));
        let pressures = Arc::new(pressures);
        FUNCTIONS
            .iter()
            .map(|&(name, _)| {
                let f = PortFunction {
                    name,
                    thermo: thermo.clone(),
                    ports: ports.clone(),
                    components: components.clone(),
                    pressures: pressures.clone(),
                };
                (name, Arc::new(f) as Arc<dyn ExternalFunction>)
            })
            .collect()
    }

    fn port(&self, arg: usize, text: &str) -> Result<usize, BindError> {
        match self.ports.iter().find(|(p, _)| p == text) {
            Some(&(_, at)) => Ok(at),
            None => {
                let names: Vec<&str> = self.ports.iter().map(|(p, _)| p.as_str()).collect();
                Err(BindError::at(arg, format!("`{text}` is not a port of the unit (ports: {})", names.join(", "))))
            }
        }
    }
}

impl ExternalFunction for PortFunction {
    fn bind(&self, args: &[&str]) -> Result<ExternalCall, BindError> {
        let (form, base) = match self.name {
            "K" => ("(port, component[, P])", 2),
            "T_bubble" => ("(port[, P])", 1),
            _ => ("(port)", 1),
        };
        let takes_p = form.ends_with("P])");
        if args.len() < base || args.len() > base + usize::from(takes_p) {
            let n = args.len();
            return Err(BindError::call(format!("called with {n} argument(s), as `{}{form}`", self.name)));
        }
        let at = self.port(0, args[0])?;
        let prop = match self.name {
            "h_L" => Prop::LiquidEnthalpy,
            "h_V" => Prop::VapourEnthalpy,
            "rho_L" => Prop::LiquidDensity,
            "mw" => Prop::MolarMass,
            "T_bubble" => Prop::BubbleT,
            _ => match self.components.iter().position(|c| c == args[1]) {
                Some(i) => Prop::KValue(i),
                None => {
                    let msg = format!("`{}` is not a component (components: {})", args[1], self.components.join(", "));
                    return Err(BindError::at(1, msg));
                }
            },
        };
        let p_at = match args.get(base) {
            None => at + P,
            Some(name) => match self.pressures.iter().find(|(n, _)| n == name) {
                Some(&(_, i)) => i,
                None => {
                    let names: Vec<&str> = self.pressures.iter().map(|(n, _)| n.as_str()).collect();
                    let msg = format!("`{name}` is not a pressure of the unit (pressures: {})", names.join(", "));
                    return Err(BindError::at(base, msg));
                }
            },
        };
        let nc = self.components.len();
        let mut reads = Vec::with_capacity(nc + 2);
        if prop.reads_t() {
            reads.push(at + T);
        }
        if prop.reads_p() {
            reads.push(p_at);
        }
        reads.extend((0..nc).map(|i| at + Z0 + i));
        let eval = PropEval { prop, thermo: self.thermo.clone() };
        Ok(ExternalCall { reads, dim: prop.dimension(), eval: Arc::new(eval) })
    }
}

/// A bound property: its inputs are `[T]? [P]? x…` as [`Prop::reads_t`] and [`Prop::reads_p`] say.
#[derive(Debug)]
struct PropEval {
    prop: Prop,
    thermo: Arc<ThermoPackage>,
}

impl PropEval {
    /// `(T, P, x)` from the inputs (an unread `T` or `P` is NaN: it is not used).
    fn split<S: Scalar>(&self, inputs: &[S]) -> (S, S, usize) {
        let nan = S::from(f64::NAN);
        let mut k = 0;
        let mut next = |read: bool| {
            if read {
                k += 1;
                inputs[k - 1]
            } else {
                nan
            }
        };
        let t = next(self.prop.reads_t());
        let p = next(self.prop.reads_p());
        (t, p, k)
    }

    /// The property (all but the bubble temperature) at the inputs.
    fn direct<S: Scalar>(&self, inputs: &[S]) -> S {
        let (t, p, k) = self.split(inputs);
        let x = &inputs[k..];
        let th = &self.thermo;
        match self.prop {
            Prop::LiquidEnthalpy => th.h_liq(t, x),
            Prop::VapourEnthalpy => th.h_vap(t, x),
            Prop::KValue(i) => {
                let mut kv = vec![S::from(0.0); x.len()];
                th.k_values(t, p, x, &mut kv);
                kv[i]
            }
            Prop::LiquidDensity => th.v_liq(t, x).recip(),
            Prop::MolarMass => th.mw(x),
            Prop::BubbleT => S::from(f64::NAN),
        }
    }

    /// The bubble-point residual at temperature `t`, the inputs `[P, x…]` normalised in `x`.
    fn bubble_residual<S: Scalar>(&self, t: S, inputs: &[S]) -> S {
        let sum = inputs[1..].iter().fold(S::from(0.0), |acc, &v| acc + v);
        let x: Vec<S> = inputs[1..].iter().map(|&v| v / sum).collect();
        self.thermo.bubble_residual(t, inputs[0], &x)
    }

    fn bubble_t(&self, inputs: &[f64]) -> f64 {
        let sum: f64 = inputs[1..].iter().sum();
        let x: Vec<f64> = inputs[1..].iter().map(|v| v / sum).collect();
        self.thermo.bubble_t(inputs[0], &x).map_or(f64::NAN, |s| s.t)
    }
}

/// The inputs as dual numbers, input `k` seeded.
fn seeded(inputs: &[f64], k: usize) -> Vec<Dual64> {
    inputs.iter().enumerate().map(|(j, &v)| Dual64::new(v, if j == k { 1.0 } else { 0.0 })).collect()
}

impl ExternalEval for PropEval {
    fn value(&self, inputs: &[f64]) -> f64 {
        match self.prop {
            Prop::BubbleT => self.bubble_t(inputs),
            _ => self.direct(inputs),
        }
    }

    fn value_and_partials(&self, inputs: &[f64], d: &mut [f64]) -> f64 {
        if self.prop != Prop::BubbleT {
            for (k, dk) in d.iter_mut().enumerate() {
                *dk = self.direct(&seeded(inputs, k)).eps;
            }
            return self.direct(inputs);
        }
        // r(T_b(P, x), P, x) = 0, so ∂T_b/∂u = −(∂r/∂u)/(∂r/∂T) for u = P, x_i.
        let t = self.bubble_t(inputs);
        let plain: Vec<Dual64> = inputs.iter().map(|&v| Dual64::from(v)).collect();
        let r_t = self.bubble_residual(Dual64::new(t, 1.0), &plain).eps;
        for (k, dk) in d.iter_mut().enumerate() {
            *dk = -self.bubble_residual(Dual64::from(t), &seeded(inputs, k)).eps / r_t;
        }
        t
    }
}
