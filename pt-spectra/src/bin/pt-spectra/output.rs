//! Where the tables go: `--out` files checked against the run's inputs before any work, and every table
//! checked for non-finite values before it is written.

use anyhow::{bail, Context, Result};
use pt_spectra::output::Table;
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Refuses outputs that would replace an input of the same run, or each other: `outputs` are the
/// `(option, path)` of the files to be written, `inputs` those read. Called before any computation.
pub fn check_outputs(
    outputs: &[(&str, Option<&Path>)],
    inputs: &[(&str, Option<&Path>)],
) -> Result<()> {
    let outputs: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|&(o, p)| p.map(|p| (o, p)))
        .collect();
    for (i, &(option, out)) in outputs.iter().enumerate() {
        if out.is_dir() {
            bail!("{option} {}: is a directory, not a file", out.display());
        }
        for (input, path) in inputs.iter().filter_map(|&(o, p)| p.map(|p| (o, p))) {
            if same_file(out, path) {
                bail!(
                    "{option} {} would overwrite the input {input} {}: choose another output file",
                    out.display(),
                    path.display()
                );
            }
        }
        for &(other, path) in &outputs[..i] {
            if same_file(out, path) || out == path {
                bail!(
                    "{option} {} and {other} {} are the same file: choose two different files",
                    out.display(),
                    path.display()
                );
            }
        }
    }
    Ok(())
}

/// Whether `a` and `b` name one existing file (through links, `..` or another spelling).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
            return x.dev() == y.dev() && x.ino() == y.ino();
        }
        false
    }
    #[cfg(not(unix))]
    {
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// Prints `message` on standard error as `warning: message`, unless this run has printed it already
/// (a warning made while reading the input is in the table's header too).
pub fn warn_once(message: &str) {
    static SEEN: Mutex<BTreeSet<String>> = Mutex::new(BTreeSet::new());
    let new = SEEN
        .lock()
        .map_or(true, |mut seen| seen.insert(message.to_string()));
    if new {
        eprintln!("warning: {message}");
    }
}

/// Writes `table` as text to `out` (atomically: an existing file is replaced only by the whole new
/// table), or to standard output, after checking that every value is finite. The header's warnings
/// (its lines `warning: …`, e.g. a window whose Q0(0) is not 1) go to standard error as well.
pub fn write_output(out: Option<&PathBuf>, table: &Table) -> Result<()> {
    for line in &table.header {
        if let Some(warning) = line.strip_prefix("warning: ") {
            warn_once(warning);
        }
    }
    let text = table.checked()?.to_text();
    match out {
        Some(path) => pt_spectra::output::write_atomic(path, text.as_bytes())
            .with_context(|| format!("cannot write `{}`", path.display()))?,
        None => std::io::stdout().write_all(text.as_bytes())?,
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_that_is_an_input_is_refused() {
        let dir = std::env::temp_dir().join(format!("pt-spectra-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("lin.dat");
        std::fs::write(&input, "0.1 1\n").unwrap();
        let other = dir.join("out.dat");
        let spelled = dir.join(".").join("lin.dat");
        let inputs = [("--linear", Some(input.as_path())), ("--k-file", None)];
        let e = check_outputs(&[("--out", Some(spelled.as_path()))], &inputs).unwrap_err();
        assert!(
            e.to_string().contains("would overwrite the input --linear"),
            "{e}"
        );
        assert!(check_outputs(&[("--out", Some(other.as_path()))], &inputs).is_ok());
        assert!(check_outputs(&[("--out", None)], &inputs).is_ok());
        let both = [
            ("--out", Some(other.as_path())),
            ("--model-out", Some(other.as_path())),
        ];
        let e = check_outputs(&both, &inputs).unwrap_err();
        assert!(e.to_string().contains("are the same file"), "{e}");
        let e = check_outputs(&[("--out", Some(dir.as_path()))], &inputs).unwrap_err();
        assert!(e.to_string().contains("is a directory"), "{e}");
        #[cfg(unix)]
        {
            let link = dir.join("link.dat");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(check_outputs(&[("--out", Some(link.as_path()))], &inputs).is_err());
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
