//! The report of a sensitivity sweep ([`Curve`]s): one table per disturbance, its change and value
//! at each point and the outputs there, in display units. `plantwide sensitivity` prints [`text`];
//! the CSV is [`crate::csv::sensitivity_csv`], the figure [`crate::plot::write_sensitivity`].

use plantwide_analysis::select::Signal;
use plantwide_analysis::sensitivity::Curve;

use super::sig6 as sig;

/// The sweeps of the plant `plant_name` as text: for each disturbance its base value, then one row
/// per point (change in %, value, each output, or `not converged`).
pub fn text(plant_name: &str, curves: &[Curve], outputs: &[Signal]) -> String {
    let mut t = format!(
        "sensitivity of `{plant_name}` (control structure as in the flowsheet, each point re-converged from its neighbour)\n"
    );
    for c in curves {
        let d = &c.disturbance;
        t.push_str(&format!(
            "\n{} [{}] (base {})\n",
            d.signal.path,
            d.signal.unit,
            sig(d.signal.display_value(d.base))
        ));
        t.push_str(&format!("{:>12} {:>14}", "change %", "value"));
        for o in outputs {
            t.push_str(&format!(" {:>24}", format!("{} [{}]", o.path, o.unit)));
        }
        t.push('\n');
        for (v, y) in c.values.iter().zip(&c.outputs) {
            t.push_str(&format!("{:>12} {:>14}", sig(d.percent(*v)), sig(d.signal.display_value(*v))));
            match y {
                Some(y) => {
                    outputs.iter().zip(y).for_each(|(o, yi)| t.push_str(&format!(" {:>24}", sig(o.display_value(*yi)))))
                }
                None => t.push_str(&format!(" {:>24}", "not converged")),
            }
            t.push('\n');
        }
    }
    t
}
