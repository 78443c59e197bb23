#!/usr/bin/env bash
# The README's main job: installs the Debian packages, builds, and runs a small end-to-end
# example on this machine. Output goes to ./runs/demo.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/deploy/install-deps.sh"
"$root/deploy/build.sh"
gs="${GRAVSWEEP_BUILD_DIR:-$root/build}/scheduler/gravsweep"
out="$root/runs/demo"
mkdir -p "$out"
"$gs" bench --steps 500 --threads 1,2 | tee "$out/bench.txt"
