#!/bin/sh
# The table "Identification error against noise level" of docs/identification.md: the PUMA 560
# excited by `codegen excite` (seed 1, one start of 300 evaluations), its efforts from the
# spec's own model (`--with-tau`) plus Gaussian noise of standard deviation
# L * (1, 1, 1/2, 1/20, 1/20, 1/40) N·m on joints 1..6 (noise seed 2), identified by
# `codegen identify`; the reference is the spec's BASE_PARAMETERS (the `spec` column);
# z = |estimate - reference| / std per parameter.
# Run from the repository root: sh tools/identification/noise_table.sh
set -eu
codegen=${CODEGEN:-target/debug/codegen}
spec=mechanisms/specs/puma560.toml
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
echo "| noise L (N·m) | ‖π̂ − π‖ / ‖π‖ | max z | mean z² | parameters over 10 % rel. std | residual RMS j1, j6 (N·m) |"
echo "|---:|---:|---:|---:|---:|---|"
for level in 0 0.001 0.01 0.1 1; do
    noise=$(awk -v l="$level" 'BEGIN { printf "%g,%g,%g,%g,%g,%g", l, l, l/2, l/20, l/20, l/40 }')
    "$codegen" excite "$spec" --seed 1 --restarts 1 --evaluations 300 --samples 1000 \
        --with-tau --noise "$noise" --noise-seed 2 -o "$dir/d.csv" 2>/dev/null
    "$codegen" identify "$spec" "$dir/d.csv" --estimates "$dir/e.csv" >"$dir/out.txt" 2>"$dir/err.txt"
    over=$(grep -c "relative std" "$dir/err.txt" || true)
    rms=$(sed -n 's/^residual RMS per joint (N·m or N): j1 \([^,]*\),.* j6 \(.*\)$/\1, \2/p' "$dir/out.txt")
    awk -F, -v l="$level" -v over="$over" -v rms="$rms" 'NR > 1 {
        d = $4 - $3; e2 += d * d; p2 += $3 * $3
        if ($5 > 0) { z = (d < 0 ? -d : d) / $5; if (z > zmax) zmax = z; z2 += z * z }
        n++
    } END {
        if (l == 0) printf "| 0 | %.2e | – | – | %d | %s |\n", sqrt(e2 / p2), over, rms
        else printf "| %g | %.2e | %.2f | %.2f | %d | %s |\n", l, sqrt(e2 / p2), zmax, z2 / n, over, rms
    }' "$dir/e.csv"
done
