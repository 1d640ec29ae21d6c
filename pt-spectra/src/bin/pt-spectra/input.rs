//! The options that say what to compute from: cosmology, linear spectrum, redshifts, loop-integral
//! settings, table cache and k grid; parsed here, turned into library inputs by the library.

use anyhow::{bail, Context, Result};
use pt_spectra::cosmology::TransferKind;
use pt_spectra::linear::{Columns, LinearSpectrum, LogGrid};
use pt_spectra::precision::{Precision, TwoLoopMethod};
use pt_spectra::setup::{self, LinearSource, NamedCosmology, Prepared, Request};
use pt_spectra::store::TableStore;
use pt_spectra::table::KGrid;
use std::path::{Path, PathBuf};

/// `K,P` (1-based column numbers) as 0-based [`Columns`].
pub fn parse_columns(s: &str) -> std::result::Result<Columns, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [k, p] = parts[..] else {
        return Err(format!(
            "`{s}`: expected two column numbers K,P (1-based), e.g. 1,2"
        ));
    };
    let one = |x: &str| match x.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n - 1),
        _ => Err(format!("`{x}` is not a column number (1, 2, …)")),
    };
    let (k, p) = (one(k)?, one(p)?);
    if k == p {
        return Err(format!("`{s}`: k and P must be different columns"));
    }
    Ok(Columns::new(k, p))
}

/// `QMIN,QMAX` [h/Mpc]: 0 < QMIN < QMAX, both finite.
pub fn parse_q_range(s: &str) -> std::result::Result<(f64, f64), String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [a, b] = parts[..] else {
        return Err(format!("`{s}`: expected QMIN,QMAX in h/Mpc, e.g. 1e-5,1e3"));
    };
    let number = |x: &str| {
        x.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite() && *v > 0.0)
            .ok_or_else(|| format!("`{x}` is not a finite positive wavenumber"))
    };
    let (lo, hi) = (number(a)?, number(b)?);
    if lo >= hi {
        return Err(format!("`{s}`: QMIN must be below QMAX"));
    }
    Ok((lo, hi))
}

/// A memory size such as `8G`.
fn parse_max_memory(s: &str) -> std::result::Result<f64, String> {
    pt_spectra::memory::parse_size(s).map_err(|e| e.to_string())
}

/// A 2-loop method by name.
fn parse_two_loop(s: &str) -> std::result::Result<TwoLoopMethod, String> {
    s.parse()
        .map_err(|e: pt_spectra::error::Error| e.to_string())
}

/// A precision preset by name.
pub fn parse_precision(s: &str) -> std::result::Result<Precision, String> {
    Precision::preset(s).map_err(|e| e.to_string())
}

/// Eisenstein & Hu (1998) transfer function choice.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum EhKind {
    /// Full fit with baryon acoustic oscillations.
    Wiggle,
    /// Smooth no-wiggle fit.
    NoWiggle,
}

/// The cosmology, linear spectrum, redshift and accuracy: the options `real`, `rsd` and `fit` share.
#[derive(clap::Args, Debug)]
pub struct SpectrumInput {
    /// Cosmology: a preset (`gm2012`, the default, or `planck2018`) or a CLASS/CAMB `.ini` parameter
    /// file. It sets the growth D(z) and f(z) (rescaling from --z-input to --z, default f, FoG scale)
    /// and the no-wiggle reference; without --linear, a cosmology other than gm2012 is emulated
    /// (CAMB's P_m and, with massive neutrinos, P_cb; a parameter outside the emulator's prior is an
    /// error, --eh keeps Eisenstein & Hu).
    #[arg(long, value_name = "NAME|FILE")]
    cosmology: Option<String>,
    /// Linear spectrum table (k [h/Mpc], P [(Mpc/h)^3]; CAMB or CLASS format). Default: the embedded
    /// CAMB spectrum of the Gil-Marín et al. (2012) cosmology.
    #[arg(long, value_name = "FILE", conflicts_with = "eh")]
    linear: Option<PathBuf>,
    /// Columns of k and P in the --linear table, 1-based, e.g. `1,3` for a CLASS file with several
    /// spectra. Default `1,2`.
    #[arg(long, value_name = "K,P", value_parser = parse_columns, requires = "linear")]
    columns: Option<Columns>,
    /// Use the Eisenstein & Hu (1998) linear spectrum of the cosmology instead of a table: `wiggle`
    /// (with BAO) or `no-wiggle` (the smooth fit); gm2012 is normalised to σ8 = 0.8.
    #[arg(long, value_name = "KIND", value_enum)]
    eh: Option<EhKind>,
    /// Redshift of the --linear table.
    #[arg(
        long,
        value_name = "Z",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    z_input: f64,
    /// Redshift of the output; the input is rescaled by [D(z)/D(z_input)]² of the cosmology.
    #[arg(
        long,
        value_name = "Z",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    z: f64,
    /// Accuracy of the loop integrals: fast, default or reference.
    #[arg(long, value_name = "PRESET", default_value = pt_spectra::jobs::defaults::PRECISION, value_parser = parse_precision)]
    precision: Precision,
    /// Range of every loop integral over q [h/Mpc], QMIN,QMAX (default 1e-5,1e3). The 2-loop and
    /// propagator terms P15, P17 depend on QMAX (UV sensitivity); the header states the range.
    #[arg(long, value_name = "QMIN,QMAX", value_parser = parse_q_range)]
    q_range: Option<(f64, f64)>,
    /// The most memory the plans may take, e.g. `8G` or `500M` (decimal units): a k grid whose
    /// estimated memory exceeds it is refused before anything is allocated, with both figures.
    /// Default: $PT_SPECTRA_MAX_MEMORY, else half of the machine's memory.
    #[arg(long, value_name = "SIZE", value_parser = parse_max_memory)]
    max_memory: Option<f64>,
    /// How the loop terms are computed (1-loop, TNS, the galaxy model `ept`, 2-loop, the one-loop
    /// bispectrum): `basis` (precomputed tensors contracted with the spectrum's projection on a basis
    /// of linear spectra; built and cached once per k grid or triangle set, seconds, minutes for
    /// 2-loop and ~0.7 s per triangle for the bispectrum, then a fraction of a millisecond
    /// to milliseconds per spectrum; a spectrum the basis does not represent is computed directly,
    /// with a note), `direct` (integrals for every spectrum), or `auto` (basis if the tensors of this
    /// grid are already cached, else direct). The header says which was used.
    #[arg(long, value_name = "METHOD", default_value = pt_spectra::jobs::defaults::TWO_LOOP, value_parser = parse_two_loop)]
    two_loop: TwoLoopMethod,
    /// Directory of the cached angular tables (P15, P17). Default: $PT_SPECTRA_CACHE, else
    /// $XDG_CACHE_HOME/pt-spectra, else ~/.cache/pt-spectra.
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
}

/// What the input options give: the prepared spectrum and growth, the loop settings, the table store.
pub struct Loaded {
    /// The linear spectrum at the output redshift, with the cosmology's growth.
    pub prepared: Prepared,
    /// The loop-integral settings.
    pub precision: Precision,
    /// The angular-table cache.
    pub store: TableStore,
}

impl SpectrumInput {
    /// The files these options read, by option, for [`crate::output::check_outputs`].
    pub fn files(&self) -> Vec<(&'static str, Option<&Path>)> {
        let cosmology = self
            .cosmology
            .as_deref()
            .map(Path::new)
            .filter(|p| p.is_file());
        vec![
            ("--linear", self.linear.as_deref()),
            ("--cosmology", cosmology),
        ]
    }

    /// Parses the cosmology and reads the spectrum; warnings go to standard error.
    pub fn load(&self) -> Result<Loaded> {
        self.load_at(self.z, "--z")
    }

    /// [`Self::load`] at the output redshift `z` (given by `origin`) in place of --z.
    pub fn load_at(&self, z: f64, origin: &str) -> Result<Loaded> {
        for (name, z) in [(origin, z), ("--z-input", self.z_input)] {
            if !(z.is_finite() && z > -1.0) {
                bail!("{name} {z}: a redshift must be finite and > -1");
            }
        }
        let (cosmology, ignored) = match &self.cosmology {
            None => (None, Vec::new()),
            Some(s) => {
                let (named, ignored) =
                    NamedCosmology::parse(s).map_err(|e| anyhow::anyhow!("--cosmology: {e}"))?;
                (Some(named), ignored)
            }
        };
        let source = match (&self.linear, self.eh) {
            (Some(path), _) => LinearSource::Table {
                // The library error already names the file and the OS error; keep the message single.
                spectrum: Box::new(
                    LinearSpectrum::from_file_with_columns(path, self.columns.unwrap_or_default())
                        .map_err(|e| anyhow::anyhow!("{e}"))?,
                ),
                z_input: self.z_input,
            },
            (None, Some(EhKind::Wiggle)) => LinearSource::EisensteinHu(TransferKind::Wiggle),
            (None, Some(EhKind::NoWiggle)) => LinearSource::EisensteinHu(TransferKind::NoWiggle),
            (None, None) => LinearSource::Embedded,
        };
        let prepared = setup::prepare(Request {
            source,
            cosmology,
            z,
        })?;
        // Ignored keys are a note (the file may hold a Boltzmann code's other settings).
        for w in setup::input_warnings(&prepared, &ignored, &[]) {
            eprintln!("note: {w}");
        }
        for w in &prepared.warnings {
            crate::output::warn_once(w);
        }
        let mut precision = self.precision.clone();
        precision.two_loop = self.two_loop;
        precision.max_memory = match self.max_memory {
            Some(m) => Some(m),
            None => pt_spectra::memory::env_max_memory()?,
        };
        if let Some((lo, hi)) = self.q_range {
            precision = precision
                .with_q_range(lo, hi)
                .context("invalid --q-range")?;
        }
        let store = match &self.cache_dir {
            Some(dir) => TableStore::new(dir),
            None => TableStore::from_env(),
        };
        Ok(Loaded {
            prepared,
            precision,
            store,
        })
    }
}

/// The linear spectrum and the output k grid: the options `real` and `rsd` share.
#[derive(clap::Args, Debug)]
pub struct Input {
    #[command(flatten)]
    pub spectrum: SpectrumInput,
    /// Smallest output k [h/Mpc] (log-spaced grid).
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1e-3,
        allow_hyphen_values = true
    )]
    k_min: f64,
    /// Largest output k [h/Mpc].
    #[arg(
        long,
        value_name = "K",
        default_value_t = 1.0,
        allow_hyphen_values = true
    )]
    k_max: f64,
    /// Number of log-spaced k values.
    #[arg(long, value_name = "N", default_value_t = 100)]
    nk: usize,
    /// Read the output k values [h/Mpc] from the first column of this file instead ('#' comments).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["k_min", "k_max", "nk"])]
    k_file: Option<PathBuf>,
}

impl Input {
    /// The files these options read, by option.
    pub fn files(&self) -> Vec<(&'static str, Option<&Path>)> {
        let mut files = self.spectrum.files();
        files.push(("--k-file", self.k_file.as_deref()));
        files
    }

    /// The output k grid [h/Mpc] and the loaded input (with a warning when the grid reaches the
    /// extrapolated ends of the linear table).
    pub fn load(&self) -> Result<(KGrid, Loaded)> {
        let k = match &self.k_file {
            Some(path) => read_k_file(path)?,
            None => LogGrid::new(self.k_min, self.k_max, self.nk)
                .context("invalid --k-min/--k-max/--nk")?
                .k_grid(),
        };
        let loaded = self.spectrum.load()?;
        for w in setup::input_warnings(&loaded.prepared, &[], &k) {
            crate::output::warn_once(&w);
        }
        Ok((k, loaded))
    }
}

/// k values from the first column of a file: finite, positive, strictly increasing. The file is read as
/// any table (`#` comments, one optional row of column names, comma or blank separated, any line ends);
/// every error names the file and the line.
pub fn read_k_file(path: &PathBuf) -> Result<KGrid> {
    KGrid::read(path).context("--k-file")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(name: &str, text: &str) -> PathBuf {
        let path =
            std::env::temp_dir().join(format!("pt-spectra-real-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn k_files_are_validated_with_line_numbers() {
        let ok = write("ok", "# k\n0.01 1\n\n0.1, 2 # comment\n");
        assert_eq!(read_k_file(&ok).unwrap().into_vec(), vec![0.01, 0.1]);
        for (name, text, needle) in [
            ("dec", "0.1\n0.05\n", ":2: k = 0.05"),
            ("nan", "0.1\nNaN\n", ":2: k = NaN"),
            ("neg", "-1\n", ":1: k = -1"),
            ("txt", "0.1\nabc\n", ":2: cannot parse `abc`"),
            ("empty", "# nothing\n", "0 data row(s)"),
        ] {
            let e = format!("{:#}", read_k_file(&write(name, text)).unwrap_err());
            assert!(e.contains(needle), "{name}: {e}");
        }
        let missing = format!(
            "{:#}",
            read_k_file(&PathBuf::from("/nonexistent/k")).unwrap_err()
        );
        assert!(missing.contains("/nonexistent/k"), "{missing}");
    }

    #[test]
    fn k_files_of_any_origin_are_read_or_refused_at_a_line() {
        let windows = write("crlf", "\u{feff}# k\r\n0.01, y\r\n0.02, x\r\n");
        assert_eq!(read_k_file(&windows).unwrap().into_vec(), vec![0.01, 0.02]);
        let mac = write("cr", "k\r0.01\r0.02\r0.03");
        assert_eq!(
            read_k_file(&mac).unwrap().into_vec(),
            vec![0.01, 0.02, 0.03]
        );
        let cases: [(&str, &[u8], &str); 9] = [
            (
                "dup",
                b"0.1\n0.1\n",
                ":2: k = 0.1 h/Mpc does not exceed the previous k = 0.1",
            ),
            ("huge", b"0.1\n1e400\n", ":2: k = inf h/Mpc"),
            (
                "tiny",
                b"1e-320\n1e-321\n",
                ":2: k = 1e-321 h/Mpc does not exceed",
            ),
            (
                "zero",
                b"# k\n\n-0\n",
                ":3: k = -0 h/Mpc is not a finite positive number",
            ),
            ("names", b"k\nkh\n0.1\n", ":2: cannot parse `kh`"),
            (
                "bytes",
                b"\x7fELF\x02\x01\n\xff\xfe\n",
                ":2: cannot parse `\u{fffd}\u{fffd}`",
            ),
            ("cut", b"0.1\n0.2\n0.", ":3: k = 0 h/Mpc"),
            ("esc", b"0.1\n\x1b[31m\n", ":2: cannot parse `\\u{1b}[31m`"),
            ("blank", b"\n \t\n# only comments\n", "0 data row(s)"),
        ];
        for (name, bytes, needle) in cases {
            let path = write(name, "");
            std::fs::write(&path, bytes).unwrap();
            let e = format!("{:#}", read_k_file(&path).unwrap_err());
            assert!(e.contains(needle), "{name}: {e}");
            assert!(e.contains(&path.display().to_string()), "{name}: {e}");
        }
    }

    #[test]
    fn column_choices_and_q_ranges_are_checked() {
        assert_eq!(parse_columns("1,3").unwrap(), Columns::new(0, 2));
        for bad in ["0,1", "1", "1,1", "a,2", "1,2,3"] {
            assert!(parse_columns(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_q_range("1e-4, 10").unwrap(), (1e-4, 10.0));
        for bad in ["1", "10,1", "0,1", "nan,1", "1,inf", "a,b"] {
            assert!(parse_q_range(bad).is_err(), "{bad}");
        }
    }
}
