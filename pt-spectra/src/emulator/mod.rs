//! The linear-spectrum emulator: P_lin(k, z) of all matter and of cold dark matter + baryons from the
//! cosmological parameters, without a Boltzmann code.
//!
//! * **What is emulated.** G = ln P_cb(k, z) − ln A_s − (n_s − 1) ln(k h/k_pivot) − 2 ln(D_md(z)/Ω_m)
//!   and ln(P_m/P_cb) (set to 0, exactly, without massive neutrinos), as functions of the six parameters that shape the transfer functions (Ω_b, Ω_m,
//!   h, Σm_ν, w0, wa), on nodes in x = k r_d (r_d, the drag sound horizon of Aubourg et al. 2015, eq. 16, in Mpc/h: the
//!   baryon oscillations then sit at the same x for every cosmology) and in redshift. A_s and n_s enter
//!   through the primordial factor, which is exact in linear theory, so any A_s and n_s are accepted.
//!   D_md(z) is the growing mode of the background ([`Cosmology::growth_md_and_rate`]: all matter as
//!   dust, normalised to a deep in matter domination); dividing it out takes the steep dependence of
//!   the amplitude on w0, wa and Ω_m out of what the polynomials must fit.
//! * **How.** Each quantity is the training mean plus its leading principal components; each component's
//!   coefficient is a polynomial (Legendre products, the terms listed in the file) of seven
//!   coordinates: the shape parameters mapped to [−1, 1] by the prior box, and the early dark-energy
//!   density ([`PriorPoint::coordinates`]). Between redshift nodes (uniform in ln(1 + z)) the four nearest
//!   nodes are joined by a cubic (Lagrange) polynomial in s = ln(1 + z), whose derivative gives the
//!   scale-dependent growth rate f_cb(k, z) = d ln D_cb/d ln a = f_md(z) − ½ ∂G/∂s.
//! * **Trained on** CAMB spectra (`pt-spectra/data/make_emulator_training.py`, fitted by
//!   `pt-spectra/data/fit_emulator.py`): three degenerate massive neutrinos of total mass Σm_ν,
//!   N_eff = 3.046, T_CMB = 2.7255 K, flat, w0–wa dark energy in CAMB's PPF model. Its accuracy on
//!   cosmologies it was not trained on is in the file (per k) and in `docs/emulator.md`.
//! * **Units:** k in h/Mpc, P in (Mpc/h)³; Σm_ν in eV.
//!
//! ```
//! use pt_spectra::{cosmology::Cosmology, emulator::LinearEmulator};
//! let emulator = LinearEmulator::embedded()?;
//! let spectra = emulator.spectra(&Cosmology::planck2018(), 0.0)?;
//! assert!((spectra.sigma8 / 0.821734 - 1.0).abs() < 2e-3); // CAMB, massless neutrinos
//! # Ok::<(), pt_spectra::error::Error>(())
//! ```

mod format;
use format::HeadOf;
pub mod prior;

use crate::cosmology::{Cosmology, Neutrinos, EV_PER_OMEGA_NU};
use crate::error::{Error, Result};
use crate::linear::{top_hat, LinearSpectrum};
pub use prior::{PriorPoint, PriorRange, COORDINATES, PARAMETER_NAMES, SHAPE_PARAMETERS};
use std::f64::consts::PI;

/// The emulator file shipped with the library.
const EMBEDDED: &[u8] = include_bytes!("../../data/linear_emulator.bin");

/// The drag sound horizon r_d in Mpc/h from the fit of Aubourg et al. (2015, eq. 16), accurate to ~0.1%
/// for massive neutrinos; here only a coordinate that aligns the baryon oscillations of all cosmologies.
pub fn drag_horizon(omega_b: f64, omega_m: f64, h: f64, m_nu: f64) -> f64 {
    let w_nu = m_nu / EV_PER_OMEGA_NU;
    let w_b = omega_b * h * h;
    let w_cb = omega_m * h * h - w_nu;
    55.154 * (-72.3 * (w_nu + 0.0006).powi(2)).exp() / (w_cb.powf(0.25351) * w_b.powf(0.12807)) * h
}

/// Below this Σm_ν (eV) the emulated ln(P_m/P_cb) is tapered to 0 at Σm_ν = 0 and the massless head
/// tapered in (continuity of P_m and P_cb; [`LinearEmulator::spectra`]): a tenth of the smallest mass
/// the oscillations allow (0.059 eV), so no physical cosmology is touched.
pub const RATIO_TAPER: f64 = 0.005;

/// The emulator: parsed once, then [`spectra`](Self::spectra) per cosmology.
#[derive(Debug, Clone)]
pub struct LinearEmulator {
    file: format::Parsed,
    max_degree: usize,
    origin: String,
}

/// The emulated linear spectra of one cosmology at one redshift.
#[derive(Debug, Clone)]
pub struct EmulatedSpectra {
    /// The redshift.
    pub z: f64,
    /// Wavenumbers in h/Mpc (uniform in ln k; the range depends on r_d).
    pub k: Vec<f64>,
    /// P of all matter (CDM, baryons and massive neutrinos) in (Mpc/h)³.
    pub p_m: Vec<f64>,
    /// P of cold dark matter + baryons in (Mpc/h)³ (equal to `p_m` for massless neutrinos).
    pub p_cb: Vec<f64>,
    /// Growth rate of cold dark matter + baryons, f_cb(k, z) = d ln D_cb(k, z)/d ln a.
    pub f_cb: Vec<f64>,
    /// Estimated relative error of `p_cb` per k (the test set's 99th percentile of |Δ ln P|).
    pub error_cb: Vec<f64>,
    /// Estimated relative error of `p_m` per k.
    pub error_m: Vec<f64>,
    /// The neutrino setting emulated (the cosmology's).
    pub neutrinos: Neutrinos,
    /// The measured worst |Δ ln P| of P_cb and of P_m against CAMB over the whole stated prior
    /// (corners included, 1e-3 ≤ k ≤ 1 h/Mpc, 0 ≤ z ≤ 3) for this neutrino setting.
    pub worst: [f64; 2],
    /// σ8 of all matter at `z`.
    pub sigma8: f64,
    /// A_s at the pivot (given, or set by σ8).
    pub a_s: f64,
}

/// The growth of cold dark matter + baryons with massive neutrinos ([`LinearEmulator::growth_cb`]).
#[derive(Debug, Clone)]
pub struct ScaleDependentGrowth {
    /// The redshift.
    pub z: f64,
    /// Wavenumbers in h/Mpc.
    pub k: Vec<f64>,
    /// D_cb(k, z), normalised to 1 at z = 0 at every k.
    pub d_cb: Vec<f64>,
    /// f_cb(k, z) = d ln D_cb/d ln a.
    pub f_cb: Vec<f64>,
}

impl EmulatedSpectra {
    /// P_m as a [`LinearSpectrum`] (power-law extrapolation beyond the nodes).
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`].
    pub fn matter(&self) -> Result<LinearSpectrum> {
        LinearSpectrum::from_nodes(self.k.clone(), self.p_m.clone())
    }

    /// P_cb as a [`LinearSpectrum`].
    ///
    /// # Errors
    /// As [`LinearSpectrum::from_nodes`].
    pub fn cb(&self) -> Result<LinearSpectrum> {
        LinearSpectrum::from_nodes(self.k.clone(), self.p_cb.clone())
    }
}

impl LinearEmulator {
    /// The emulator shipped with the library (`pt-spectra/data/linear_emulator.bin`).
    ///
    /// # Errors
    /// [`Error::BadDataFile`] if the embedded file is malformed (a build error, tested).
    pub fn embedded() -> Result<Self> {
        Self::from_bytes(EMBEDDED, "embedded linear-spectrum emulator")
    }

    /// An emulator from the bytes of a file written by `fit_emulator.py`; `origin` names it.
    ///
    /// # Errors
    /// [`Error::BadDataFile`] naming the byte where the layout breaks.
    pub fn from_bytes(bytes: &[u8], origin: &str) -> Result<Self> {
        let file = format::parse(bytes, origin)?;
        let max_degree = file
            .exponents
            .iter()
            .chain(file.heads.iter().flat_map(|h| h.exponents.iter()))
            .flat_map(|e| e.iter())
            .map(|&d| usize::from(d))
            .max()
            .unwrap_or(0);
        Ok(Self {
            file,
            max_degree,
            origin: origin.to_string(),
        })
    }

    /// The prior: the range of each of the eight parameters it was trained or tested on. The six shape
    /// parameters must lie inside; A_s and n_s may lie outside (their dependence is exact).
    pub fn prior(&self) -> Vec<PriorRange> {
        let mut out = self.file.stated.clone();
        out.extend_from_slice(&self.file.prior[SHAPE_PARAMETERS..]);
        out
    }

    /// The redshift range, [z_min, z_max].
    pub fn z_range(&self) -> (f64, f64) {
        let z = &self.file.z_nodes;
        (z[0], z[z.len() - 1])
    }

    /// One line for output headers: what the emulator is and where it is valid.
    pub fn describe(&self) -> String {
        let prior: Vec<String> = self
            .file
            .stated
            .iter()
            .map(|p| format!("{} in [{}, {}]", p.name, p.min, p.max))
            .collect();
        let (z0, z1) = self.z_range();
        let settings: Vec<&str> = self
            .neutrino_settings()
            .into_iter()
            .map(Neutrinos::name)
            .collect();
        format!(
            "{} (trained on CAMB; prior {}, {} <= {}; z in [{z0}, {z1}]; neutrinos: {}; N_eff 3.046, \
             PPF dark energy, flat)",
            self.origin,
            prior.join(", "),
            prior::EARLY_DE_NAME,
            crate::error::number(&(self.file.q_bound * self.file.q_max)),
            settings.join(" or ")
        )
    }

    /// The neutrino settings emulated: three degenerate species and those of the file's heads.
    pub fn neutrino_settings(&self) -> Vec<Neutrinos> {
        std::iter::once(Neutrinos::ThreeDegenerate)
            .chain(self.file.heads.iter().filter_map(|h| match h.of {
                HeadOf::Setting(s) => Some(s),
                HeadOf::Massless => None,
            }))
            .collect()
    }

    /// The largest early dark-energy density q = ρ_DE/ρ_m at a = 0.1 of the prior
    /// ([`PriorPoint::coordinates`]).
    pub fn q_limit(&self) -> f64 {
        self.file.q_bound * self.file.q_max
    }

    /// The measured worst |Δ ln P| of P_cb and of P_m over the prior with massless neutrinos (Σm_ν =
    /// 0), if the file has a massless head (else the spectra at Σm_ν = 0 carry [`Self::worst`]'s
    /// figure of three degenerate species).
    pub fn worst_massless(&self) -> Option<[f64; 2]> {
        self.head_of(HeadOf::Massless).map(|h| h.worst)
    }

    /// The measured worst |Δ ln P| of P_cb and of P_m over the prior with Σm_ν > 0 shared as
    /// `neutrinos`, if emulated.
    pub fn worst(&self, neutrinos: Neutrinos) -> Option<[f64; 2]> {
        if neutrinos == Neutrinos::ThreeDegenerate {
            return Some(self.file.worst);
        }
        self.head_of(HeadOf::Setting(neutrinos)).map(|h| h.worst)
    }

    /// P_m, P_cb and f_cb of `cosmology` at redshift `z`.
    ///
    /// # Errors
    /// [`Error::OutsidePrior`] naming a shape parameter outside the prior, or the early dark-energy
    /// density beyond its bound; [`Error::InvalidParameter`] for a curved cosmology or a redshift
    /// outside [`z_range`](Self::z_range); [`Error::InvalidChoice`] for a neutrino setting that is not
    /// emulated ([`neutrino_settings`](Self::neutrino_settings)).
    pub fn spectra(&self, cosmology: &Cosmology, z: f64) -> Result<EmulatedSpectra> {
        let point = PriorPoint::of(cosmology)?;
        let u = self.coordinates(&point)?;
        let head = self.head(cosmology)?;
        let m_nu = point.values[3];
        // The massless head: CAMB's massless spectrum over the base's at Σm_ν = 0 (the edge of the
        // training box; CAMB's massless run is not the limit of its massive runs). Tapered in below
        // RATIO_TAPER, as the ratio's offset is tapered out, so P_cb and P_m are continuous in Σm_ν;
        // nothing changes from RATIO_TAPER up.
        let taper = (1.0 - m_nu / RATIO_TAPER).max(0.0);
        let mut heads: Vec<(&format::Head, f64)> = head.map(|h| (h, 1.0)).into_iter().collect();
        if taper > 0.0 {
            heads.extend(self.head_of(HeadOf::Massless).map(|h| (h, taper)));
        }
        let (z0, z1) = self.z_range();
        if !(z >= z0 - 1e-12 && z <= z1 + 1e-12) {
            return Err(Error::InvalidParameter {
                name: "z",
                value: z,
                reason: "outside the linear-spectrum emulator's redshift range [0, 3]",
            });
        }
        let [ob, om, h, ..] = point.values;
        let n_s = point.values[7];
        let r_d = if self.file.rescale {
            drag_horizon(ob, om, h, m_nu)
        } else {
            1.0
        };
        let (lx0, lx1) = self.file.ln_x;
        let n_x = self.file.n_x;
        let step = (lx1 - lx0) / (n_x - 1) as f64;
        let ln_k: Vec<f64> = (0..n_x).map(|i| lx0 + step * i as f64 - r_d.ln()).collect();
        // k_i = k_0 q^i (a geometric progression: no exponential per node)
        let ratio = step.exp();
        let k: Vec<f64> = std::iter::successors(Some(ln_k[0].exp()), |k| Some(k * ratio))
            .take(n_x)
            .collect();
        let z = z.clamp(z0, z1);
        let point_coefficients = self.point_coefficients(&u, &heads);
        let shape_at = |z: f64| self.shape(&point_coefficients, &heads, z);
        // The emulated ln(P_m/P_cb), continuous as Σm_ν → 0: P_m = P_cb exactly without massive
        // neutrinos (the emulated ratio is then its own error, and the neutrino head is 0 too: the
        // settings differ only in how the mass is shared); below RATIO_TAPER the ratio's value at
        // Σm_ν = 0 (its polynomial's offset, 7e-4 to 1.2e-3) is removed in proportion, so that P_m
        // meets P_cb at 0 instead of jumping by the offset at 0⁺.
        // the coefficients of the same point with Σm_ν = 0, if the taper applies (the massless head
        // adds nothing to the ratio)
        let massless = if m_nu > 0.0 && taper > 0.0 {
            let mut p = point;
            p.values[3] = 0.0;
            Some(self.point_coefficients(&self.coordinates(&p)?, &heads))
        } else {
            None
        };
        let ln_ratio = |shape: &Shape, z: f64| -> Vec<f64> {
            if m_nu <= 0.0 {
                return vec![0.0; shape.ratio.len()];
            }
            match &massless {
                Some(c) => (shape.ratio.iter().zip(&self.shape(c, &heads, z).ratio))
                    .map(|(r, o)| r - taper * o)
                    .collect(),
                None => shape.ratio.clone(),
            }
        };
        let shape = shape_at(z);
        // ln P_cb = G_cb + 2 ln(D_md/Ω_m) + ln A_s + (n_s − 1) ln(k h/k_pivot)
        let growth = |z: f64| {
            let (d_md, f) = cosmology.growth_md_and_rate(z);
            (2.0 * (d_md / om).ln(), f)
        };
        let (growth_z, f_ode) = growth(z);
        let tilt: Vec<f64> = ln_k
            .iter()
            .map(|&lk| (n_s - 1.0) * (lk + (h / point.k_pivot).ln()))
            .collect();
        let ln_as = match point.a_s {
            Some(a_s) => a_s.ln(),
            None => {
                let today = shape_at(z0);
                let today_ratio = ln_ratio(&today, z0);
                let growth_0 = growth(z0).0;
                let sigma8_unit = sigma8(&k, step, |i| {
                    (today.cb[i] + growth_0 + today_ratio[i] + tilt[i]).exp()
                });
                let crate::cosmology::Amplitude::Sigma8(target) = cosmology.amplitude else {
                    unreachable!("a_s is None only for a σ8 amplitude")
                };
                2.0 * (target / sigma8_unit).ln()
            }
        };
        let ln_p_cb: Vec<f64> = (0..n_x)
            .map(|i| shape.cb[i] + growth_z + ln_as + tilt[i])
            .collect();
        let p_cb: Vec<f64> = ln_p_cb.iter().map(|v| v.exp()).collect();
        let ratio = ln_ratio(&shape, z);
        let p_m: Vec<f64> = (0..n_x).map(|i| (ln_p_cb[i] + ratio[i]).exp()).collect();
        let sigma8 = sigma8(&k, step, |i| p_m[i]);
        Ok(EmulatedSpectra {
            z,
            k,
            p_m,
            p_cb,
            f_cb: shape.d_cb_ds.iter().map(|d| f_ode - 0.5 * d).collect(),
            error_cb: self.file.error[0].clone(),
            error_m: self.file.error[1].clone(),
            neutrinos: cosmology.neutrinos,
            worst: self.worst_of(cosmology.neutrinos, m_nu),
            sigma8,
            a_s: ln_as.exp(),
        })
    }

    /// The scale-dependent growth of cold dark matter + baryons at `z`: D_cb(k, z) = T_cb(k, z)/T_cb(k, 0)
    /// = √(P_cb(k, z)/P_cb(k, 0)) and f_cb(k, z), on the nodes of [`spectra`](Self::spectra) (two
    /// evaluations; with massless neutrinos D_cb is the scale-independent D(z)/D(0) to the emulator's
    /// accuracy).
    ///
    /// # Errors
    /// As [`spectra`](Self::spectra).
    pub fn growth_cb(&self, cosmology: &Cosmology, z: f64) -> Result<ScaleDependentGrowth> {
        let at_z = self.spectra(cosmology, z)?;
        let today = self.spectra(cosmology, self.z_range().0)?;
        let d_cb = at_z
            .p_cb
            .iter()
            .zip(&today.p_cb)
            .map(|(p, p0)| (p / p0).sqrt())
            .collect();
        Ok(ScaleDependentGrowth {
            z: at_z.z,
            k: at_z.k,
            d_cb,
            f_cb: at_z.f_cb,
        })
    }

    /// The prior coordinates of `point` (the file's box, stated prior and early dark-energy bound).
    fn coordinates(&self, point: &PriorPoint) -> Result<[f64; COORDINATES]> {
        point.coordinates(
            &self.file.prior,
            &self.file.stated,
            self.file.a_early,
            self.file.q_max,
            self.file.q_bound,
        )
    }

    /// The polynomial coefficients of the targets and of the `heads`' at coordinates `u`.
    fn point_coefficients(
        &self,
        u: &[f64; COORDINATES],
        heads: &[(&format::Head, f64)],
    ) -> ([Vec<f64>; 2], Vec<[Vec<f64>; 2]>) {
        (
            coefficients(&self.file.exponents, &self.file.targets, u, self.max_degree),
            heads
                .iter()
                .map(|(h, _)| coefficients(&h.exponents, &h.targets, u, self.max_degree))
                .collect(),
        )
    }

    /// The targets at redshift `z` of a point's coefficients ([`Self::point_coefficients`]), each
    /// head added with its weight.
    fn shape(
        &self,
        (c, head_c): &([Vec<f64>; 2], Vec<[Vec<f64>; 2]>),
        heads: &[(&format::Head, f64)],
        z: f64,
    ) -> Shape {
        let mut shape = self.at_redshift(&self.file.targets, c, z);
        for ((h, weight), hc) in heads.iter().zip(head_c) {
            shape.add(&self.at_redshift(&h.targets, hc, z), *weight);
        }
        shape
    }

    /// The file's head that corrects `of`, if it has one.
    fn head_of(&self, of: HeadOf) -> Option<&format::Head> {
        self.file.heads.iter().find(|h| h.of == of)
    }

    /// The measured worst error of a cosmology's spectra: the massless head's at Σm_ν = 0, else
    /// that of its neutrino setting.
    fn worst_of(&self, setting: Neutrinos, m_nu: f64) -> [f64; 2] {
        let massless = (m_nu == 0.0).then(|| self.worst_massless()).flatten();
        massless
            .or_else(|| self.worst(setting))
            .unwrap_or(self.file.worst)
    }

    /// The neutrino head of `cosmology`'s setting (`None`: three degenerate species, or massless).
    ///
    /// # Errors
    /// [`Error::InvalidChoice`] for a setting the file does not emulate.
    fn head(&self, cosmology: &Cosmology) -> Result<Option<&format::Head>> {
        let setting = cosmology.neutrinos;
        if setting == Neutrinos::ThreeDegenerate || cosmology.m_nu == 0.0 {
            return Ok(None);
        }
        match self.head_of(HeadOf::Setting(setting)) {
            Some(h) => Ok(Some(h)),
            None => Err(Error::InvalidChoice {
                what: format!("neutrinos: {}", setting.describe()),
                reason: format!(
                    "the linear-spectrum emulator ({}) emulates {} only: if that is what you mean, say \
                     so (CAMB num_massive_neutrinos = 3 with neutrino_hierarchy = degenerate; CLASS \
                     three equal m_ncdm, or N_ncdm = 1 with deg_ncdm = 3; the key `neutrinos = three \
                     degenerate`; the cobaya theory's option `neutrinos: three degenerate`), else give \
                     a linear spectrum (--linear FILE)",
                    self.origin,
                    self.neutrino_settings()
                        .iter()
                        .map(|s| s.describe())
                        .collect::<Vec<_>>()
                        .join("; ")
                ),
            }),
        }
    }

    /// Both targets at redshift `z` (four-node Lagrange interpolation in s = ln(1 + z)), and
    /// ∂(first target)/∂s.
    fn at_redshift(
        &self,
        targets: &[format::Target; 2],
        coefficients: &[Vec<f64>; 2],
        z: f64,
    ) -> Shape {
        let nodes: Vec<f64> = self.file.z_nodes.iter().map(|z| z.ln_1p()).collect();
        let s = z.ln_1p();
        let interval = nodes.partition_point(|&v| v <= s).saturating_sub(1);
        let first = interval.saturating_sub(1).min(nodes.len() - 4);
        let window = &nodes[first..first + 4];
        let (w, dw) = lagrange(window, s);
        let n_x = self.file.n_x;
        let mut out = [vec![0.0; n_x], vec![0.0; n_x], vec![0.0; n_x]];
        // one node's Σ_p c_p V_p, accumulated in f32 (the components are f32; |sum| ≲ 10, so the
        // rounding is ~1e-6 in ln P)
        let mut row = vec![0.0_f32; n_x];
        for (t, (target, c)) in targets.iter().zip(coefficients).enumerate() {
            let stride = target.mean.len();
            for j in 0..4 {
                let node = first + j;
                row.fill(0.0);
                for (p, &cp) in c.iter().enumerate() {
                    let cp = cp as f32;
                    let v = &target.components[p * stride + node * n_x..][..n_x];
                    for (r, &vi) in row.iter_mut().zip(v) {
                        *r += cp * vi;
                    }
                }
                let mean = &target.mean[node * n_x..(node + 1) * n_x];
                for ((o, &r), &m) in out[t].iter_mut().zip(&row).zip(mean) {
                    *o += w[j] * (m + f64::from(r));
                }
                if t == 0 {
                    for ((o, &r), &m) in out[2].iter_mut().zip(&row).zip(mean) {
                        *o += dw[j] * (m + f64::from(r));
                    }
                }
            }
        }
        let [cb, ratio, d_cb_ds] = out;
        Shape { cb, ratio, d_cb_ds }
    }
}

/// The targets at one redshift.
struct Shape {
    cb: Vec<f64>,
    ratio: Vec<f64>,
    d_cb_ds: Vec<f64>,
}

impl Shape {
    /// Adds `weight` times a head's correction of ln P_cb to ln P_cb and of ln P_m − ln P_cb to
    /// ln(P_m/P_cb) (0 for the massless head, whose two targets are equal).
    fn add(&mut self, head: &Shape, weight: f64) {
        for i in 0..self.cb.len() {
            self.cb[i] += weight * head.cb[i];
            self.ratio[i] += weight * (head.ratio[i] - head.cb[i]);
            self.d_cb_ds[i] += weight * head.d_cb_ds[i];
        }
    }
}

/// The principal-component coefficients of two targets with polynomial terms `exponents` at the unit
/// point `u` (Legendre polynomials to `max_degree`).
fn coefficients(
    exponents: &[[u8; COORDINATES]],
    targets: &[format::Target; 2],
    u: &[f64; COORDINATES],
    max_degree: usize,
) -> [Vec<f64>; 2] {
    let legendre: Vec<Vec<f64>> = u.iter().map(|&x| legendre(x, max_degree)).collect();
    let features: Vec<f64> = exponents
        .iter()
        .map(|e| {
            e.iter()
                .enumerate()
                .map(|(d, &n)| legendre[d][usize::from(n)])
                .product()
        })
        .collect();
    [0, 1].map(|t| {
        let t = &targets[t];
        let mut c = vec![0.0; t.n_pc];
        for (row, f) in t.coefficients.chunks_exact(t.n_pc).zip(&features) {
            for (cj, r) in c.iter_mut().zip(row) {
                *cj += f * r;
            }
        }
        c
    })
}

/// Legendre polynomials P_0..P_n at x.
fn legendre(x: f64, n: usize) -> Vec<f64> {
    let mut p = vec![1.0, x];
    for m in 1..n {
        let m_f = m as f64;
        p.push(((2.0 * m_f + 1.0) * x * p[m] - m_f * p[m - 1]) / (m_f + 1.0));
    }
    p.truncate(n + 1);
    p
}

/// Lagrange weights of four nodes at s, and of the derivative.
fn lagrange(nodes: &[f64], s: f64) -> ([f64; 4], [f64; 4]) {
    let mut w = [0.0; 4];
    let mut dw = [0.0; 4];
    for j in 0..4 {
        let others: Vec<usize> = (0..4).filter(|&m| m != j).collect();
        let denominator: f64 = others.iter().map(|&m| nodes[j] - nodes[m]).product();
        w[j] = others.iter().map(|&m| s - nodes[m]).product::<f64>() / denominator;
        dw[j] = others
            .iter()
            .map(|&skip| {
                others
                    .iter()
                    .filter(|&&m| m != skip)
                    .map(|&m| s - nodes[m])
                    .product::<f64>()
            })
            .sum::<f64>()
            / denominator;
    }
    (w, dw)
}

/// σ8 from P on k uniform in ln k with spacing `step`: σ² = (1/2π²) ∫ k³ P W²(8k) d ln k by the
/// trapezoidal rule (the integrand vanishes at both ends of the emulator's range).
fn sigma8(k: &[f64], step: f64, p: impl Fn(usize) -> f64) -> f64 {
    let last = k.len() - 1;
    let sum: f64 = k
        .iter()
        .enumerate()
        .map(|(i, &k)| {
            let end = if i == 0 || i == last { 0.5 } else { 1.0 };
            end * k.powi(3) * p(i) * top_hat(8.0 * k).powi(2)
        })
        .sum();
    (sum * step / (2.0 * PI * PI)).sqrt()
}

#[cfg(test)]
mod tests;
