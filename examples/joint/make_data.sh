#!/bin/sh
# Makes the two data sets of joint_analysis.toml (noise-free ept multipoles at z = 0.5 with
# b1 = 1.8 and 2.2, b2 = -0.4, alpha0 = 8 (Mpc/h)^2, sn = 900 (Mpc/h)^3, f = 0.7; errors 1% of P0)
# and fits them jointly:
#     sh examples/joint/make_data.sh [path/to/pt-spectra]
set -e
BIN=${1:-target/release/pt-spectra}
DIR=$(dirname "$0")
for pair in low_bias:1.8 high_bias:2.2; do
    name=${pair%%:*}; b1=${pair##*:}
    "$BIN" rsd --rsd ept --z 0.5 --bias "$b1" --b2 -0.4 --alpha0 8 --sn 900 --f 0.7 \
        --k-min 0.02 --k-max 0.2 --nk 25 --precision fast |
        awk '!/^#/ { s = 0.01 * $2; print $1, $2, s, $3, s, $4, s }' > "$DIR/$name.dat"
done
"$BIN" fit --analysis "$DIR/joint_analysis.toml" --precision fast --out "$DIR/joint_fit.dat"
echo "wrote $DIR/joint_fit.dat"
