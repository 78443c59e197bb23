#!/usr/bin/env bash
# The gravity sweep (GRAVITY.md): five gravity levels from 9.81 to 0.001 m/s2, speeds by Froude
# number, run with gravsweep's own scheduler. The cheap levels run first (sweep priorities); every
# run resumes where the last one stopped (kill it any time).
#
#   deploy/gravity-sweep.sh run      submit examples/gravity_sweep/*.json and run the workers
#   deploy/gravity-sweep.sh status   progress with ETA
#   deploy/gravity-sweep.sh export   finished levels -> data/gravity_sweep/ (measurement format, 2 kHz)
#   deploy/gravity-sweep.sh table    data/gravity_sweep/results.csv: every committed folder's drops in one
#                                    table (the union of their columns, a column `folder` first), the
#                                    metrics recomputed from the committed traces by this build's
#                                    processing (each drop in its own scales; `processed_by` names the
#                                    build), so that every row has one definition; each folder's own
#                                    results.csv keeps the worker's record as it ran
#
# Environment: GRAVSWEEP_CAMPAIGN (default runs/gravity_sweep/sweep.db), GRAVSWEEP_BIN (default
# build/scheduler/gravsweep), WORKERS (1), THREADS (2), SPECS (the folder of level specs, default
# examples/gravity_sweep; examples/gravity_sweep/extend holds the design's extensions: Fr 2-3 at
# 9.81 m/s2 with their dt check, a second bed and a deeper, wider bed at 0.01 m/s2; run them in a
# campaign of their own), DATA (where export writes, default data/gravity_sweep; the projectile
# sweep: SPECS=examples/projectile_sweep DATA=data/projectile_sweep, on the gravity sweep's beds).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
gs="${GRAVSWEEP_BIN:-$root/build/scheduler/gravsweep}"
db="${GRAVSWEEP_CAMPAIGN:-$root/runs/gravity_sweep/sweep.db}"
data="${DATA:-$root/data/gravity_sweep}"
specs="${SPECS:-$root/examples/gravity_sweep}"
beds="$root/data/gravity_sweep/beds"  # the bed cache of every sweep (the projectile sweep's beds are the gravity sweep's)
[ -x "$gs" ] || { "$root/deploy/install-deps.sh" && "$root/deploy/build.sh"; }

case "${1:-}" in
  run)
    mkdir -p "$(dirname "$db")" "$beds"
    for spec in "$specs"/g*.json; do "$gs" submit "$spec" --db "$db"; done
    "$gs" resume --db "$db"
    # Beds are kept in data/gravity_sweep/beds/ (commit them: a fresh machine skips their preparation).
    exec nice -n 10 "$gs" work --db "$db" --workers "${WORKERS:-1}" --threads "${THREADS:-2}" --lease 300 \
      --bed-cache "$beds"
    ;;
  status)
    exec "$gs" status --db "$db"
    ;;
  export)
    # One measurement campaign per level with finished drops, and one result table of all levels.
    for spec in "$specs"/g*.json; do
      sweep=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["sweep"])' "$spec")
      dir="$data/${sweep#*_sweep_}"
      rm -rf "$dir.tmp"
      if "$gs" export --db "$db" --sweep "$sweep" --out "$dir.tmp" --rate-hz 2000 &&
        [ "$(wc -l < "$dir.tmp/trials.csv")" -gt 1 ]; then
        rm -rf "$dir" && mv "$dir.tmp" "$dir"
      else
        echo "export: $sweep: nothing exported (see above)"; rm -rf "$dir.tmp"
      fi
    done
    "$0" table
    du -sh "$data"
    ;;
  table)
    # The committed folders' result rows in one table; a drop in two folders is refused. The
    # metric columns are this build's processing of the committed traces (measurements import).
    /usr/bin/python3 - "$data" "$gs" <<'PY'
import csv, glob, os, sqlite3, subprocess, sys, tempfile
data, gs = sys.argv[1], sys.argv[2]
version = subprocess.run([gs, "--version"], capture_output=True, text=True, check=True).stdout.strip()
processed_cols = ["vc_m_s", "apeak_m_s2", "zstop_m", "tstop_s", "rebound", "start_depth_m", "zstop_surface_m",
                  "cutoff_hz", "end_hold_s", "t_start_s", "t_end_s", "depth_at_end_m", "final_depth_m", "note"]
def processed(folder_dir):
    """The folder's trials processed by this build: {trial_id: {column: value}}."""
    with tempfile.TemporaryDirectory() as tmp:
        db = os.path.join(tmp, "m.db")
        subprocess.run([gs, "measurements", "import", folder_dir, "--db", db, "--format", "csv"],
                       check=True, stdout=subprocess.DEVNULL)
        con = sqlite3.connect(db)
        con.row_factory = sqlite3.Row
        out = {r["trial_id"]: {c: r[c] for c in processed_cols} for r in con.execute("SELECT * FROM trial_metrics")}
        con.close()
        return out
rows, cols, seen = [], ["folder"], {}
for path in sorted(glob.glob(os.path.join(data, "g*", "results.csv"))):
    folder = os.path.basename(os.path.dirname(path))
    metrics = processed(os.path.dirname(path))
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        for name in reader.fieldnames:
            if name not in cols:
                cols.append(name)
        for r in reader:
            if r["job_id"] in seen:
                sys.exit(f"{path}: drop {r['job_id']} is also in {seen[r['job_id']]}")
            seen[r["job_id"]] = folder
            m = metrics.get(r["job_id"], {})
            r.update({c: ("" if m.get(c) is None else m[c]) for c in processed_cols})
            rows.append(dict(r, folder=folder, processed_by=version))
for c in processed_cols + ["processed_by"]:
    if c not in cols:
        cols.append(c)
with open(os.path.join(data, "results.csv"), "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=cols, restval="")
    w.writeheader()
    w.writerows(rows)
print(f"{len(rows)} drops from {len(set(seen.values()))} folders -> {os.path.join(data, 'results.csv')}, "
      f"metrics processed by {version}")
PY
    ;;
  *)
    sed -n '2,17p' "$0"
    exit 2
    ;;
esac
