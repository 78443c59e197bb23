#!/usr/bin/env bash
# Opens a report's index.html in a real headless browser (Debian's chromium) and writes a
# screenshot, so a person (or a test) can see what a colleague will see:
#   deploy/check-report.sh REPORT_DIR [SHOT.png]     (default shot: REPORT_DIR/screenshot.png)
# Checks first that the page is self-contained (no http(s), file or relative src/href), then that
# the screenshot is a PNG. Exit 0: screenshot written; 1: a check failed; 77: no chromium here
# (apt-get install chromium; the test that calls this script is then skipped with that reason).
set -euo pipefail
dir="${1:?usage: deploy/check-report.sh REPORT_DIR [SHOT.png]}"
page="$(cd "$dir" && pwd)/index.html"
shot="${2:-$dir/screenshot.png}"
[ -f "$page" ] || { echo "check-report: no $page" >&2; exit 1; }
browser="$(command -v chromium || command -v chromium-browser || true)"
[ -n "$browser" ] || { echo "check-report: chromium not installed (apt-get install chromium)" >&2; exit 77; }
if grep -Eo '(src|href)="[^"#][^"]*"' "$page" | grep -v '^src="data:' >&2; then
  echo "check-report: $page links to other files (above): not self-contained" >&2
  exit 1
fi
profile="$(mktemp -d)"
trap 'rm -rf "$profile"' EXIT
rm -f "$shot"
# --no-sandbox: tests and CI run as root; a fresh profile so nothing of a user's browser is read.
timeout 120 "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars --user-data-dir="$profile" \
  --window-size=1280,6400 --screenshot="$(realpath -m "$shot")" "file://$page" >/dev/null 2>&1 || true
if [ ! -s "$shot" ] || [ "$(head -c 4 "$shot" | tail -c 3)" != "PNG" ]; then
  echo "check-report: chromium wrote no screenshot of $page" >&2
  exit 1
fi
echo "$shot"
