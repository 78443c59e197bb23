#!/usr/bin/env bash
# The paper's simulation campaign (Sunday et al. 2021), run with gravsweep itself.
#
#   deploy/reproduce.sh run      submit every part of examples/reproduction/ and run the workers
#                                (hours on 2 cores; kill it any time, run it again to resume)
#   deploy/reproduce.sh status   progress with ETA
#   deploy/reproduce.sh export   the finished drops -> data/reproduction/ (measurement format)
#   deploy/reproduce.sh figures  Figs. 3, 6, 9, 10 and Table 3 from the committed data
#                                (docs/reproduction/figures.txt)
#
# Environment: GRAVSWEEP_CAMPAIGN (default runs/reproduction/paper.db), GRAVSWEEP_BIN (default
# build/scheduler/gravsweep), WORKERS (2), THREADS (1).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
gs="${GRAVSWEEP_BIN:-$root/build/scheduler/gravsweep}"
db="${GRAVSWEEP_CAMPAIGN:-$root/runs/reproduction/paper.db}"
data="$root/data/reproduction"
figs="$root/docs/reproduction"
[ -x "$gs" ] || { "$root/deploy/install-deps.sh" && "$root/deploy/build.sh"; }

case "${1:-}" in
  run)
    mkdir -p "$(dirname "$db")"
    for spec in "$root"/examples/reproduction/part*.json; do "$gs" submit "$spec" --db "$db"; done
    "$gs" resume --db "$db"
    # Beds are stored in (and taken from) data/reproduction/beds/: commit them, and a campaign on a
    # fresh machine skips the hours of bed preparation (pipeline/bed_cache.h).
    exec nice -n 10 "$gs" work --db "$db" --workers "${WORKERS:-2}" --threads "${THREADS:-1}" --lease 120 \
      --bed-cache "$data/beds"
    ;;
  status)
    exec "$gs" status --db "$db"
    ;;
  export)
    # One measurement campaign per Table 3 row (a fit mixes every trial of a gravity level), and
    # the result table of every sweep with finished drops. A campaign that was restarted on a new
    # machine may hold fewer drops of a part than the committed dataset: that dataset is kept.
    count() { [ -f "$1/trials.csv" ] && echo $(( $(wc -l < "$1/trials.csv") - 1 )) || echo 0; }
    for part in part1_chrono_1g:chrono_1g part2_chrono_lowg:chrono_0.1g part5_pkdgrav_1g:pkdgrav_1g \
      part1_dt_check:dt_check part4_rolling_friction:rolling_friction part3_fill_height:fill_height \
      part5b_pkdgrav_stiff_1g:pkdgrav_stiff_1g; do
      sweep="${part%%:*}"; dir="$data/${part##*:}"
      rm -rf "$dir.tmp"
      if ! "$gs" export --db "$db" --sweep "$sweep" --out "$dir.tmp" --rate-hz 2000; then
        echo "export: $sweep: nothing exported (see above); $dir kept"; rm -rf "$dir.tmp"; continue
      fi
      if [ "$(count "$dir.tmp")" -eq 0 ] || [ "$(count "$dir.tmp")" -lt "$(count "$dir")" ]; then
        echo "export: $sweep: $(count "$dir.tmp") drops in this campaign, $(count "$dir") in $dir: kept"
        rm -rf "$dir.tmp"; continue
      fi
      rm -rf "$dir" && mv "$dir.tmp" "$dir"
    done
    for spec in "$root"/examples/reproduction/part*.json; do
      sweep=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["sweep"])' "$spec")
      out="$data/results_$sweep.csv"
      "$gs" results --db "$db" --where "sweep=$sweep" --where "kind=drop" --all --format csv --out "$out.tmp"
      rows=$(( $(wc -l < "$out.tmp") - 1 ))
      if [ "$rows" -gt 0 ] && [ "$rows" -ge "$( [ -f "$out" ] && echo $(( $(wc -l < "$out") - 1 )) || echo 0)" ]; then
        mv "$out.tmp" "$out"; echo "export: $out ($rows drops)"
      else
        rm -f "$out.tmp"
      fi
    done
    du -sh "$data"
    ;;
  figures)
    # Every line of docs/reproduction/figures.txt, from the committed data (paths from the root),
    # then the report's Figs. 9 and 10 (Eq. 2-4 lines and alpha fits) of both Chrono levels.
    cd "$root"
    grep -v '^#' docs/reproduction/figures.txt | while IFS= read -r line; do
      [ -n "$line" ] || continue
      file="${line%%: *}"; args="${line#*: }"
      case "$file" in
        *.png) eval "\"$gs\" $args --out 'docs/reproduction/$file' --data 'docs/reproduction/${file%.png}.csv'" ;;
        *) eval "\"$gs\" $args" > "docs/reproduction/$file" 2>&1 ;;
      esac
    done
    rm -rf "$figs/report"
    "$gs" report data/reproduction/chrono_1g_sites data/reproduction/chrono_0.1g --out "$figs/report" >/dev/null
    cp "$figs/report/fig9_metrics_vs_vc.png" "$figs/report/fig10_zstop_vs_H.png" "$figs/"
    rm -rf "$figs/report"
    ;;
  *)
    sed -n '2,12p' "${BASH_SOURCE[0]}"
    exit 2
    ;;
esac
