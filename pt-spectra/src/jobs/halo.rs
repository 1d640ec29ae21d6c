//! `pt-spectra halo`: the scale-dependent bias b(k) and stochasticity P_εε(k) from measured spectra.

use super::VERSION;
use crate::error::{Error, Result};
use crate::halo::{bias_and_noise, MeasuredSpectrum};
use crate::output::{Table, POWER, WAVENUMBER};

/// The inputs of `halo`: the measured matter, matter–halo and halo spectra (the last with its noise)
/// on one k grid, and optionally the halo number density for the ratio to Poisson noise.
#[derive(Debug, Clone, PartialEq)]
pub struct HaloRequest {
    /// P_mm, the matter power spectrum.
    pub pmm: MeasuredSpectrum,
    /// P_mh, the matter–halo cross spectrum.
    pub pmh: MeasuredSpectrum,
    /// P_hh, the measured halo spectrum (noise included).
    pub phh: MeasuredSpectrum,
    /// n_h [(h/Mpc)^3], for `P_eps_n` = P_εε n_h = P_εε/P_Poisson.
    pub number_density: Option<f64>,
}

/// `pt-spectra halo`: `k b P_eps`, with `P_eps_n` = P_εε n_h for a number density, and `err_b
/// err_P_eps (err_P_eps_n)` where the inputs have errors ([`bias_and_noise`]). The columns `b` and
/// `P_eps` are what `--bias-file` and `--noise-file` read by name.
///
/// ```
/// use pt_spectra::{halo::MeasuredSpectrum, jobs::{halo_table, HaloRequest}};
/// let k = vec![0.05, 0.1];
/// let m = |name, p: Vec<f64>| MeasuredSpectrum::new(name, "memory", k.clone(), p, None).unwrap();
/// let request = HaloRequest { pmm: m("P_mm", vec![8e3, 5e3]), pmh: m("P_mh", vec![2e4, 1.3e4]),
///     phh: m("P_hh", vec![8.2e4, 5.98e4]), number_density: Some(2.5e-5) };
/// let t = halo_table(&request)?;
/// assert_eq!(t.names(), ["k", "b", "P_eps", "P_eps_n"]);
/// assert!((t.column("P_eps_n").unwrap()[0] - 0.8).abs() < 1e-12);
/// # Ok::<(), pt_spectra::error::Error>(())
/// ```
///
/// # Errors
/// As [`bias_and_noise`]; [`Error::InvalidParameter`] for a number density that is not finite and
/// positive.
pub fn halo_table(request: &HaloRequest) -> Result<Table> {
    if let Some(n) = request.number_density {
        if !(n.is_finite() && n > 0.0) {
            return Err(Error::InvalidParameter {
                name: "number density n_h [(h/Mpc)^3]",
                value: n,
                reason: "must be finite and positive",
            });
        }
    }
    let r = bias_and_noise(&request.pmm, &request.pmh, &request.phh)?;
    let mut header = vec![
        format!(
            "pt-spectra {VERSION} halo: b = P_mh/P_mm (eq. bias_eq) and P_eps = P_hh - P_mh^2/P_mm \
             (eq. delta_field) from P_mm = {}, P_mh = {}, P_hh = {} (noise included)",
            request.pmm.origin, request.pmh.origin, request.phh.origin
        ),
        "the columns b and P_eps feed --bias-file and --noise-file of rsd and fit (read by name)"
            .into(),
    ];
    if let Some(n) = request.number_density {
        header.push(format!(
            "P_eps_n = P_eps n_h = P_eps/P_Poisson, n_h = {n:e} (h/Mpc)^3 (P_Poisson = 1/n_h = {:.6e} \
             (Mpc/h)^3)",
            1.0 / n
        ));
    }
    if r.bias_error.is_some() {
        let given: Vec<&str> = [&request.pmm, &request.pmh, &request.phh]
            .iter()
            .filter(|s| s.error.is_some())
            .map(|s| s.name)
            .collect();
        header.push(format!(
            "errors: first-order propagation of the errors of {} (a missing error counts as 0), taken \
             as independent: err_b^2 = (s_mh/P_mm)^2 + (b s_mm/P_mm)^2, err_P_eps^2 = s_hh^2 + \
             (2b s_mh)^2 + (b^2 s_mm)^2 (spectra of the same simulations correlate: an estimate)",
            given.join(", ")
        ));
    }
    let negative = r.noise.iter().filter(|&&p| p <= 0.0).count();
    if negative > 0 {
        header.push(format!(
            "warning: P_eps <= 0 at {negative} of {} k; --noise-file accepts only positive values",
            r.k.len()
        ));
    }
    let mut t = Table::new(header);
    t.push("k", WAVENUMBER, r.k.clone());
    t.push("b", "1", r.bias);
    t.push("P_eps", POWER, r.noise.clone());
    let ratio = |v: &[f64], n: f64| v.iter().map(|p| p * n).collect::<Vec<f64>>();
    if let Some(n) = request.number_density {
        t.push("P_eps_n", "1", ratio(&r.noise, n));
    }
    if let (Some(be), Some(ne)) = (r.bias_error, r.noise_error) {
        t.push("err_b", "1", be);
        t.push("err_P_eps", POWER, ne.clone());
        if let Some(n) = request.number_density {
            t.push("err_P_eps_n", "1", ratio(&ne, n));
        }
    }
    Ok(t)
}
