//! A minimal reader of NumPy `.npy` files holding one 2-D float array (`np.save(path, matrix)`).
//!
//! Format (NumPy's `format.py`, versions 1.0–3.0): the magic `\x93NUMPY`, the version (2 bytes), the
//! header length (u16 little-endian for 1.0, u32 for 2.0 and 3.0), the header (a Python dict literal
//! with `descr`, `fortran_order` and `shape`), then the data. Accepted: `descr` `<f8`, `>f8`, `<f4`,
//! `>f4` (also `=`/`|` for native little-endian), C or Fortran order, a 2-D shape. Pickled objects
//! (`allow_pickle`, e.g. a saved dict) are not.

use crate::error::{Error, Result};

/// A 2-D array: `rows × cols` values in row-major order.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Array2 {
    pub rows: usize,
    pub cols: usize,
    pub values: Vec<f64>,
}

/// Parses the bytes of a `.npy` file; `origin` names it in messages.
///
/// # Errors
/// [`Error::InvalidChoice`] for a file that is not a `.npy` file of a 2-D float array, or is truncated.
pub(super) fn parse_npy(bytes: &[u8], origin: &str) -> Result<Array2> {
    let bad = |reason: String| Error::InvalidChoice {
        what: format!("`{origin}` (.npy)"),
        reason,
    };
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("not a .npy file (no \\x93NUMPY magic)".into()));
    }
    let major = bytes[6];
    let (len, start) = match major {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        _ => return Err(bad(format!("unsupported .npy version {major}"))),
    };
    let header = bytes
        .get(start..start + len)
        .ok_or_else(|| bad("truncated header".into()))?;
    let header = String::from_utf8_lossy(header);
    let value = |key: &str| -> Option<String> {
        let at = header.find(&format!("'{key}'"))? + key.len() + 2;
        let rest = header[at..].trim_start().strip_prefix(':')?.trim_start();
        let end = if rest.starts_with('(') {
            rest.find(')')? + 1
        } else {
            rest.find([',', '}'])?
        };
        Some(rest[..end].trim().to_string())
    };
    let descr = value("descr").ok_or_else(|| bad(format!("no 'descr' in header {header}")))?;
    let descr = descr.trim_matches(|c| c == '\'' || c == '"');
    let (size, big) = match descr {
        "<f8" | "=f8" | "|f8" => (8, false),
        ">f8" => (8, true),
        "<f4" | "=f4" | "|f4" => (4, false),
        ">f4" => (4, true),
        other => {
            return Err(bad(format!(
                "data type `{other}`: only float64 and float32 arrays are read (a pickled object, \
                 e.g. a saved dict, cannot be: save the matrix itself with np.save)"
            )))
        }
    };
    let fortran = match value("fortran_order").as_deref() {
        Some("False") => false,
        Some("True") => true,
        _ => return Err(bad(format!("no fortran_order in header {header}"))),
    };
    let shape = value("shape").ok_or_else(|| bad(format!("no 'shape' in header {header}")))?;
    let dims: Vec<usize> = shape
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<usize>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad(format!("cannot read the shape {shape}")))?;
    let [rows, cols] = dims[..] else {
        return Err(bad(format!("shape {shape}: a 2-D array is needed")));
    };
    let data = &bytes[start + len..];
    let bytes_expected = rows
        .checked_mul(cols)
        .and_then(|count| count.checked_mul(size))
        .ok_or_else(|| bad(format!("shape {shape} too large")))?;
    if data.len() != bytes_expected {
        return Err(bad(format!(
            "{} data bytes for shape {shape} of {size}-byte values ({bytes_expected} expected)",
            data.len(),
        )));
    }
    let read = |c: &[u8]| -> f64 {
        if size == 8 {
            let b: [u8; 8] = c.try_into().unwrap_or([0; 8]);
            if big {
                f64::from_be_bytes(b)
            } else {
                f64::from_le_bytes(b)
            }
        } else {
            let b: [u8; 4] = c.try_into().unwrap_or([0; 4]);
            f64::from(if big {
                f32::from_be_bytes(b)
            } else {
                f32::from_le_bytes(b)
            })
        }
    };
    let flat: Vec<f64> = data.chunks_exact(size).map(read).collect();
    let values = if fortran {
        (0..rows)
            .flat_map(|i| (0..cols).map(move |j| (i, j)))
            .map(|(i, j)| flat[j * rows + i])
            .collect()
    } else {
        flat
    };
    Ok(Array2 { rows, cols, values })
}

/// The bytes of a version-1.0 `.npy` file with the header dict `dict` and the raw `data`.
#[cfg(test)]
pub(super) fn npy_bytes(dict: &str, data: &[u8]) -> Vec<u8> {
    let mut header = dict.to_string();
    while !(10 + header.len() + 1).is_multiple_of(64) {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

/// The bytes of a `.npy` file of a C-order float64 `rows × cols` array (tests).
#[cfg(test)]
pub(super) fn write_npy(rows: usize, cols: usize, values: &[f64]) -> Vec<u8> {
    let dict = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({rows}, {cols}), }}");
    let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    npy_bytes(&dict, &data)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn le(values: &[f64]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn round_trip_and_orders() {
        let values = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let bytes = write_npy(2, 3, &values);
        assert_eq!((bytes.len() - 48) % 64, 0);
        let a = parse_npy(&bytes, "a.npy").unwrap();
        assert_eq!((a.rows, a.cols), (2, 3));
        assert_eq!(a.values, values);
        // Fortran order: the same matrix stored column by column.
        let dict = "{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }";
        let f = npy_bytes(dict, &le(&[1.0, 4.0, 2.0, 5.0, 3.0, 6.0]));
        assert_eq!(parse_npy(&f, "f.npy").unwrap().values, values);
        // Big-endian float32.
        let data: Vec<u8> = values
            .iter()
            .flat_map(|&v| (v as f32).to_be_bytes())
            .collect();
        let dict = "{'descr': '>f4', 'fortran_order': False, 'shape': (3, 2), }";
        let b = parse_npy(&npy_bytes(dict, &data), "b.npy").unwrap();
        assert_eq!((b.rows, b.cols, b.values), (3, 2, values.to_vec()));
    }

    #[test]
    fn bad_files_are_refused() {
        let ok = write_npy(2, 2, &[1.0; 4]);
        assert!(parse_npy(b"not numpy at all", "x").is_err());
        assert!(parse_npy(&ok[..ok.len() - 8], "short").is_err());
        let dict = "{'descr': '|O', 'fortran_order': False, 'shape': (), }";
        let e = parse_npy(&npy_bytes(dict, &[0; 8]), "dict.npy").unwrap_err();
        assert!(e.to_string().contains("pickled"), "{e}");
        let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (4,), }";
        assert!(parse_npy(&npy_bytes(dict, &le(&[1.0; 4])), "1d.npy").is_err());
    }
}
