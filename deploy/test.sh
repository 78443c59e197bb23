#!/usr/bin/env bash
# The README's test command: installs the Debian packages, builds, runs every test (CTest labels
# unit, physics, model, integration, postgres, cluster). Exit code: 0 when all pass.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/deploy/install-deps.sh"
"$root/deploy/build.sh"
cd "${GRAVSWEEP_BUILD_DIR:-$root/build}"
ctest --output-on-failure -j "$(nproc)" --timeout 900 "$@"
