#!/usr/bin/env bash
# The analysis of Gil-Marín et al. (2012) on the embedded default cosmology at z = 0, 0.5, 1, 1.5:
# real-space models over the no-wiggle spectrum, the RPT propagators, redshift-space multipoles, fits of f
# and sigma0 versus k_max, and the halo signal-to-noise table. Writes tables/ and figures/ under OUT.
#
#   examples/paper_analysis.sh [OUT]        (default OUT = target/paper-analysis; about two minutes)
#
# There are no N-body measurements here: the "data" are mock multipoles made with TNS + 2L-RPT-N1 and
# Lorentzian FoG (sigma0 = 4 Mpc/h) with 1% errors, which the fits then analyse with other models.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-target/paper-analysis}"
mkdir -p "$OUT/tables" "$OUT/figures"
cargo build --release -q -p pt-spectra
B=target/release/pt-spectra
GRID=(--k-min 0.01 --k-max 0.3 --nk 40)
# Halo number densities for M > 1e14 M_sun/h (the paper's table_haloes) and a typical bias.
declare -A NH=([0]=1.79e-5 [0.5]=7.02e-6 [1]=1.66e-6 [1.5]=2.33e-7)
declare -A BH=([0]=2.6 [0.5]=3.3 [1]=4.2 [1.5]=5.3)
echo "# z: k where P0_hh/P_eps falls to 1, 0.5, 0.1 (Poisson noise, constant bias; the paper's table_noise)" \
    > "$OUT/tables/table_noise.txt"
for z in 0 0.5 1 1.5; do
    echo "== z = $z"
    T="$OUT/tables" F="$OUT/figures"
    # Real space: every model over the no-wiggle spectrum.
    $B real --model all --z "$z" --k-min 0.005 --k-max 0.4 --nk 60 --out "$T/models_z$z.dat"
    $B plot models "$T/models_z$z.dat" --reference 2l-rpt-n2 --out "$F/models_z$z.png" \
        --title "z = $z: P_dd / P_nowiggle of every model (ratio to 2L-RPT-N2)"
    # Propagators N0..N3 and the effective sigma_v^2.
    for n in 0 1 2 3; do
        $B real --model "1l-rpt-n$n" --terms --z "$z" --k-min 0.005 --k-max 0.4 --nk 60 --out "$T/prop_n${n}_z$z.dat"
    done
    $B plot propagators "$T"/prop_n{0,1,2,3}_z"$z".dat --out "$F/propagators_z$z.png" \
        --title "z = $z: N^2 and the effective sigma_v^2 of N0, N1, N2, N3"
    # Mock multipoles and the RSD models.
    $B rsd --rsd tns --real 2l-rpt-n1 --fog lorentzian --sigma0 4 --z "$z" "${GRID[@]}" \
        | awk '!/^#/ { s = 0.01 * $2; print $1, $2, s, $3, s, $4, s }' > "$T/mock_z$z.dat"
    for m in kaiser scoccimarro tns; do
        $B rsd --rsd "$m" --real 1l-spt --fog lorentzian --sigma0 4 --z "$z" "${GRID[@]}" --out "$T/rsd_${m}_z$z.dat"
    done
    $B plot multipoles "$T"/rsd_{kaiser,scoccimarro,tns}_z"$z".dat --data "$T/mock_z$z.dat" \
        --out "$F/multipoles_z$z.png" --title "z = $z: Kaiser, Scoccimarro, TNS (1L-SPT) and the mock"
    # f and sigma0 versus k_max, monopole and quadrupole separately, as the paper does.
    fz=$($B rsd --z "$z" --nk 2 --real linear | sed -n 's/.* f = \([0-9.e-]*\),.*/\1/p' | head -1)
    fz=$(printf "%.6f" "$fz")
    for l in 0 2; do
        for m in scoccimarro tns; do
            $B fit --data "$T/mock_z$z.dat" --rsd "$m" --real 1l-spt --free f,sigma0 --ells "$l" \
                --z "$z" --k-max 0.05:0.25:0.01 --out "$T/fit_${m}_l${l}_z$z.dat"
        done
        $B plot fit "$T"/fit_{scoccimarro,tns}_l"$l"_z"$z".dat --truth "$fz" --out "$F/fit_l${l}_z$z.png" \
            --title "z = $z, l = $l: f and sigma0 versus k_max (truth f = $fz, 1% and 2% bands)"
    done
    # Haloes: signal-to-noise crossings.
    line=$($B rsd --real 1l-spt --rsd kaiser --bias "${BH[$z]}" --number-density "${NH[$z]}" --z "$z" \
        --k-min 0.005 --k-max 0.5 --nk 200 | grep 'signal-to-noise')
    echo "z = $z (b = ${BH[$z]}, n_h = ${NH[$z]}): ${line#*falls to }" >> "$OUT/tables/table_noise.txt"
done
echo "tables in $OUT/tables, figures in $OUT/figures"
