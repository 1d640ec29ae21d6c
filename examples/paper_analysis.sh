#!/usr/bin/env bash
# The analysis of Gil-Marín et al. (2012) on the embedded default cosmology at z = 0, 0.5, 1, 1.5: every
# figure of the paper, drawn by `pt-spectra plot` from the tables the other subcommands write, and the
# halo signal-to-noise table. Writes tables/ and figures/ under OUT (examples/README.md lists them).
#
#   examples/paper_analysis.sh [OUT]        (default OUT = target/paper-analysis; 5-10 minutes on 2 cores)
#
# There are no N-body measurements here. Where the paper shows simulations the script makes stand-ins,
# and says so in the file names (mock_*, synthetic):
# - dark matter: P(k) of 2L-SPT and multipoles of TNS + 2L-RPT-N1 with Lorentzian FoG (sigma0 = 4
#   Mpc/h), with 1% errors;
# - haloes (M > 1e14 M_sun/h): synthetic P_mm (2L-RPT-N2), P_mh = b P_mm and P_hh = b^2 P_mm + P_eps
#   with b(k) = b0 (1 + 1.5 k^2) and P_eps = r/n_h (1 - 0.2 k), b0 and the sub-Poissonian r of the
#   paper's kind (its bias_noise figure), n_h of its table_haloes, 1% errors; `halo` measures b and
#   P_eps back from them, and the halo multipoles are TNS + 2L-RPT-N2 with that b(k).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-target/paper-analysis}"
T="$OUT/tables" F="$OUT/figures"
mkdir -p "$T" "$F"
cargo build --release -q -p pt-spectra
B=target/release/pt-spectra
GRID=(--k-min 0.01 --k-max 0.3 --nk 30)
# Halo number densities (table_haloes), bias amplitudes and P_eps/P_Poisson (bias_noise) by redshift.
declare -A NH=([0]=1.79e-5 [0.5]=7.02e-6 [1]=1.66e-6 [1.5]=2.33e-7)
declare -A B0=([0]=2.6 [0.5]=3.3 [1]=4.2 [1.5]=5.3)
declare -A R=([0]=0.65 [0.5]=0.9 [1]=1.0 [1.5]=1.0)
# f(z) of the cosmology, from an rsd header.
growth_rate() { $B rsd --z "$1" --nk 2 --real linear | sed -n 's/.* f = \([0-9.e-]*\),.*/\1/p' | head -1; }
# Mock multipoles from an rsd table: k P0 s0 P2 s2 P4 s4 with 1% of P0 as every error.
mock() { awk '!/^#/ { s = 0.01 * $2; print $1, $2, s, $3, s, $4, s }'; }

for z in 0 0.5 1 1.5; do
    echo "== z = $z"
    # FigAz0, FigAz15 left: every model over the no-wiggle spectrum, with mock "N-body" data.
    $B real --model all --z "$z" --k-min 0.005 --k-max 0.4 --nk 60 --out "$T/models_z$z.dat"
    $B real --model 2l-spt --z "$z" --k-min 0.01 --k-max 0.25 --nk 20 \
        | awk '!/^#/ { print $1, $3, 0.01 * $3 }' > "$T/mock_pk_z$z.dat"
    $B plot models "$T/models_z$z.dat" --data "$T/mock_pk_z$z.dat" --out "$F/FigAz_models_z$z.png" \
        --title "z = $z: P_dd/P_nw of every model, and mock data/model"
    # FigAz0, FigAz15 right: N^2 of N0..N3 and the effective sigma_v^2.
    for n in 0 1 2 3; do
        $B real --model "1l-rpt-n$n" --terms --z "$z" --k-min 0.005 --k-max 0.4 --nk 60 \
            --out "$T/prop_n${n}_z$z.dat"
    done
    $B plot propagators "$T"/prop_n{0,1,2,3}_z"$z".dat --out "$F/FigAz_propagators_z$z.png" \
        --title "z = $z: N^2 of N0..N3 and -2 ln N/k^2 (line: sigma_v^2)"

    # Haloes: synthetic measured spectra, b(k) and P_eps measured back (bias_noise).
    $B real --model 2l-rpt-n2 --z "$z" --k-min 0.005 --k-max 0.4 --nk 60 | awk -v b0="${B0[$z]}" \
        -v r="${R[$z]}" -v n="${NH[$z]}" -v pre="$T/synthetic_" -v z="$z" '!/^#/ {
            b = b0 * (1 + 1.5 * $1 * $1); e = r / n * (1 - 0.2 * $1); m = $3
            print $1, m, 0.01 * m > (pre "pmm_z" z ".dat")
            print $1, b * m, 0.01 * b * m > (pre "pmh_z" z ".dat")
            print $1, b * b * m + e, 0.01 * (b * b * m + e) > (pre "phh_z" z ".dat") }'
    $B halo --pmm "$T/synthetic_pmm_z$z.dat" --pmh "$T/synthetic_pmh_z$z.dat" \
        --phh "$T/synthetic_phh_z$z.dat" --columns 1,2,3 --number-density "${NH[$z]}" \
        --out "$T/halo_z$z.dat"
    # S2N, table_noise, Taruya_terms: the real-space S/N and the parts of the TNS + 2L-RPT-N2 monopole.
    $B rsd --rsd tns --real 2l-rpt-n2 --terms --no-wiggle --bias-file "$T/halo_z$z.dat" \
        --noise-file "$T/halo_z$z.dat" --z "$z" "${GRID[@]}" --out "$T/rsd_halo_z$z.dat"
done

fz=() # f(z) for the truth lines
for z in 0 0.5 1 1.5; do fz+=("$(printf "%.6f" "$(growth_rate "$z")")"); done
declare -A FZ=([0]=${fz[0]} [0.5]=${fz[1]} [1]=${fz[2]} [1.5]=${fz[3]})

$B plot bias-noise "$T"/halo_z{0,0.5,1,1.5}.dat --labels "z = 0,z = 0.5,z = 1,z = 1.5" \
    --out "$F/bias_noise.png" --title "Synthetic haloes, M > 1e14 M_sun/h: b(k) and P_eps/P_Poisson"
$B plot sn "$T"/rsd_halo_z{0,0.5,1,1.5}.dat --out "$F/S2N.png"
{
    echo "# z: k [h/Mpc] where SN = P_hh/P_eps (real space) falls to 1, 0.5, 0.1 (the paper's table_noise)"
    for z in 0 0.5 1 1.5; do
        line=$(grep '^# signal-to-noise' "$T/rsd_halo_z$z.dat")
        echo "z = $z (b0 = ${B0[$z]}, n_h = ${NH[$z]}): ${line#*falls to }"
    done
} > "$T/table_noise.txt"
for z in 0 0.5; do
    $B plot tns-terms "$T/rsd_halo_z$z.dat" --out "$F/Taruya_terms_z$z.png"
done

# Dark matter in redshift space at z = 0 and 1: mock multipoles, then the fits of the paper.
for z in 0 1; do
    f=${FZ[$z]}
    $B rsd --rsd tns --real 2l-rpt-n1 --fog lorentzian --sigma0 4 --z "$z" "${GRID[@]}" \
        | mock > "$T/mock_dm_z$z.dat"
    models=()
    for real in 1l-spt 2l-rpt-n1; do
        for m in kaiser scoccimarro tns; do
            # multipoles_dark_matter: f fixed, sigma0 fitted to l = 0, 2, 4 up to k_max = 0.2.
            $B fit --data "$T/mock_dm_z$z.dat" --rsd "$m" --real "$real" --free sigma0 --ells 0,2,4 \
                --z "$z" --k-max 0.2 --model-out "$T/model_dm_${m}_${real}_z$z.dat" \
                --out "$T/fit_dm_sigma0_${m}_${real}_all_z$z.dat"
            models+=("$T/model_dm_${m}_${real}_z$z.dat")
            for l in 0 2 4; do
                # sigma_0_multipoles: sigma0 alone; f_dm: f and sigma0 (errors from Delta chi2 = 2.3).
                $B fit --data "$T/mock_dm_z$z.dat" --rsd "$m" --real "$real" --free sigma0 --ells "$l" \
                    --z "$z" --k-max 0.05:0.25:0.02 --out "$T/fit_dm_sigma0_${m}_${real}_l${l}_z$z.dat"
                $B fit --data "$T/mock_dm_z$z.dat" --rsd "$m" --real "$real" --free f,sigma0 --ells "$l" \
                    --z "$z" --k-max 0.05:0.25:0.02 --out "$T/fit_dm_f_${m}_${real}_l${l}_z$z.dat"
            done
        done
    done
    $B plot multipoles "${models[@]}" --out "$F/multipoles_dark_matter_z$z.png" \
        --title "z = $z: dark-matter multipoles (f fixed, sigma0 fitted to k = 0.2) over the no-wiggle Kaiser"
    for l in 0 2 4; do
        $B plot fit "$T"/fit_dm_sigma0_*_l"${l}"_z"$z".dat --out "$F/sigma_0_multipoles_l${l}_z$z.png" \
            --title "z = $z, l = $l: sigma0 (f fixed) and its theory values"
        $B plot fit "$T"/fit_dm_f_*_l"${l}"_z"$z".dat --truth "$f" --bands 1,2 \
            --out "$F/f_dm_l${l}_z$z.png" --title "z = $z, l = $l: f and sigma0 (truth f = $f, 1% and 2%)"
    done
    # The Delta chi2 surface behind the f_dm errors: TNS + 2L-RPT-N1, monopole, k_max = 0.15.
    $B fit --data "$T/mock_dm_z$z.dat" --rsd tns --real 2l-rpt-n1 --free f,sigma0 --ells 0 --z "$z" \
        --k-max 0.15 --contour f,sigma0 --contour-out "$T/contour_dm_z$z.dat" --out /dev/null
    $B plot contour "$T/contour_dm_z$z.dat" --out "$F/contour_f_sigma0_z$z.png"
done

# Haloes in redshift space at z = 0 and 0.5: no FoG, b(k) measured by `halo`.
for z in 0 0.5; do
    f=${FZ[$z]}
    H=(--bias-file "$T/halo_z$z.dat" --noise-file "$T/halo_z$z.dat" --z "$z")
    # Mock halo multipoles (noise subtracted, as the paper's P^s_hh), errors 1% of P0 + P_eps.
    $B rsd --rsd tns --real 2l-rpt-n2 "${H[@]}" "${GRID[@]}" \
        | awk '!/^#/ { s = 0.01 * ($2 + $5); print $1, $2, s, $3, s, $4, s }' > "$T/mock_halo_z$z.dat"
    # multipoles_haloes: no free parameter; Scoccimarro and TNS with each real-space model.
    halo_models=()
    for real in linear 1l-spt 2l-spt 2l-rpt-n1 2l-rpt-n2; do
        for m in scoccimarro tns; do
            $B rsd --rsd "$m" --real "$real" --no-wiggle --ells 0,2 "${H[@]}" "${GRID[@]}" \
                --out "$T/rsd_halo_${m}_${real}_z$z.dat"
            halo_models+=("$T/rsd_halo_${m}_${real}_z$z.dat")
        done
    done
    $B plot multipoles "${halo_models[@]}" --data "$T/mock_halo_z$z.dat" --bands 2 \
        --out "$F/multipoles_haloes_z$z.png" --title "z = $z: halo multipoles over the no-wiggle Kaiser"
    # refind_beta_haloes: f from the monopole with A_b = 1 known (Delta chi2 = 1), 5% bands.
    for real in 1l-spt 2l-spt 2l-rpt-n1 2l-rpt-n2; do
        for m in scoccimarro tns; do
            $B fit --data "$T/mock_halo_z$z.dat" --rsd "$m" --real "$real" --fog none --free f --ells 0 \
                --bias-file "$T/halo_z$z.dat" --z "$z" --k-max 0.05:0.25:0.02 \
                --out "$T/fit_halo_f_${m}_${real}_z$z.dat"
        done
    done
    $B plot fit "$T"/fit_halo_f_*_z"$z".dat --truth "$f" --bands 5 --out "$F/refind_beta_haloes_z$z.png" \
        --title "z = $z: f from the halo monopole, A_b = 1 known (truth f = $f, 5%)"
    # refind_f_haloes: f and A_b free (Delta chi2 = 2.3), with the f-A_b surface at k_max = 0.15.
    for real in 2l-spt 2l-rpt-n2; do
        $B fit --data "$T/mock_halo_z$z.dat" --rsd tns --real "$real" --fog none --free f,ab --ells 0 \
            --bias-file "$T/halo_z$z.dat" --z "$z" --k-max 0.05:0.25:0.02 \
            --contour f,ab --contour-out "$T/contour_halo_${real}_z$z.dat" \
            --out "$T/fit_halo_fab_${real}_z$z.dat"
    done
    $B plot fit "$T"/fit_halo_fab_*_z"$z".dat --truth "$f" --bands 5 --out "$F/refind_f_haloes_z$z.png" \
        --title "z = $z: f and A_b from the halo monopole (truth f = $f, A_b = 1)"
    $B plot contour "$T/contour_halo_2l-rpt-n2_z$z.dat" --k-max 0.15 \
        --out "$F/contour_f_ab_z$z.png"
done
echo "tables in $T, figures in $F"
