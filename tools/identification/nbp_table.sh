#!/bin/sh
# The table "NBP per bundled mechanism" of docs/identification.md: for every spec in
# mechanisms/specs/, its kind, degrees of freedom, the regressor's standard parameters and base
# parameters (the first line `codegen excite` prints, before its search; a short search whose
# outcome does not matter here), the generated module's `NBP` (checked equal), and the flops of
# `inverse_dynamics` and `regressor` (`codegen SPEC --stats`). A spec whose `[scene] functions`
# leave the regressor out is counted from a copy without that list (marked ¹).
# Run from the repository root: sh tools/identification/nbp_table.sh
set -eu
codegen=${CODEGEN:-target/debug/codegen}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
echo "| spec | kind | DOF | standard parameters | NBP | flops \`inverse_dynamics\` | flops \`regressor\` |"
echo "|---|---|---:|---:|---:|---:|---:|"
for spec in mechanisms/specs/*.toml mechanisms/specs/*.urdf; do
    "$codegen" "$spec" --stats >"$dir/code.rs" 2>"$dir/stats.txt" || true
    nbp=$(sed -n 's/^pub const NBP: usize = \([0-9]*\);$/\1/p' "$dir/code.rs")
    mark=""
    if [ -z "$nbp" ]; then
        sed '/^functions = /d' "$spec" >"$dir/$(basename "$spec")"
        "$codegen" "$dir/$(basename "$spec")" --stats >"$dir/code.rs" 2>"$dir/stats.txt" || true
        nbp=$(sed -n 's/^pub const NBP: usize = \([0-9]*\);$/\1/p' "$dir/code.rs")
        mark=" ¹"
    fi
    id=$(awk -F'|' '$2 ~ /^ inverse_dynamics $/ { gsub(/ /, "", $3); print $3 }' "$dir/stats.txt")
    reg=$(awk -F'|' '$2 ~ /^ regressor $/ { gsub(/ /, "", $3); print $3 }' "$dir/stats.txt")
    "$codegen" excite "$spec" --restarts 1 --evaluations 1 --samples 200 --search-samples 200 \
        -o "$dir/t.csv" 2>"$dir/excite.txt" || true
    line=$(sed -n 's/^excite: [^ ]* (\(.*\)): \([0-9]*\) base parameters of \([0-9]*\) standard, \([0-9]*\) .*$/\1|\4|\3|\2/p' "$dir/excite.txt")
    kind=${line%%|*}; rest=${line#*|}
    dof=${rest%%|*}; rest=${rest#*|}
    nstd=${rest%%|*}; nbp_cli=${rest#*|}
    if [ "$nbp_cli" != "$nbp" ]; then
        echo "error: $spec: NBP $nbp in the module, $nbp_cli in the tools" >&2
        exit 1
    fi
    echo "| \`$(basename "$spec")\`$mark | $kind | $dof | $nstd | $nbp | $id | $reg |"
done
