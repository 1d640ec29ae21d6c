//! The names and keys of the basis tensors' cache files: a file is named by a hash of the settings
//! that made it (its key) and starts with the key itself, which is checked when it is read. Keys are
//! compared to 12 significant digits, so that equal settings written differently in the last bits
//! find the same tensors.

use super::BASIS_SIZE;

/// A key value rounded to 12 significant digits: tensors are found for settings equal to that
/// (a k grid from `numpy.geomspace` and the same grid from [`crate::linear::LogGrid`] differ in the
/// last bits, and must not build a second set of tensors).
fn canonical(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    format!("{v:.11e}").parse().unwrap_or(v)
}

/// The cache file name `<prefix>-v<version>-n<BASIS_SIZE>-<hash>.bin` of tensors made with the
/// settings `key` (FNV-1a over the bits of its [`canonical`] values).
pub(crate) fn cache_file_name(prefix: &str, version: u32, key: &[f64]) -> String {
    let hash = key
        .iter()
        .flat_map(|&v| canonical(v).to_le_bytes())
        .fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
    format!("{prefix}-v{version}-n{BASIS_SIZE}-{hash:016x}.bin")
}

/// The values of a cache file after its key, if the file starts with `expected` (the key's length,
/// then the key, equal to 12 significant digits: [`canonical`]) and every value is finite; `None` for
/// a file made for other settings.
pub(crate) fn after_key<'a>(values: &'a [f64], expected: &[f64]) -> Option<&'a [f64]> {
    let len = stored_count(*values.first()?, expected.len())?;
    let stored = values.get(1..1 + len)?;
    if len != expected.len()
        || stored
            .iter()
            .zip(expected)
            .any(|(&a, &b)| canonical(a) != canonical(b))
    {
        return None;
    }
    if values.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(&values[1 + len..])
}

/// The most basis functions a cache file may declare: the bases in use have [`BASIS_SIZE`]; a larger
/// count is a corrupted or crafted header, refused before any size is computed from it (so that the
/// n³-sized products of the tensors stay far from overflow).
pub(crate) const MAX_STORED_BASIS: usize = 1024;

/// `value`, a size read from a cache file, as a count if it is a whole number in `0..=max`; `None`
/// (the file is not used) otherwise. Every size read from a file goes through this before it is used,
/// with `max` a sane maximum or the number of values the file still holds.
pub(crate) fn stored_count(value: f64, max: usize) -> Option<usize> {
    (value.is_finite() && value >= 0.0 && value.fract() == 0.0 && value <= max as f64)
        .then_some(value as usize)
}

/// The values after the points per k and the number of replicas of a tensor file, if they are
/// `points` and `replicas` (those the settings give: a file that disagrees is not used).
pub(crate) fn after_points<'a>(
    values: &'a [f64],
    points: &[usize],
    replicas: usize,
) -> Option<&'a [f64]> {
    let stored = values.get(..=points.len())?;
    let equal = stored[..points.len()]
        .iter()
        .zip(points)
        .all(|(&s, &p)| s == p as f64);
    (equal && stored[points.len()] == replicas as f64).then(|| &values[points.len() + 1..])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_equal_to_twelve_digits_find_the_same_tensors_and_others_do_not() {
        // np.geomspace(0.005, 0.4, 40) and LogGrid differ by an ulp here and there.
        let k: Vec<f64> = (0..40)
            .map(|i| 0.005 * (80.0_f64).powf(f64::from(i) / 39.0))
            .collect();
        let nudged: Vec<f64> = k.iter().map(|&x| f64::from_bits(x.to_bits() + 1)).collect();
        let moved: Vec<f64> = k.iter().map(|&x| x * (1.0 + 1e-9)).collect();
        let name = |key: &[f64]| cache_file_name("t", 1, key);
        assert_eq!(name(&k), name(&nudged));
        assert_ne!(name(&k), name(&moved));
        let mut file = vec![k.len() as f64];
        file.extend(&k);
        file.push(7.0);
        assert_eq!(after_key(&file, &nudged), Some(&[7.0][..]));
        assert_eq!(after_key(&file, &moved), None);
        assert_eq!(after_key(&file, &k[1..]), None);
        assert_eq!(canonical(0.0), 0.0);
        assert!(canonical(f64::NAN).is_nan());
    }
}
