#!/usr/bin/env bash
# Installs the Debian packages listed in deploy/debian-packages.txt (skips the
# install when all are present, so repeated runs are fast and need no network), then
# what the browser test of `gravsweep serve` needs from npm (deploy/node/).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
mapfile -t pkgs < <(grep -v '^\s*#' "$here/debian-packages.txt" | grep -v '^\s*$')
missing=()
for p in "${pkgs[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
# Node and npm for the browser test: Debian's, unless a node is installed already (NodeSource's
# nodejs bundles its own npm and conflicts with Debian's npm package).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  missing+=(nodejs npm)
fi
if [ ${#missing[@]} -eq 0 ]; then
  echo "deploy: all ${#pkgs[@]} Debian packages present"
else
  echo "deploy: installing ${missing[*]}"
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# playwright-core drives Debian's chromium in the browser test (tests/scheduler/serve_page_check.js),
# at the version deploy/node/package-lock.json pins; it downloads no browser of its own.
if [ ! -f "$here/node/node_modules/playwright-core/package.json" ] ||
   ! grep -q "\"version\": \"$(sed -n 's/.*"playwright-core": "\(.*\)".*/\1/p' "$here/node/package.json")\"" \
     "$here/node/node_modules/playwright-core/package.json"; then
  echo "deploy: npm ci in $here/node (playwright-core)"
  PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --prefix "$here/node" --no-audit --no-fund --loglevel=error
fi
