//! Product sink: the end of a stream. It owns no variables and writes no equations.
//!
//! Port: inlet `in`.

use crate::capability::{Boundary, Shape};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::{BuildCx, FieldError, Scalar, UnitIo, UnitModel};

/// Flowsheet description of a product sink (no parameters).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ProductConfig {}

impl crate::registry::UnitConfig for ProductConfig {
    fn ports() -> &'static str {
        "inlet `in`"
    }
}

/// A product sink.
#[derive(Debug, Clone)]
pub struct Product;

impl Product {
    /// Build from the flowsheet description.
    pub fn build(_config: &ProductConfig, cx: BuildCx<'_>, _links: ()) -> Result<Product, Vec<FieldError>> {
        cx.finish(Product)
    }
}

impl UnitModel for Product {
    fn type_name(&self) -> &'static str {
        "product"
    }
    fn shape(&self) -> Shape {
        Shape::Sink
    }
    fn boundary(&self) -> Boundary {
        Boundary::Sink
    }
    fn inlet_ports(&self) -> Vec<String> {
        vec!["in".into()]
    }
    fn outlet_ports(&self) -> Vec<String> {
        Vec::new()
    }
    fn eval<S: Scalar>(&self, _io: &UnitIo<'_, S>, _r: &mut [S]) {}
    fn guess(&self, _io: &UnitIo<'_, f64>, _own: &mut [f64]) {}
}
