#!/bin/sh
# Writes stalk_particles.csv: the particle model's angles of stalk_particles.yaml
# at the generating values (kappa 12, chi0 0.7, e_max 100 MPa, delta 2e-4 s-1)
# every 15 min for an hour, by `phytocal simulate` on a copy of the config with
# those values as the start and a CSV of zeros, reshaped to one column per
# stalk (degrees, 12 significant digits).
# usage: sh make_stalk_particles.sh PATH/TO/phytocal   (run in this folder)
set -eu
phc=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf 't (min),a (deg),b (deg)\n' >"$tmp/zeros.csv"
for t in 0 15 30 45 60; do printf '%s,0,0\n' "$t" >>"$tmp/zeros.csv"; done
sed -e 's/^  kappa: {value: [^,]*,/  kappa: {value: 12,/' -e 's/^  chi0:  {value: [^,]*,/  chi0:  {value: 0.7,/' \
    -e 's/^  e_max: {value: [^,]*,/  e_max: {value: 100,/' -e 's/^  delta: {value: [^,]*,/  delta: {value: 2e-4,/' \
    -e "s|file: stalk_particles.csv|file: $tmp/zeros.csv|" -e 's/frames: 3/frames: 0/' stalk_particles.yaml >"$tmp/truth.yaml"
"$phc" simulate "$tmp/truth.yaml" -o "$tmp/out" --quiet
# x is in hours, series a then b, 5 rows each; angles in rad
awk -F, 'NR > 1 { m[NR - 2] = $3 } END {
    printf "t (min),a (deg),b (deg)\n";
    for (i = 0; i < 5; ++i)
        printf "%d,%.12g,%.12g\n", 15 * i, m[i] * 180 / 3.14159265358979323846, m[i + 5] * 180 / 3.14159265358979323846 }' \
    "$tmp/out/stalks_simulated.csv" >stalk_particles.csv
