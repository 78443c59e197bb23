#!/usr/bin/env bash
# The paper's simulation campaign (Sunday et al. 2021), run with gravsweep itself.
#
#   deploy/reproduce.sh run      submit every part of examples/reproduction/ and run the workers
#                                (hours on 2 cores; kill it any time, run it again to resume)
#   deploy/reproduce.sh status   progress with ETA
#   deploy/reproduce.sh export   the finished drops -> data/reproduction/ (measurement format)
#   deploy/reproduce.sh figures  Figs. 3, 6, 9, 10 and Table 3 from the campaign and the dataset
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
    mkdir -p "$figs"
    plot() { "$gs" plot results --db "$db" "$@" || true; }
    plot --sweep part3_fill_height --x fill_height_m --y zstop_m \
      --title "Fig. 3: 1 m/s at 1 g, Chrono set" --out "$figs/fig3_zstop_vs_fill.png"
    plot --sweep part4_rolling_friction --x mu_rolling --y zstop_m \
      --title "Fig. 6: 1 m/s at 1 g, mu_t = 0" --out "$figs/fig6_zstop_vs_mur.png"
    for y in apeak_m_s2 zstop_m tstop_s; do
      plot --where 'sweep~_chrono_' --x vc_m_s --y "$y" --group gravity_m_s2 \
        --title "Chrono set, 10 cm (1 g) and 21 cm (0.1 m/s2) fills" --out "$figs/fig9_${y}_vs_vc.png"
    done
    for d in "$data"/*/; do "$gs" model table3 "$d"; done | tee "$figs/table3.txt"
    "$gs" model rank "$db" --where 'sweep~_chrono_' | tee "$figs/model_rank_chrono.txt"
    # Figs. 9 and 10 with both gravity levels (Table 3's Eq. 2-4 lines and alpha fits, the models' curves).
    reports=("$data/chrono_1g"); [ -f "$data/chrono_0.1g/trials.csv" ] && reports+=("$data/chrono_0.1g")
    "$gs" report "${reports[@]}" --out "$figs/report"
    cp "$figs/report/fig9_metrics_vs_vc.png" "$figs/report/fig10_zstop_vs_H.png" "$figs/"
    ;;
  *)
    sed -n '2,12p' "${BASH_SOURCE[0]}"
    exit 2
    ;;
esac
