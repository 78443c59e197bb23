#!/usr/bin/env bash
# The README's main job: installs the Debian packages, builds, and runs a small end-to-end
# campaign on the embedded SQLite default, into ./runs/demo:
#   1. submit a sweep (2 gravities x 3 speeds x 2 start offsets; bed jobs shared by their drops),
#   2. run it with 2 worker processes (beds kept in a bed cache), 3. show status and the result table (and export CSV),
#   4. compare the collision model with a laboratory campaign (depth-friction-dev, if present):
#      import, rank the candidate terms, fit base vs base+depth_friction, write the report,
#   5. the same questions of the gravity sweep itself: every finished drop of the campaign
#      database is a trial (model rank, Table 3, report), and the repeats' means per group,
#   6. figures: the campaign's metrics against vc, and one demo drop (`gravsweep run`
#      on the campaign's 1 g bed at 1 m/s): Fig. 2, Fig. 1 and its ParaView snapshots; the
#      report's index.html opened in headless chromium when it is installed. Paths are printed;
#      nothing here is committed (runs/ is not tracked).
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
echo "== 2. work (2 worker processes, 1 thread each; beds kept in $out/beds, shared with other campaigns)"
"$gs" work --db "$db" --workers 2 --threads 1 --bed-cache "$out/beds"
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
echo "== 6. figures of the campaign and of one drop"
figs="$out/figures"
mkdir -p "$figs"
for y in apeak_m_s2 zstop_m tstop_s; do
  "$gs" plot results --db "$db" --x vc_m_s --y "$y" --group gravity_m_s2 --out "$figs/campaign_${y}_vs_vc.png"
done
# One drop with snapshots: the sweep's base scenario at 1 m/s, on the campaign's 1 g bed.
/usr/bin/python3 - "$root/examples/sweep_tiny.json" "$out/drop.json" <<'PY'
import json, sys
base = json.load(open(sys.argv[1]))["base"]
base["projectile"]["impact_speed_m_s"] = 1.0
json.dump(base, open(sys.argv[2], "w"), indent=1)
PY
# The bed cache's copy (<bed job id>.h5 + .sha256): `run --bed` verifies it against its checksum.
bed="$out/beds/$(sqlite3 "$db" "SELECT job_id FROM jobs WHERE kind='bed' AND state='done' AND \
  json_extract(scenario_json, '$.gravity_m_s2') = 9.81 LIMIT 1").h5"
"$gs" run "$out/drop.json" --out "$out/drop" --bed "$bed" --threads 2 --quiet
"$gs" plot bed "$bed" --trace "$out/drop/trace.h5" --snapshots "$out/drop/snapshots.h5" --out "$out/drop/fig1.png"
"$gs" plot trace "$out/drop/trace.h5" --out "$out/drop/fig2.png"
echo "   campaign figures:"
ls -1 "$figs"/*.png "$out/report-sweep"/*.png | sed 's/^/     /'
echo "   demo drop: $out/drop/fig1.png (Fig. 1), $out/drop/fig2.png (Fig. 2),"
echo "              $out/drop/snapshots.xdmf (open in ParaView: grains and projectile as point sets)"
echo "   report to send: $out/report-sweep/index.html"
if "$root/deploy/check-report.sh" "$out/report-sweep" "$out/report-sweep/screenshot.png" >/dev/null; then
  echo "   headless chromium screenshot of it: $out/report-sweep/screenshot.png"
fi
echo "demo finished: $out"
