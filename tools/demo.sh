#!/usr/bin/env bash
# Set up (packages, build) and run the demo: examples/pour on 2 MPI ranks,
# then plot its energies. Output goes to out/pour/.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
mkdir -p out/pour
cd out/pour
mpirun --allow-run-as-root --oversubscribe -np 2 ../../build/granary \
  -in ../../examples/pour/in.pour -log log.pour "$@"
/usr/bin/python3 ../../tools/plot_thermo.py log.pour --out energies.png --log-y \
  --columns KinEng c_rke v_zmax
echo "Demo output in out/pour: log.pour, energies.png, and pour_.pvd (open it in ParaView)"
