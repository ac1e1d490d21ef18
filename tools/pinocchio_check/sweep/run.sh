#!/usr/bin/env bash
# Every URDF of example-robot-data (fixed base) against Pinocchio: inverse dynamics, mass matrix
# and forward dynamics at 30 random states each (README.md, "Every URDF of example-robot-data").
# Needs network access for pip. Usage: bash tools/pinocchio_check/sweep/run.sh
set -euo pipefail
cd "$(dirname "$0")"
python3 -m pip install --quiet pin example-robot-data
D=$(python3 -c "import site; print(site.getsitepackages()[0])")/cmeel.prefix/share/example-robot-data/robots
rm -rf urdf data && mkdir -p urdf data
for f in $(find "$D" -name '*.urdf' | sort); do
    n=$(basename "$f" .urdf)
    d=$(basename "$(dirname "$(dirname "$f")")" | sed 's/_description//')
    m=$(echo "${d}_${n}" | tr 'A-Z.-' 'a-z__')
    case "$m" in
    # No movable joint (hector, iris_simple), an empty robot (ur3.urdf), and copies of robots
    # kept (the same dynamics: *_box, *_joint_limited_robot, panda_collision); tiago_dual's
    # 101 DOF take long to build.
    *quadrotor_base | *iris_simple | ur_ur3 | *_box | *joint_limited* | *panda_collision | *tiago_dual) continue ;;
    esac
    cp -p "$f" "urdf/$m.urdf"
    printf '[scene]\nfunctions = ["inverse_dynamics", "mass_matrix", "forward_dynamics"]\nframes = []\n' >"urdf/$m.scene.toml"
done
python3 ../gen.py 30 --values-only
# Unoptimized: the modules of 30–55 DOF build in about a minute (the build script optimized).
cargo run | tee results.txt
