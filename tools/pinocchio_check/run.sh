#!/usr/bin/env bash
# Cross-check nocdyn's generated code against Pinocchio on the URDFs of example-robot-data.
# Needs network access for pip. Usage: bash tools/pinocchio_check/run.sh
set -euo pipefail
cd "$(dirname "$0")"
# cmeel-cppad / cmeel-cppadcodegen: CppAD (with its configured cppad/configure.hpp) and
# CppADCodeGen, header-only, into the same cmeel prefix as Pinocchio, for bench_cg.cpp. Pinned to
# the releases checked here with Pinocchio 4.1.0.
python3 -m pip install --quiet pin example-robot-data cmeel-eigen cmeel-urdfdom-headers \
  cmeel-cppad==20250000.2 cmeel-cppadcodegen==2.4.3
D=$(python3 -c "import site; print(site.getsitepackages()[0])")/cmeel.prefix/share/example-robot-data/robots
mkdir -p urdf data
cp -p "$D/ur_description/urdf/ur5_robot.urdf" urdf/ur5.urdf
cp -p "$D/ur_description/urdf/ur10_robot.urdf" urdf/ur10.urdf
cp -p "$D/panda_description/urdf/panda.urdf" urdf/panda.urdf
cp -p "$D/z1_description/urdf/z1.urdf" urdf/z1.urdf
cp -p "$D/kinova_description/robots/kinova.urdf" urdf/kinova.urdf
cp -p "$D/xarm_description/urdf/xarm7.urdf" urdf/xarm7.urdf
cp -p "$D/talos_data/robots/talos_left_arm.urdf" urdf/talos_left_arm.urdf
cp -p "$D/baxter_description/urdf/baxter.urdf" urdf/baxter.urdf
cp -p ../../mechanisms/specs/iiwa14.urdf urdf/iiwa14.urdf
cp -p "$D/pr2_description/urdf/pr2.urdf" urdf/pr2.urdf
cp -p "$D/icub_description/robots/icub.urdf" urdf/icub.urdf
cp -p "$D/tiago_description/robots/tiago.urdf" urdf/tiago.urdf
cp -p "$D/anymal_b_simple_description/robots/anymal.urdf" urdf/anymal.urdf
cp -p "$D/talos_data/robots/talos_full_v2.urdf" urdf/talos_full.urdf
cp -p "$D/allegro_hand_description/urdf/allegro_right_hand.urdf" urdf/allegro.urdf
# Robots above 16 DOF leave the derivatives and the regressor out (scenes/NAME.scene.toml,
# read beside NAME.urdf by codegen::build_script).
cp -p scenes/*.scene.toml urdf/
python3 gen.py
# The generated code, built for this CPU (plain `a*b + c` stays two roundings: Rust never contracts;
# the FMA modules' `mul_add` becomes one instruction). Timings pinned to core 1 when taskset exists.
PIN=""; command -v taskset >/dev/null && PIN="taskset -c 1"
mkdir -p out
RUSTFLAGS="-C target-cpu=native" cargo build --release
$PIN ./target/release/pinocchio-check | tee out/rust.txt
# (Each C++ program is rebuilt only when its source is newer.)
# Pinocchio's own timing of the same URDFs (header-only build, -O3, the defines of its CMake
# config), to set beside the `ns:` columns above.
P=$(python3 -c "import site; print(site.getsitepackages()[0])")/cmeel.prefix
[ pinocchio_bench -nt bench.cpp ] || g++ -O3 -DNDEBUG -std=c++17 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_MPL_LIMIT_LIST_SIZE=30 \
  -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -DPINOCCHIO_WITH_URDFDOM \
  -DPINOCCHIO_URDFDOM_HEADERS_MAJOR_VERSION=3 -DPINOCCHIO_URDFDOM_HEADERS_MINOR_VERSION=0 \
  -DPINOCCHIO_URDFDOM_HEADERS_PATCH_VERSION=0 bench.cpp -I"$P/include" -I"$P/include/eigen3" \
  -I"$P/include/urdfdom_headers" -L"$P/lib" -lpinocchio_default -lpinocchio_parsers -lurdfdom_model \
  -lboost_filesystem -Wl,-rpath,"$P/lib" -o pinocchio_bench
./pinocchio_bench urdf/ur5.urdf urdf/ur10.urdf urdf/panda.urdf urdf/z1.urdf urdf/kinova.urdf \
  urdf/xarm7.urdf urdf/iiwa14.urdf urdf/talos_left_arm.urdf urdf/baxter.urdf urdf/pr2.urdf \
  urdf/icub.urdf urdf/tiago.urdf urdf/anymal.urdf urdf/talos_full.urdf urdf/allegro.urdf
# Pinocchio's code generation (CppADCodeGen) beside plain Pinocchio on the arms: bench_cg.cpp
# tapes, generates C, compiles it with gcc "$CG_FLAGS" and loads it. The program itself (and so
# its plain Pinocchio) is built with -O3 like bench.cpp: built with
# -march=native (even -mavx2, or with Eigen's alignment held at 16 bytes), the Model that
# urdf::buildModel fills with libpinocchio_parsers is corrupt (a crash in ~Model). The libraries
# go to cg_libs/ (rebuilt each run unless KEEP_CG_LIBS=1).
CG_FLAGS="-O3 -march=native"
[ pinocchio_bench_cg -nt bench_cg.cpp ] || g++ -O3 -DNDEBUG -std=c++17 -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_MPL_LIMIT_LIST_SIZE=30 \
  -DBOOST_MPL_LIMIT_VECTOR_SIZE=30 -DBOOST_FUSION_INVOKE_MAX_ARITY=12 -DPINOCCHIO_WITH_URDFDOM \
  -DPINOCCHIO_URDFDOM_HEADERS_MAJOR_VERSION=3 -DPINOCCHIO_URDFDOM_HEADERS_MINOR_VERSION=0 \
  -DPINOCCHIO_URDFDOM_HEADERS_PATCH_VERSION=0 bench_cg.cpp -I"$P/include" -I"$P/include/eigen3" \
  -I"$P/include/urdfdom_headers" -L"$P/lib" -lpinocchio_default -lpinocchio_parsers -lurdfdom_model \
  -lboost_filesystem -ldl -Wl,-rpath,"$P/lib" -o pinocchio_bench_cg
[ "${KEEP_CG_LIBS:-0}" = 1 ] || rm -rf cg_libs
$PIN ./pinocchio_bench_cg "$CG_FLAGS" cg_libs urdf/ur5.urdf urdf/ur10.urdf urdf/panda.urdf urdf/z1.urdf \
  urdf/kinova.urdf urdf/xarm7.urdf urdf/iiwa14.urdf urdf/talos_left_arm.urdf | tee out/cg.txt
python3 tables.py out/rust.txt out/cg.txt | tee out/tables.md
# The bundled Gough-Stewart's actuator forces against Pinocchio routes on its opened tree
# (README.md, "Gough–Stewart"; its own crate and program in gough_stewart/).
bash gough_stewart/run.sh
