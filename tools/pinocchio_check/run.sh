#!/usr/bin/env bash
# Cross-check nocdyn's generated code against Pinocchio on the URDFs of example-robot-data.
# Needs network access for pip. Usage: bash tools/pinocchio_check/run.sh
set -euo pipefail
cd "$(dirname "$0")"
python3 -m pip install --quiet pin example-robot-data
D=$(python3 -c "import site; print(site.getsitepackages()[0])")/cmeel.prefix/share/example-robot-data/robots
mkdir -p urdf data
cp "$D/ur_description/urdf/ur5_robot.urdf" urdf/ur5.urdf
cp "$D/ur_description/urdf/ur10_robot.urdf" urdf/ur10.urdf
cp "$D/panda_description/urdf/panda.urdf" urdf/panda.urdf
cp "$D/z1_description/urdf/z1.urdf" urdf/z1.urdf
cp "$D/kinova_description/robots/kinova.urdf" urdf/kinova.urdf
cp "$D/xarm_description/urdf/xarm7.urdf" urdf/xarm7.urdf
cp "$D/talos_data/robots/talos_left_arm.urdf" urdf/talos_left_arm.urdf
cp "$D/baxter_description/urdf/baxter.urdf" urdf/baxter.urdf
cp ../../mechanisms/specs/iiwa14.urdf urdf/iiwa14.urdf
cp "$D/pr2_description/urdf/pr2.urdf" urdf/pr2.urdf
cp "$D/icub_description/robots/icub.urdf" urdf/icub.urdf
cp "$D/tiago_description/robots/tiago.urdf" urdf/tiago.urdf
cp "$D/anymal_b_simple_description/robots/anymal.urdf" urdf/anymal.urdf
cp "$D/talos_data/robots/talos_full_v2.urdf" urdf/talos_full.urdf
cp "$D/allegro_hand_description/urdf/allegro_right_hand.urdf" urdf/allegro.urdf
python3 gen.py
cargo run --release
