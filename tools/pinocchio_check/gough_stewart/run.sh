#!/usr/bin/env bash
# The bundled Gough-Stewart's actuator forces: generated code against Pinocchio routes on the
# opened tree (../README.md, "Gough–Stewart"). Needs Pinocchio 4.1 with CppAD and CppADCodeGen in
# its cmeel prefix (../run.sh installs them and then runs this). Usage: bash run.sh
set -euo pipefail
cd "$(dirname "$0")"
# The two specs (bundled, full-inertia variant) and the Pinocchio models of their opened trees.
python3 gen.py
# The generated modules (build.rs), built for this CPU: `mul_add` is one instruction.
RUSTFLAGS="-C target-cpu=native" cargo build --release
# Header-only Pinocchio (the model is built in code, no URDF parser library): so -march=native
# works here (see ../run.sh for the crash with libpinocchio_parsers). Rebuilt on a change only.
P=$(python3 -c "import site; print(site.getsitepackages()[0])")/cmeel.prefix
if [ ! gs_bench -nt gs_bench.cpp ] || [ ! gs_bench -nt gs_model.hpp ]; then
  g++ -O3 -march=native -DNDEBUG -std=c++17 -Wno-deprecated-declarations -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS \
    -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_FUSION_INVOKE_MAX_ARITY=12 \
    gs_bench.cpp -I"$P/include" -I"$P/include/eigen3" -ldl -o gs_bench
fi
# One run: the generated code (writes data/*.txt, the states and their forces), then Pinocchio
# (checks its forces against those first, fails above 1e-10), pinned to core 1 when taskset exists.
PIN=""; command -v taskset >/dev/null && PIN="taskset -c 1"
mkdir -p out
[ "${KEEP_CG_LIBS:-0}" = 1 ] || rm -rf cg_libs
$PIN ./target/release/gs-check | tee out/rust.txt
$PIN ./gs_bench "-O3 -march=native" cg_libs | tee out/pin.txt
