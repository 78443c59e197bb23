#!/usr/bin/env bash
# The README's main job: installs the Debian packages, builds, and runs a small end-to-end
# campaign on the embedded SQLite default, into ./runs/demo:
#   1. submit a sweep (2 gravities x 3 speeds x 2 start offsets; bed jobs shared by their drops),
#   2. run it with 2 worker processes, 3. show status and the result table (and export CSV),
#   4. compare the collision model with a laboratory campaign (depth-friction-dev, if present):
#      import, rank the candidate terms, fit base vs base+depth_friction, write the report,
#   5. the same questions of the gravity sweep itself: every finished drop of the campaign
#      database is a trial (model rank, Table 3, report), and the repeats' means per group.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
"$root/deploy/install-deps.sh"
"$root/deploy/build.sh"
gs="${GRAVSWEEP_BUILD_DIR:-$root/build}/scheduler/gravsweep"
out="$root/runs/demo"
rm -rf "$out"
mkdir -p "$out"
db="$out/campaign.db"

echo "== 1. submit"
"$gs" submit "$root/examples/sweep_tiny.json" --db "$db"
echo "== 2. work (2 worker processes, 1 thread each)"
"$gs" work --db "$db" --workers 2 --threads 1
echo "== 3. status and results"
"$gs" status --db "$db"
# The table shows the job, the swept parameters and the paper's metrics; the CSV has every column.
"$gs" results --db "$db" --sort gravity_m_s2
"$gs" results --db "$db" --format csv > "$out/results.csv"
echo "   results exported to $out/results.csv"

lab="$root/../shared/data/measurements/depth-friction-dev"
if [ -d "$lab" ]; then
  echo "== 4. model vs measurements ($lab)"
  "$gs" measurements import "$lab" --db "$out/lab.db"
  "$gs" model rank "$out/lab.db"
  "$gs" model fit "$out/lab.db" --model base+depth_friction --plot "$out/error_falls.png"
  "$gs" report "$out/lab.db" --out "$out/report"
  echo "   report written to $out/report"
fi
echo "== 5. the sweep as a campaign: model rank, table3, report on $db"
"$gs" results --db "$db" --group-by gravity_m_s2,impact_speed_m_s
"$gs" model rank "$db"
"$gs" model table3 "$db"
"$gs" report "$db" --out "$out/report-sweep"
echo "   report written to $out/report-sweep"
echo "demo finished: $out"
