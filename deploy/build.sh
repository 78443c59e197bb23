#!/usr/bin/env bash
# Configures and builds gravsweep (Release, ccache when present) into ./build.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${GRAVSWEEP_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release >/dev/null
# Serialise builds on this machine (2 cores): concurrent builds only slow each other down.
flock /tmp/gravsweep-build.lock cmake --build "$build" -j "$(nproc)"
