//! Sensitivity sweeps as CSV: one row per point, the disturbance, its value and change from base,
//! then one column per output, all in display units.

use plantwide_analysis::select::Signal;
use plantwide_analysis::sensitivity::Curve;

/// CSV of the curves: one row per point, columns `disturbance, value, change_percent` and one per
/// output (display units; empty where not converged).
pub fn sensitivity_csv(curves: &[Curve], outputs: &[Signal]) -> String {
    let mut s = String::from("disturbance,unit,value,change_percent");
    for o in outputs {
        s.push_str(&format!(",{} [{}]", csv_field(&o.path), csv_field(&o.unit)));
    }
    s.push('\n');
    for c in curves {
        let d = &c.disturbance;
        for (v, out) in c.values.iter().zip(&c.outputs) {
            s.push_str(&format!(
                "{},{},{},{}",
                csv_field(&d.signal.path),
                csv_field(&d.signal.unit),
                d.signal.display_value(*v),
                d.percent(*v)
            ));
            for (k, o) in outputs.iter().enumerate() {
                match out {
                    Some(y) => s.push_str(&format!(",{}", o.display_value(y[k]))),
                    None => s.push(','),
                }
            }
            s.push('\n');
        }
    }
    s
}

/// Quote a field that holds a comma, a quote or a line break (RFC 4180).
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_string() }
}
