//! NumPy `.npz` archives: named arrays as `.npy` (format 1.0) entries of an uncompressed zip, read
//! back by `numpy.load(path)` without pickling. Arrays are `float64` (`<f8`), `complex128`
//! (`<c16`) or fixed-width unicode strings (`<U{n}`), in C order.
//!
//! [`linear_model`] writes the state-space export: `A, B, C, D`, the python-control-safe names
//! beside the paths they stand for, units, steady values and eigenvalues.

use faer::c64;

use crate::export::ModelExport;

/// One array's element type and values, row-major.
#[derive(Debug, Clone, PartialEq)]
pub enum Data {
    /// `float64`.
    F64(Vec<f64>),
    /// `complex128`.
    C64(Vec<c64>),
    /// Unicode strings.
    Str(Vec<String>),
}

/// A named array.
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    /// Its key in the archive (`A` → entry `A.npy`).
    pub name: String,
    /// Its shape (`[]` for a scalar).
    pub shape: Vec<usize>,
    /// Its values.
    pub data: Data,
}

impl Array {
    /// A matrix from rows (all of `cols` entries; `cols` given so that an empty matrix keeps it).
    pub fn matrix(name: &str, rows: &[Vec<f64>], cols: usize) -> Array {
        Array { name: name.into(), shape: vec![rows.len(), cols], data: Data::F64(rows.concat()) }
    }
    /// A vector of numbers.
    pub fn vector(name: &str, v: &[f64]) -> Array {
        Array { name: name.into(), shape: vec![v.len()], data: Data::F64(v.to_vec()) }
    }
    /// A vector of strings.
    pub fn strings(name: &str, v: &[String]) -> Array {
        Array { name: name.into(), shape: vec![v.len()], data: Data::Str(v.to_vec()) }
    }

    /// The `.npy` bytes: magic, version 1.0, the header dict padded to 64 bytes, the data.
    fn npy(&self) -> Vec<u8> {
        let (descr, body) = match &self.data {
            Data::F64(v) => ("<f8".to_string(), v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>()),
            Data::C64(v) => {
                ("<c16".to_string(), v.iter().flat_map(|z| [z.re, z.im]).flat_map(f64::to_le_bytes).collect())
            }
            Data::Str(v) => {
                let width = v.iter().map(|s| s.chars().count()).max().unwrap_or(0).max(1);
                let mut body = Vec::with_capacity(v.len() * width * 4);
                for s in v {
                    let chars: Vec<u32> = s.chars().map(u32::from).collect();
                    (0..width).for_each(|k| body.extend(chars.get(k).copied().unwrap_or(0).to_le_bytes()));
                }
                (format!("<U{width}"), body)
            }
        };
        let shape = match self.shape.as_slice() {
            [] => "()".to_string(),
            [n] => format!("({n},)"),
            s => format!("({})", s.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
        };
        let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        // magic (6) + version (2) + length (2) + header + '\n' is a multiple of 64.
        while (10 + header.len() + 1) % 64 != 0 {
            header.push(' ');
        }
        header.push('\n');
        let mut out = b"\x93NUMPY\x01\x00".to_vec();
        out.extend((header.len() as u16).to_le_bytes());
        out.extend(header.as_bytes());
        out.extend(body);
        out
    }
}

/// The archive's bytes: each array as `<name>.npy`, stored (not compressed).
pub fn archive(arrays: &[Array]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    for a in arrays {
        let name = format!("{}.npy", a.name);
        let data = a.npy();
        let crc = crc32fast::hash(&data);
        let offset = out.len() as u32;
        // Local file header: version 2.0, no flags, stored, 1980-01-01 00:00.
        out.extend(0x0403_4b50u32.to_le_bytes());
        entry_fields(&mut out, crc, data.len() as u32, name.len() as u16);
        out.extend(name.as_bytes());
        out.extend(&data);
        // Central directory entry: made by version 2.0, then the same fields, offset last.
        central.extend(0x0201_4b50u32.to_le_bytes());
        central.extend(20u16.to_le_bytes());
        entry_fields(&mut central, crc, data.len() as u32, name.len() as u16);
        central.extend([0u8; 6]); // comment length, disk number, internal attributes
        central.extend([0u8; 4]); // external attributes
        central.extend(offset.to_le_bytes());
        central.extend(name.as_bytes());
    }
    let (at, size, n) = (out.len() as u32, central.len() as u32, arrays.len() as u16);
    out.extend(central);
    out.extend(0x0605_4b50u32.to_le_bytes());
    out.extend([0u8; 4]);
    out.extend(n.to_le_bytes());
    out.extend(n.to_le_bytes());
    out.extend(size.to_le_bytes());
    out.extend(at.to_le_bytes());
    out.extend(0u16.to_le_bytes());
    out
}

/// The fields a local header and a central entry share: version needed, flags, method, time,
/// date, CRC-32, sizes, name length, extra length.
fn entry_fields(out: &mut Vec<u8>, crc: u32, len: u32, name_len: u16) {
    for v in [20u16, 0, 0, 0, 0x21] {
        out.extend(v.to_le_bytes());
    }
    out.extend(crc.to_le_bytes());
    out.extend(len.to_le_bytes());
    out.extend(len.to_le_bytes());
    out.extend(name_len.to_le_bytes());
    out.extend(0u16.to_le_bytes());
}

/// The state-space export as arrays: `A, B, C, D` (and `steady_state_gain` when `A` is regular),
/// `eigenvalues` (per time unit), `state_names`/`input_names`/`output_names` (python-control-safe)
/// with `state_paths`/`input_paths`/`output_paths` beside them (the label map, entry by entry),
/// `input_units`/`output_units`, the steady values and `time_unit`.
pub fn linear_model(export: &ModelExport<'_>) -> Vec<Array> {
    let m = export.matrices();
    let names = export.names();
    let pm = export.model;
    let (n, ni, no) = (pm.states.len(), export.inputs.len(), export.outputs.len());
    let paths = |s: &[plantwide_analysis::select::Signal]| s.iter().map(|s| s.path.clone()).collect::<Vec<_>>();
    let units = |s: &[plantwide_analysis::select::Signal]| s.iter().map(|s| s.unit.clone()).collect::<Vec<_>>();
    let ts = export.time_unit.1;
    let mut arrays = vec![
        Array::matrix("A", &m.a, n),
        Array::matrix("B", &m.b, ni),
        Array::matrix("C", &m.c, n),
        Array::matrix("D", &m.d, ni),
    ];
    if let Some(g) = &m.steady_state_gain {
        arrays.push(Array::matrix("steady_state_gain", g, ni));
    }
    let eig = pm.eigenvalues.iter().map(|l| c64::new(l.re * ts, l.im * ts)).collect();
    arrays.push(Array { name: "eigenvalues".into(), shape: vec![pm.eigenvalues.len()], data: Data::C64(eig) });
    arrays.extend([
        Array::strings("state_names", &names.states),
        Array::strings("input_names", &names.inputs),
        Array::strings("output_names", &names.outputs),
        Array::strings("state_paths", &pm.states),
        Array::strings("input_paths", &paths(export.inputs)),
        Array::strings("output_paths", &paths(export.outputs)),
        Array::strings("input_units", &units(export.inputs)),
        Array::strings("output_units", &units(export.outputs)),
        Array::vector("state_values", &pm.state_values),
        Array::vector("input_values", &pm.input_values),
        Array::vector("output_values", &pm.output_values),
        Array { name: "time_unit".into(), shape: vec![], data: Data::Str(vec![export.time_unit.0.to_string()]) },
    ]);
    debug_assert_eq!(arrays[2].shape, [no, n]);
    arrays
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_headers_are_aligned_and_describe_the_data() {
        let a = Array::matrix("A", &[vec![1.0, 2.0], vec![3.0, 4.0]], 2).npy();
        let len = u16::from_le_bytes([a[8], a[9]]) as usize;
        assert_eq!((10 + len) % 64, 0);
        let header = std::str::from_utf8(&a[10..10 + len]).unwrap();
        assert!(header.contains("'descr': '<f8'") && header.contains("'shape': (2, 2)"), "{header}");
        assert_eq!(f64::from_le_bytes(a[10 + len + 8..10 + len + 16].try_into().unwrap()), 2.0);
        let s = Array::strings("n", &["ab".into(), "c".into()]).npy();
        let len = u16::from_le_bytes([s[8], s[9]]) as usize;
        assert_eq!(s.len() - 10 - len, 2 * 2 * 4, "two strings of width 2, UTF-32");
    }

    #[test]
    fn the_archive_lists_every_entry_once() {
        let bytes = archive(&[Array::vector("x", &[1.0]), Array::strings("s", &["a".into()])]);
        let end = bytes.len() - 22;
        assert_eq!(u32::from_le_bytes(bytes[end..end + 4].try_into().unwrap()), 0x0605_4b50);
        assert_eq!(u16::from_le_bytes([bytes[end + 10], bytes[end + 11]]), 2);
        let size = u32::from_le_bytes(bytes[end + 12..end + 16].try_into().unwrap()) as usize;
        assert_eq!(size, 2 * (46 + "x.npy".len()), "two central entries of 46 bytes and a name each");
        let text = String::from_utf8_lossy(&bytes);
        assert_eq!(text.matches("x.npy").count(), 2, "local header and central directory");
    }
}
