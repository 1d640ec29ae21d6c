//! The crate's error type.
//!
//! Every fallible function of `pt-spectra` returns [`Result`]. Each variant carries the offending value and,
//! for table input, where it came from (`origin` is a file path or a description such as
//! `embedded gm2012 z=0.0`, `line` is the 1-based line number, or the 1-based row number for in-memory
//! arrays), so that the message alone says what to fix.

use std::path::PathBuf;

/// All errors of the `pt-spectra` library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file could not be opened or read.
    #[error("cannot read `{}`: {source}", path.display())]
    Io {
        /// The file that was asked for.
        path: PathBuf,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },

    /// The table cache failed: a directory, lock or table file could not be created or written.
    #[error("table cache: cannot {what} `{}`: {source}", path.display())]
    Cache {
        /// The file or directory.
        path: PathBuf,
        /// What was being done, e.g. `write the table`.
        what: &'static str,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },

    /// A result was asked for a term that was not computed.
    #[error("{needed_by} needs {term}, which was not computed{hint}")]
    MissingTerm {
        /// The term, e.g. `P15`.
        term: &'static str,
        /// What needs it, e.g. `model 1l-rpt-n2`.
        needed_by: String,
        /// How to compute it (may be empty).
        hint: &'static str,
    },

    /// A plan used for a model it was not built for.
    #[error(
        "the plan was built for {found}, but {expected} is asked for: build the plan for it{hint}"
    )]
    PlanMismatch {
        /// What the request needs, e.g. `model 2l-spt`.
        expected: String,
        /// What the plan is for.
        found: String,
        /// How to build the right plan (may be empty).
        hint: &'static str,
    },

    /// Two inputs that must share a k grid do not.
    #[error("{what}: {found} does not match the {expected} it must match")]
    GridMismatch {
        /// Which inputs, e.g. `TNS terms and real-space spectra`.
        what: &'static str,
        /// The grid that was expected, described (e.g. `40 k in [0.005, 0.4] h/Mpc`).
        expected: String,
        /// The grid that was found, described.
        found: String,
    },

    /// A field of a data row is not a number.
    #[error("{origin}:{line}: cannot parse `{field}` (column {}) as a number", .column + 1)]
    Parse {
        /// File path or description of the input.
        origin: String,
        /// 1-based line number.
        line: usize,
        /// 0-based column index of the field (printed 1-based, as `--columns` counts).
        column: usize,
        /// The text that failed to parse.
        field: String,
    },

    /// A data row has fewer columns than the requested column choice needs.
    #[error(
        "{origin}:{line}: column {} was requested but the row has only {found} column(s)",
        .column + 1
    )]
    MissingColumn {
        /// File path or description of the input.
        origin: String,
        /// 1-based line number.
        line: usize,
        /// The 0-based column index that was requested (printed 1-based).
        column: usize,
        /// Number of columns found on the row.
        found: usize,
    },

    /// A wavenumber is zero, negative, infinite or NaN.
    #[error("{origin}:{line}: k = {} h/Mpc is not a finite positive number", number(.k))]
    InvalidK {
        /// File path or description of the input.
        origin: String,
        /// 1-based line (or row) number.
        line: usize,
        /// The offending wavenumber in h/Mpc.
        k: f64,
    },

    /// The wavenumbers are not strictly increasing.
    #[error(
        "{origin}:{line}: k = {} h/Mpc does not exceed the previous k = {} h/Mpc \
         (k must be strictly increasing)",
        number(.k),
        number(.previous)
    )]
    NonIncreasingK {
        /// File path or description of the input.
        origin: String,
        /// 1-based line (or row) number of the offending row.
        line: usize,
        /// The offending wavenumber in h/Mpc.
        k: f64,
        /// The wavenumber of the previous row in h/Mpc.
        previous: f64,
    },

    /// A power value is zero, negative, infinite or NaN.
    #[error(
        "{origin}:{line}: P = {} (Mpc/h)^3 at k = {} h/Mpc is not a finite positive number",
        number(.p),
        number(.k)
    )]
    InvalidPower {
        /// File path or description of the input.
        origin: String,
        /// 1-based line (or row) number.
        line: usize,
        /// The wavenumber of the row in h/Mpc.
        k: f64,
        /// The offending power in (Mpc/h)^3.
        p: f64,
    },

    /// The table has too few rows to be interpolated and extrapolated reliably.
    #[error("{origin}: {found} data row(s), at least {min} are needed")]
    TooFewPoints {
        /// File path or description of the input.
        origin: String,
        /// Number of data rows found.
        found: usize,
        /// Minimum number of rows required.
        min: usize,
    },

    /// Two arrays that must have the same length do not.
    #[error("{what}: {left} values against {right} values")]
    LengthMismatch {
        /// Which arrays (e.g. `k and P`).
        what: &'static str,
        /// Length of the first array.
        left: usize,
        /// Length of the second array.
        right: usize,
    },

    /// A tabulated value is not acceptable for a reason the variants above do not state (a value other
    /// than k or P, a k too close to the previous one, a P that overflows the interpolation).
    #[error("{origin}:{line}: {name} = {}: {reason}", number(.value))]
    InvalidValue {
        /// File path or description of the input.
        origin: String,
        /// 1-based line (or row) number.
        line: usize,
        /// What the value is, e.g. `b(k)`.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },

    /// A tabulated function was asked for outside its range (it is not extrapolated).
    #[error(
        "{what} is tabulated for {} <= k <= {} h/Mpc, but k = {} h/Mpc is needed",
        number(.min),
        number(.max),
        number(.k)
    )]
    OutOfRange {
        /// The function and where it came from.
        what: String,
        /// The requested wavenumber in h/Mpc.
        k: f64,
        /// Lower end of the table in h/Mpc.
        min: f64,
        /// Upper end of the table in h/Mpc.
        max: f64,
    },

    /// A numeric argument or parameter is outside its allowed range.
    #[error("invalid {name} = {}: {reason}", number(.value))]
    InvalidParameter {
        /// Name of the parameter, with its unit where it has one.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What the value must satisfy.
        reason: &'static str,
    },

    /// A cosmological parameter outside the box the linear-spectrum emulator was trained on.
    #[error(
        "{name} = {} is outside the linear-spectrum emulator's prior [{}, {}]: give a linear spectrum \
         (--linear FILE) or use Eisenstein & Hu (--eh)",
        number(.value), number(.min), number(.max)
    )]
    OutsidePrior {
        /// The parameter, e.g. `m_nu`.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Smallest value of the prior.
        min: f64,
        /// Largest value of the prior.
        max: f64,
    },

    /// A data file embedded in or shipped with the library is malformed.
    #[error("{what}: malformed at byte {offset}: {reason}")]
    BadDataFile {
        /// The file, e.g. `embedded linear-spectrum emulator`.
        what: String,
        /// Where reading stopped.
        offset: usize,
        /// What was expected.
        reason: &'static str,
    },

    /// No linear spectrum is embedded for the requested redshift.
    #[error("no embedded linear spectrum at z = {z}; embedded redshifts: {available}")]
    NoEmbeddedSpectrum {
        /// The requested redshift.
        z: f64,
        /// The redshifts that are embedded.
        available: &'static str,
    },

    /// A combination of settings that does not make sense, e.g. a Δχ² surface of a fixed parameter.
    #[error("{what}: {reason}")]
    InvalidChoice {
        /// The setting, as the user wrote it where possible.
        what: String,
        /// What is wrong and what is expected.
        reason: String,
    },

    /// A name (of a model, a FoG kind, a parameter, a preset) that is not known.
    #[error("unknown {what} `{name}`; available: {available}")]
    UnknownName {
        /// What kind of name, e.g. `real-space model`.
        what: &'static str,
        /// The name that was given.
        name: String,
        /// The names that are accepted.
        available: &'static str,
    },

    /// A cosmology name that is not a preset.
    #[error(
        "unknown cosmology `{name}`: the presets are {available} (or give the path of a CLASS or CAMB \
         .ini parameter file where a file is accepted)"
    )]
    UnknownCosmology {
        /// The name that was given.
        name: String,
        /// The preset names, comma-separated.
        available: String,
    },

    /// A line of a parameter file that is not `key = value` (or, for key–value pairs, an empty key).
    #[error("{origin}:{line}: `{text}` is not a `key = value` line")]
    IniSyntax {
        /// File path or description of the input.
        origin: String,
        /// 1-based line number (1-based index for key–value pairs).
        line: usize,
        /// The line, trimmed (and cut after 80 characters).
        text: String,
    },

    /// The value of a parameter that is read is not a finite number.
    #[error("{origin}:{line}: the value `{value}` of `{key}` is not a finite number")]
    IniValue {
        /// File path or description of the input.
        origin: String,
        /// 1-based line number (1-based index for key–value pairs).
        line: usize,
        /// The key.
        key: String,
        /// The value as written.
        value: String,
    },

    /// A parameter that a cosmology needs is not given.
    #[error("{origin}: {quantity} is not given; set one of {keys}")]
    MissingKey {
        /// File path or description of the input.
        origin: String,
        /// The missing quantity, e.g. `the Hubble constant`.
        quantity: &'static str,
        /// The keys that would set it.
        keys: &'static str,
    },

    /// Two parameters set the same quantity to values that disagree (or set σ8 and A_s both).
    #[error("{origin}:{line}: `{second}` conflicts with `{first}` (line {first_line}): both set {quantity}")]
    ConflictingKeys {
        /// File path or description of the input.
        origin: String,
        /// The quantity both set.
        quantity: &'static str,
        /// The earlier `key = value`.
        first: String,
        /// Line (or pair index) of the earlier one.
        first_line: usize,
        /// The later `key = value`.
        second: String,
        /// Line (or pair index) of the later one.
        line: usize,
    },

    /// The same parameter is given twice.
    #[error("{origin}:{line}: `{key}` is given twice (first on line {first_line})")]
    DuplicateKey {
        /// File path or description of the input.
        origin: String,
        /// The key.
        key: String,
        /// Line (or pair index) of the first occurrence.
        first_line: usize,
        /// Line (or pair index) of the second.
        line: usize,
    },

    /// Parameters that were read do not make a valid cosmology.
    #[error("{origin}: the parameters do not give a valid cosmology: {source}")]
    InvalidCosmology {
        /// File path or description of the input.
        origin: String,
        /// What [`Cosmology::validate`](crate::cosmology::Cosmology::validate) found.
        #[source]
        source: Box<Error>,
    },
    /// A parameter-file key whose value is outside the plausible range of its quantity.
    #[error("{origin}:{line}: {key} is outside the plausible range of {quantity}, {range}{hint}")]
    Implausible {
        /// File path or description of the input.
        origin: String,
        /// 1-based line number (1-based index for key–value pairs).
        line: usize,
        /// The `key = value` as written, quoted, with the quantity's value where the units differ,
        /// e.g. `` `H0 = 6766` (h = 67.66)``.
        key: String,
        /// The quantity (`h`, `A_s`, …: [`crate::cosmology::Plausible::name`]).
        quantity: &'static str,
        /// Its plausible range, `[min, max]`.
        range: String,
        /// A guess at what was meant (may be empty), e.g. that h was given as H0.
        hint: &'static str,
    },

    /// A computed value that is NaN or infinite: never written as a result.
    #[error(
        "the result has a non-finite value, {column} = {} at {at}: not written (a bug or an input \
         outside what the model handles; please report it with the command)",
        number(.value)
    )]
    NonFiniteOutput {
        /// The column.
        column: String,
        /// The row, e.g. `k = 0.05 h/Mpc`.
        at: String,
        /// The value.
        value: f64,
    },

    /// A plan would need more memory than the limit allows.
    #[error("{what} needs about {needed} of memory, above {limit} ({origin})")]
    MemoryLimit {
        /// What would be built, e.g. `the 1l-spt plan on 10000000 k`.
        what: String,
        /// The estimate, e.g. `3.4 TB`.
        needed: String,
        /// The limit, e.g. `12 GB`.
        limit: String,
        /// Where the limit comes from.
        origin: String,
    },

    /// A row of a table does not fit the table's shape or consistency: a matrix row with the wrong number
    /// of columns, a row too many, an element that differs from its mirror image across the diagonal.
    #[error("{origin}:{line}: {problem}")]
    BadRow {
        /// File path or description of the input.
        origin: String,
        /// 1-based line (or row) number.
        line: usize,
        /// What is wrong, with the values involved.
        problem: String,
    },
}

/// `v` as messages show it: as Rust prints it (shortest exact decimal), but in scientific notation when
/// that would be a long run of zeros (|v| < 1e-4 or ≥ 1e16), e.g. `1e-320` rather than 320 digits.
pub fn number(v: &f64) -> String {
    let size = v.abs();
    if size != 0.0 && size.is_finite() && !(1e-4..1e16).contains(&size) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

/// `Result` with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_stay_short() {
        assert_eq!(number(&0.05), "0.05");
        assert_eq!(number(&-3.0), "-3");
        assert_eq!(number(&1e-4), "0.0001");
        assert_eq!(number(&1e308), "1e308");
        assert_eq!(number(&-2.5e-320), "-2.5e-320");
        assert_eq!(number(&f64::NAN), "NaN");
        assert_eq!(number(&f64::NEG_INFINITY), "-inf");
        let e = Error::NonIncreasingK {
            origin: "k.dat".into(),
            line: 3,
            k: 1e-300,
            previous: 1e300,
        };
        assert_eq!(
            e.to_string(),
            "k.dat:3: k = 1e-300 h/Mpc does not exceed the previous k = 1e300 h/Mpc \
             (k must be strictly increasing)"
        );
    }

    #[test]
    fn messages_name_the_bad_value() {
        let e = Error::InvalidPower {
            origin: "pk.dat".into(),
            line: 17,
            k: 0.1,
            p: -3.0,
        };
        assert_eq!(
            e.to_string(),
            "pk.dat:17: P = -3 (Mpc/h)^3 at k = 0.1 h/Mpc is not a finite positive number"
        );
        let e = Error::InvalidParameter {
            name: "R [Mpc/h]",
            value: -8.0,
            reason: "must be finite and positive",
        };
        assert!(e.to_string().contains("R [Mpc/h] = -8"));
    }
}
