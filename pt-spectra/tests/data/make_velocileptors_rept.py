# Makes velocileptors_rept_planck2018_z1.0.dat, velocileptors_rept_planck2018_z0.0.dat (galaxy redshift-space
# multipoles) and velocileptors_rept_components_planck2018_z1.0.dat, ..._z0.0.dat (REPT's internal term
# tables and IR quantities): reference tables from velocileptors' REPT, the 1-loop Eulerian redshift-space
# model of biased tracers with IR resummation (module velocileptors.EPT.ept_fullresum_fftw, class REPT).
# This script only calls velocileptors; it does not reimplement it.
#
# Run from this folder:  python3 make_velocileptors_rept.py            (writes the 4 files, runs the checks)
#                        python3 make_velocileptors_rept.py --no-checks (skips the convergence checks)
# Made with velocileptors 3.1 (PyPI wheel velocileptors-3.1-py3-none-any.whl, `pip install velocileptors==3.1`);
# the files EPT/ept_fullresum_fftw.py, EPT/ept_fftw.py, Utils/{qfuncfft,loginterp,
# spherical_bessel_transform_fftw}.py of that wheel are byte-identical to github sfschen/velocileptors at
# commit 02a06746dcc7ca7ba854118e7f31087dd1d9e509 ("Update version.", 2026-04-23). numpy 2.4.6, scipy 1.17.1,
# pyfftw 0.15.1, Python 3.11.7. Reruns agree with the committed files to ~1e-9 of P0, not bitwise (FFTW_MEASURE plans).
#
# Inputs: linear_pk_planck2018_z1.0.dat (f = 0.873875) and linear_pk_planck2018_z0.0.dat (f = 0.522018),
# CAMB 2.0.5 Planck 2018, 1200 log-spaced k in [1e-4, 50] h/Mpc, passed to REPT unchanged.
#
# Every REPT argument used (REPT.__init__(k, p, pnw=None, *args, rbao=110, kmin=1e-2, kmax=0.5, nk=100,
# sbao=None, **kw); **kw go to EPT -> KEVelocityMoments(beyond_gauss=True) -> KECLEFT(one_loop=True,
# shear=True, third_order [forced True by REPT], cutoff=20, jn=5, N=4000, threads=1, extrap_min=-4,
# extrap_max=3, import_wisdom=False)):
#   rbao = 110 (default), sbao = None (default: Sigma^2 computed by REPT), beyond_gauss = True (default),
#   one_loop = True (default), shear = True (default), jn = 5 (default), threads = 1 (default),
#   import_wisdom = False (default);
#   N = 8000, extrap_min = -6, extrap_max = 2, cutoff = 100   (NOT the defaults N=4000, -4, 3, 20: the defaults
#       leave the matter 1-loop term 3e-3 high at k = 0.3 and the b2^2, b2 bs, bs^2 tables 1e-3 ... 9e-3 low against
#       FAST-PT's brute-force-validated integrals; these settings, the range used in velocileptors' own
#       "EPT Examples" notebook with twice finer sampling, agree to <= 1e-4 (matter) and <= 5e-4 (bias tables)
#       for k <= 0.3. The checks below quantify the difference to the defaults.)
#   kmin, kmax, nk: REPT's output grid kv = logspace(log10 kmin, log10 kmax, nk) is chosen so that it contains
#       the 50 output k = logspace(log10 0.005, log10 0.3, 50) exactly (8 sub-steps between output points and
#       24 extra sub-steps on each side, kmin = 3.89e-3, kmax = 0.386, nk = 441). The output values are therefore
#       REPT's own values at its grid points (no interpolation by this script); the margins and the fine
#       sampling matter only for the AP variant, where REPT cubic-interpolates (scipy interp1d) P(k_obs)
#       from its own grid.
#   pnw: variant "noir" and "ap": pnw = p (the full spectrum: wiggle part exactly 0, no IR resummation);
#       variant "ir": pnw = None (REPT's default Savitzky-Golay no-wiggle spectrum, see the header).
# Multipoles: REPT.compute_redshift_space_power_multipoles(pars, f, ngauss=16, apar, aperp) (bFoG = 0 default),
#   i.e. 32 Gauss-Legendre nodes on [-1, 1] (16 evaluated, mirrored). It returns P0, P2, P4; P6 and P8 are
#   computed here with the same nodes and weights from the P(k, mu) table REPT stores (REPT.pknutable).
#   pars = (b1, b2, bs, b3, alpha0, alpha2, alpha4, alpha6, sn, sn2, sn4):
#   set A: 1.8, 0.5, -0.3, 0.1, 10, -5, 3, 1, 1000, 500, 100
#   set B: 2.3, -0.8, 0.4, -0.2, -20, 12, -4, 0, 3000, -1000, 0
#   variants: noir (pnw = p), ir (pnw = None), ap (pnw = p, apar = 1.03, aperp = 0.98), real (set A, f = 0,
#   P0 only, literal set A: the alpha2.. and sn2.. terms still enter P0 through <mu^n>), real_iso (set A with
#   alpha2 = alpha4 = alpha6 = sn2 = sn4 = 0, f = 0: the real-space galaxy spectrum proper).
import sys, time, platform
import numpy as np, scipy, pyfftw
from scipy.special import spherical_jn
import velocileptors
from velocileptors.EPT.ept_fullresum_fftw import REPT

F_GROWTH = {"z1.0": 0.873875, "z0.0": 0.522018}
SET_A = [1.8, 0.5, -0.3, 0.1, 10.0, -5.0, 3.0, 1.0, 1000.0, 500.0, 100.0]
SET_B = [2.3, -0.8, 0.4, -0.2, -20.0, 12.0, -4.0, 0.0, 3000.0, -1000.0, 0.0]
PAR_NAMES = "b1 b2 bs b3 alpha0 alpha2 alpha4 alpha6 sn sn2 sn4".split()
APAR, APERP = 1.03, 0.98
NGAUSS = 16
NUM = dict(N=8000, extrap_min=-6, extrap_max=2, cutoff=100, jn=5, threads=1)   # rbao, sbao, beyond_gauss: defaults
DEFAULTS = dict()                                                             # velocileptors' own defaults (checks)

KLO, KHI, NOUT, SUB, MARGIN = 0.005, 0.3, 50, 8, 24
KOUT = np.logspace(np.log10(KLO), np.log10(KHI), NOUT)


def grid(sub=SUB, margin=MARGIN):
    d = np.log10(KHI / KLO) / (NOUT - 1) / sub
    kmin, kmax = 10 ** (np.log10(KLO) - margin * d), 10 ** (np.log10(KHI) + margin * d)
    nk = (NOUT - 1) * sub + 1 + 2 * margin
    idx = margin + sub * np.arange(NOUT)
    return kmin, kmax, nk, idx


def multipoles(r, pars, f, ngauss=NGAUSS, apar=1.0, aperp=1.0):
    """P0..P8 on REPT's grid: P0, P2, P4 as returned by REPT; P6, P8 from REPT.pknutable with REPT's nodes."""
    kv, p0, p2, p4 = r.compute_redshift_space_power_multipoles(pars, f, ngauss=ngauss, apar=apar, aperp=aperp)
    nus, ws = np.polynomial.legendre.leggauss(2 * ngauss)          # the nodes/weights REPT uses
    out = []
    for ell in (0, 2, 4, 6, 8):
        L = np.polynomial.legendre.Legendre([0] * ell + [1])(nus)
        out.append((2 * ell + 1) / 2 * np.sum((ws * L)[:, None] * r.pknutable, axis=0))
    for a, b in zip(out[:3], (p0, p2, p4)):
        assert np.allclose(a, b, rtol=1e-12, atol=1e-9)
    return np.array(out)


def read(path):
    hdr = [l.rstrip("\n") for l in open(path) if l.startswith("#")]
    k, p = np.loadtxt(path, unpack=True)
    return hdr, k, p


def build(k, p, pnw, kw, sub=SUB, margin=MARGIN):
    kmin, kmax, nk, idx = grid(sub, margin)
    r = REPT(k, p, pnw=pnw, kmin=kmin, kmax=kmax, nk=nk, **kw)
    assert np.max(np.abs(r.kv[idx] / KOUT - 1)) < 1e-12
    return r, idx


def sigma_checks(r, rbao=110.0):
    """Independent quadrature of the IR damping scale REPT uses, on REPT's own no-wiggle spectrum on kint."""
    kk, pn = r.ept_nw.kint, r.ept_nw.pint
    lnk = np.log(kk)
    x = kk * rbao
    j0, j2 = spherical_jn(0, x), spherical_jn(2, x)
    s_rept = np.trapezoid(kk * pn * (1 - j0), lnk) / (3 * np.pi**2)                # = X(r)+Y(r)/3
    sig2_std = np.trapezoid(kk * pn * (1 - j0 + 2 * j2), lnk) / (6 * np.pi**2)        # NOT used by REPT
    dsig2_std = np.trapezoid(kk * pn * j2, lnk) / (2 * np.pi**2)                      # NOT used by REPT
    m = kk < 0.2
    sig2_std_ks = np.trapezoid((kk * pn * (1 - j0 + 2 * j2))[m], lnk[m]) / (6 * np.pi**2)
    dsig2_std_ks = np.trapezoid((kk * pn * j2)[m], lnk[m]) / (2 * np.pi**2)
    return s_rept, sig2_std, dsig2_std, sig2_std_ks, dsig2_std_ks


def main(do_checks=True):
    ver = (f"velocileptors {velocileptors.__version__} (PyPI wheel; == github sfschen/velocileptors 02a06746dcc7), "
           f"numpy {np.__version__}, scipy {scipy.__version__}, pyfftw {pyfftw.__version__}, Python {platform.python_version()}")
    kmin, kmax, nk, idx = grid()
    for tag in ("z1.0", "z0.0"):
        f = F_GROWTH[tag]
        inp = f"linear_pk_planck2018_{tag}.dat"
        ihdr, k, p = read(inp)
        notes = []

        r_noir, _ = build(k, p, p, NUM)            # (also warms up FFTW planning / imports before the timing below)
        t0 = time.perf_counter()
        r_ir, _ = build(k, p, None, NUM)
        t_build = time.perf_counter() - t0
        t0 = time.perf_counter()
        _ = r_ir.compute_redshift_space_power_multipoles(SET_A, f, ngauss=NGAUSS)
        t_mult = time.perf_counter() - t0

        cols, names = [KOUT], ["k"]
        res = {}
        for sname, pars in (("A", SET_A), ("B", SET_B)):
            for vname, r, ap in (("noir", r_noir, (1.0, 1.0)), ("ir", r_ir, (1.0, 1.0)), ("ap", r_noir, (APAR, APERP))):
                m = multipoles(r, pars, f, apar=ap[0], aperp=ap[1])[:, idx]
                res[(sname, vname)] = m
                for ell, row in zip((0, 2, 4, 6, 8), m):
                    cols.append(row); names.append(f"{sname}_{vname}_P{ell}")
        m_real = multipoles(r_noir, SET_A, 0.0)[:, idx]
        iso = list(SET_A); iso[5] = iso[6] = iso[7] = iso[9] = iso[10] = 0.0
        m_iso = multipoles(r_noir, iso, 0.0)[:, idx]
        cols += [m_real[0], m_iso[0]]; names += ["A_real_P0", "A_real_iso_P0"]
        assert np.all(np.abs(m_iso[1:]) < 1e-8 * np.abs(m_iso[0]))

        # ---- validation: Kaiser + shot at the first k (noir)
        plin0 = r_noir.plin[idx][0]
        for sname, pars in (("A", SET_A), ("B", SET_B)):
            b1, sn = pars[0], pars[8]
            kai = (b1**2 + 2 * b1 * f / 3 + f**2 / 5) * plin0 + sn
            notes.append(f"check Kaiser: k={KOUT[0]:.4g} set {sname} noir P0 / [(b1^2+2b1f/3+f^2/5)P_lin+sn] - 1 = "
                         f"{res[(sname, 'noir')][0, 0] / kai - 1:+.3e} (P_lin={plin0:.6e})")

        # ---- IR quantities
        s_ind, sig2_std, dsig2_std, sig2_std_ks, dsig2_std_ks = sigma_checks(r_ir)
        nfilt = int(np.ceil(np.log(7) / np.log(r_ir.ept.kint[-1] / r_ir.ept.kint[-2])) // 2 * 2 + 1)
        irlines = [
            f"IR (variant ir): REPT.sigma_squared_bao = X_lin(r)+Y_lin(r)/3 at r = rbao = 110 Mpc/h from the no-wiggle EPT = {r_ir.sigma_squared_bao:.8e} (Mpc/h)^2;",
            f"  damping factor exp(-0.5 k^2 sigma_squared_bao (1 + f(2+f) mu^2)), i.e. Sigma^2 := 0.5*sigma_squared_bao = {0.5 * r_ir.sigma_squared_bao:.8e} (Mpc/h)^2; REPT has NO delta Sigma^2 term.",
            f"  independent trapezoid of (1/3pi^2) int dk P_nw(k) [1 - j0(k r)] on REPT's kint/P_nw = {s_ind:.8e} (rel diff {s_ind / r_ir.sigma_squared_bao - 1:+.2e}).",
            f"  for comparison only (NOT used by REPT), the usual Sigma^2 = (1/6pi^2) int P_nw [1 - j0 + 2 j2](k r) dk = {sig2_std:.6e}, delta Sigma^2 = (1/2pi^2) int P_nw j2(k r) dk = {dsig2_std:.6e};",
            f"  with k < k_s = 0.2 h/Mpc: Sigma^2 = {sig2_std_ks:.6e}, delta Sigma^2 = {dsig2_std_ks:.6e} (r = 110 Mpc/h, same P_nw).",
            f"  P_nw (variant ir) = scipy.signal.savgol_filter(REPT.ept.pint, window={nfilt}, polyorder=4) on kint = logspace({NUM['extrap_min']},{NUM['extrap_max']},{NUM['N']}),",
            f"  pint = loginterp(k,p)(kint)*exp(-(kint/cutoff)^2); REPT then passes (kint, P_nw) to a second EPT (which applies the cutoff again).",
        ]
        sel = [np.argmin(np.abs(KOUT - x)) for x in (0.01, 0.03, 0.05, 0.1, 0.15, 0.2, 0.3)]
        irlines.append("  P_nw/P_lin at a few k: " + ", ".join(
            f"k={KOUT[i]:.4g}: {r_ir.plin_nw[idx][i] / r_ir.plin[idx][i]:.6f}" for i in sel))

        # ---- convergence checks
        chk = []
        if do_checks:
            r_n2, _ = build(k, p, p, dict(NUM, N=2 * NUM["N"]))
            r_d, _ = build(k, p, p, DEFAULTS)
            r_ir2, _ = build(k, p, None, dict(NUM, N=2 * NUM["N"]))
            r_fine, idx_f = build(k, p, p, NUM, sub=2 * SUB, margin=2 * MARGIN)
            for sname, pars in (("A", SET_A), ("B", SET_B)):
                a = res[(sname, "noir")]; b = multipoles(r_n2, pars, f)[:, idx]; c = multipoles(r_d, pars, f)[:, idx]
                g = multipoles(r_noir, pars, f, ngauss=2 * NGAUSS)[:, idx]
                ai = res[(sname, "ir")]; bi = multipoles(r_ir2, pars, f)[:, idx]
                gi = multipoles(r_ir, pars, f, ngauss=2 * NGAUSS)[:, idx]
                aa = res[(sname, "ap")]; ga = multipoles(r_noir, pars, f, ngauss=2 * NGAUSS, apar=APAR, aperp=APERP)[:, idx]
                fa = multipoles(r_fine, pars, f, apar=APAR, aperp=APERP)[:, idx_f]
                rel = lambda x, y: np.max(np.abs(x[0] - y[0]) / np.abs(y[0]))
                rel2 = lambda x, y: np.max(np.abs(x[1] - y[1]) / np.abs(y[0]))
                chk.append(f"check set {sname}: max|dP0|/P0 (and max|dP2|/P0), k in [0.005,0.3]: noir N=8000 vs N=16000 {rel(a, b):.1e} ({rel2(a, b):.1e}); "
                           f"ir N=8000 vs 16000 {rel(ai, bi):.1e} ({rel2(ai, bi):.1e}); noir ngauss 16 vs 32 {rel(a, g):.1e}, ir {rel(ai, gi):.1e}, ap {rel(aa, ga):.1e}; "
                           f"ap REPT grid sub-step halved {rel(aa, fa):.1e} ({rel2(aa, fa):.1e}); "
                           f"velocileptors DEFAULT numerics (N=4000, extrap -4..3, cutoff 20) differ from these by {rel(a, c):.1e} ({rel2(a, c):.1e})")

        # ---- write the multipole file
        out = f"velocileptors_rept_planck2018_{tag}.dat"
        H = [f"tool: {ver}; script pt-spectra/tests/data/make_velocileptors_rept.py (REPT from velocileptors.EPT.ept_fullresum_fftw)",
             f"input: pt-spectra/tests/data/{inp} (all rows, unchanged); f = {f}"] + ["input header: " + h[1:].strip() for h in ihdr] + [
             f"REPT(k, p, pnw=<p | None>, rbao=110, sbao=None, kmin={kmin:.10e}, kmax={kmax:.10e}, nk={nk}, N={NUM['N']}, extrap_min={NUM['extrap_min']}, "
             f"extrap_max={NUM['extrap_max']}, cutoff={NUM['cutoff']}, jn={NUM['jn']}, threads={NUM['threads']}, beyond_gauss=True, one_loop=True, shear=True, third_order=True, import_wisdom=False)",
             f"output k = logspace(log10 0.005, log10 0.3, 50) = REPT grid points kv[{idx[0]}::{SUB}] exactly (no interpolation by the script)",
             f"multipoles: REPT.compute_redshift_space_power_multipoles(pars, f, ngauss={NGAUSS}, apar, aperp, bFoG=0): Gauss-Legendre with 2*ngauss = {2 * NGAUSS} nodes on [-1,1]; "
             f"P6, P8 from REPT.pknutable with the same nodes/weights",
             "pars order (REPT): " + " ".join(PAR_NAMES),
             "set A: " + " ".join(f"{n}={v:g}" for n, v in zip(PAR_NAMES, SET_A)),
             "set B: " + " ".join(f"{n}={v:g}" for n, v in zip(PAR_NAMES, SET_B)),
             "variants: noir = pnw=p (wiggle part identically 0: no IR resummation, no damping); ir = pnw=None (REPT default Savitzky-Golay P_nw, rbao=110, "
             "damping exp(-0.5 k^2 sigma_squared_bao (1+f(2+f)mu^2))); "
             f"ap = noir with apar={APAR}, aperp={APERP} (k,mu observed; REPT maps k_true = k_obs sqrt(1+mu_obs^2(1/F^2-1))/aperp, mu_true = mu_obs/(F sqrt(..)), F=apar/aperp, "
             "and divides by apar*aperp^2); real = set A at f=0 (P0 includes alpha0+alpha2/3+alpha4/5+alpha6/7 and sn+sn2 k^2/3+sn4 k^4/5); "
             "real_iso = set A with alpha2=alpha4=alpha6=sn2=sn4=0 at f=0",
             "model (REPT, mu = true mu): P = [pk - f k mu^2 vk - f^2 k^2 mu^2/2 (s0 + s2 (3mu^2-1)/2) + f^3 (k mu)^3/6 (g1 mu + g3 mu^3) + f^4 (k mu)^4/24 (k0 + k2 mu^2 + k4 mu^4)]_nw "
             "+ D [same]_w - ln(D) D (b1+f mu^2)^2 P_w + (alpha0 + alpha2 mu^2 + alpha4 mu^4 + alpha6 mu^6) k^2 (P_nw + D P_w) + sn + sn2 k^2 mu^2 + sn4 k^4 mu^4, "
             "D = exp(-0.5 k^2 sigma_squared_bao (1+f(2+f)mu^2)); bias tables: see velocileptors_rept_components_planck2018_*.dat",
             "units: k [h/Mpc], P_ell [(Mpc/h)^3]; reruns reproduce the values to ~1e-9 of P0 only (pyfftw FFTW_MEASURE plans are not bitwise reproducible)",
             ] + notes + irlines + chk + [
             f"timing (this machine, 1 thread): one REPT construction (variant ir, these settings, after a warm-up construction; the first one in a process takes ~2x longer) {t_build:.2f} s; one multipole evaluation (ngauss={NGAUSS}) {t_mult:.4f} s",
             "columns: " + " ".join(f"{i + 1}:{n}" for i, n in enumerate(names))]
        np.savetxt(out, np.array(cols).T, fmt="%.10e", header="\n".join(H), comments="# ")
        print(f"wrote {out}")
        print("\n".join(notes + irlines + chk))
        print(f"timing: build {t_build:.2f} s, multipoles {t_mult:.4f} s")

        # ---- write the component file (noir tables, plus P_lin/P_nw of the ir object)
        r = r_noir
        C, N2 = [KOUT, r.plin[idx], r_ir.plin_nw[idx], r_ir.plin_w[idx]], ["k", "P_lin", "P_nw_ir", "P_w_ir"]
        for tab, lab in ((r.pktable, ["pk_b1b1", "pk_b1b2", "pk_b1bs", "pk_b2b2", "pk_b2bs", "pk_bsbs", "pk_b1b3"]),
                         (r.vktable, ["vk_b1", "vk_b1b1", "vk_b2", "vk_b1b2", "vk_bs", "vk_b1bs", "vk_b3"]),
                         (r.s0ktable, ["s0_1", "s0_b1", "s0_b1b1", "s0_b2", "s0_bs"]),
                         (r.s2ktable, ["s2_1", "s2_b1", "s2_b1b1", "s2_b2", "s2_bs"]),
                         (r.g1ktable, ["g1_1", "g1_b1"]), (r.g3ktable, ["g3_1", "g3_b1"])):
            for j, n in enumerate(lab):
                C.append(tab[idx, j + 1]); N2.append(n)
        for n, v in (("k0", r.k0), ("k2", r.k2), ("k4", r.k4)):
            C.append(v[idx]); N2.append(n)
        assert np.max(np.abs(r.pktable_w[:, 1:])) <= 1e-12 * np.max(np.abs(r.pktable[:, 1])) and np.all(r.plin_w == 0)
        out = f"velocileptors_rept_components_planck2018_{tag}.dat"
        H = [f"tool: {ver}; script pt-spectra/tests/data/make_velocileptors_rept.py",
             f"input: pt-spectra/tests/data/{inp}; f = {f} (the tables below do not depend on f); REPT settings as in velocileptors_rept_planck2018_{tag}.dat",
             "content: REPT's internal 1-loop term tables of variant noir (pnw = p; REPT.pktable, vktable, s0ktable, s2ktable, g1ktable, g3ktable, k0, k2, k4; "
             "wiggle parts identically 0) at the 50 output k (exact REPT grid points), plus P_lin = REPT.plin (loginterp of the input) and "
             "P_nw_ir = REPT.plin_nw, P_w_ir = P_lin - P_nw_ir of the default-IR object (variant ir).",
             "assembly in REPT.compute_redshift_space_power_at_mu (true k, mu):",
             "  pk = b1^2 pk_b1b1 + b1 b2 pk_b1b2 + b1 bs pk_b1bs + b2^2 pk_b2b2 + b2 bs pk_b2bs + bs^2 pk_bsbs + b1 b3 pk_b1b3",
             "  vk = b1 vk_b1 + b1^2 vk_b1b1 + b2 vk_b2 + b1 b2 vk_b1b2 + bs vk_bs + b1 bs vk_b1bs + b3 vk_b3",
             "  s0 = s0_1 + b1 s0_b1 + b1^2 s0_b1b1 + b2 s0_b2 + bs s0_bs ; s2 likewise ; g1 = g1_1 + b1 g1_b1 ; g3 likewise ; k0, k2, k4 matter only",
             "  P(k,mu) = pk - f k mu^2 vk - (1/2) f^2 k^2 mu^2 [s0 + s2 (3mu^2-1)/2] + (1/6) f^3 (k mu)^3 (g1 mu + g3 mu^3) + (1/24) f^4 (k mu)^4 (k0 + k2 mu^2 + k4 mu^4)",
             "           + (alpha0 + alpha2 mu^2 + alpha4 mu^4 + alpha6 mu^6) k^2 P_lin + sn + sn2 k^2 mu^2 + sn4 k^4 mu^4      (noir)",
             "  tree level (k -> 0): pk_b1b1 -> P_lin, vk_b1 -> -2 P_lin/k, s0_1 -> -(2/3) P_lin/k^2, s2_1 -> -(4/3) P_lin/k^2, all others 1-loop, so that P -> (b1 + f mu^2)^2 P_lin",
             "conventions (checked against tests/data/fastpt_bias_*.dat, same input): pk_b1b1 = P_lin + P22 + P13 (matter 1-loop); pk_b1b2 = Pd1d2 = 2 int F2 P P; "
             "pk_b1bs = 2 Pd1s2 = 4 int F2 S2 P P; pk_b2b2 = Pd2d2/4 = (1/2) int P P; pk_b2bs = Pd2s2 = 2 int S2 P P; pk_bsbs = Ps2s2 = 2 int S2^2 P P; "
             "pk_b1b3 = FAST-PT sig3nl = P_lin int P (4/3)[D2 S2 + 8/63]; i.e. delta_g = b1 delta + (b2/2) delta^2 + bs s^2 (s^2 = s_ij s_ij, S2 = mu^2-1/3) + b3 O3 + ...; "
             "NO k->0 constant is subtracted from pk_b2b2, pk_b2bs, pk_bsbs.",
             ] + irlines + ["units: k [h/Mpc]; pk_*, s0_*, s2_*, k0/k2/k4 ... as REPT stores them ((Mpc/h)^3 times powers of h/Mpc such that the formula above gives (Mpc/h)^3)",
             "columns: " + " ".join(f"{i + 1}:{n}" for i, n in enumerate(N2))]
        np.savetxt(out, np.array(C).T, fmt="%.10e", header="\n".join(H), comments="# ")
        print(f"wrote {out}")


if __name__ == "__main__":
    main(do_checks="--no-checks" not in sys.argv)
