"""The gravity sweep's cost for deploy/bench-sweep.sh: `estimate DATA CORES` from the committed
records, `report DB CORES` from a campaign database. One table printer for both."""
import csv, json, math, os, sqlite3, statistics, sys


def print_table(header, rows):
    """Right-aligned columns, two spaces apart."""
    width = [max(len(str(r[i])) for r in [header] + rows) for i in range(len(header))]
    for r in [header] + rows:
        print("  ".join(str(c).rjust(width[i]) for i, c in enumerate(r)))


def facts(scenario):
    """gravity (m/s2) and Froude number v / sqrt(g D) of a stored scenario (its fields, with the
    validation marks beside them)."""
    s = json.loads(scenario)
    g, p = s.get("gravity_m_s2"), s.get("projectile", {})
    v, d = p.get("impact_speed_m_s"), p.get("diameter_m")
    return g, (v / math.sqrt(g * d) if v and g and d else float("nan"))


def report(db, cores):
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
    # Each finished job with the wall and core time of all its attempts (an attempt interrupted and
    # resumed from its checkpoint counts with the one that finished it).
    rows = con.execute("""
      SELECT j.sweep_id, j.kind, sum(a.runtime_s), min(a.started_at), max(a.ended_at),
             group_concat(DISTINCT a.code_version), j.scenario_json, sum(a.runtime_s * a.threads)
      FROM attempts a JOIN jobs j ON j.job_id = a.job_id
      WHERE j.state = 'done' AND a.runtime_s IS NOT NULL GROUP BY j.job_id""").fetchall()
    if not rows:
        sys.exit("bench-sweep: no finished attempt in " + db)
    states = dict(con.execute("SELECT state, count(*) FROM jobs GROUP BY state").fetchall())
    by = {}
    for sweep, kind, rt, t0, t1, build, scen, core_s in rows:
        g, fr = facts(scen)
        e = by.setdefault((sweep, g), {"bed": [], "drop": [], "t0": t0, "t1": t1, "fr1": []})
        e[kind].append((rt, core_s))
        e["t0"], e["t1"] = min(e["t0"], t0), max(e["t1"], t1)
        if kind == "drop" and abs(fr - 1) < 0.05:
            e["fr1"].append(rt)
    builds = sorted({b for r in rows for b in r[5].split(",")})
    print(f"campaign {db}: builds {', '.join(builds)}; jobs " + ", ".join(f"{k} {v}" for k, v in sorted(states.items())))
    out = []
    for sweep, g in sorted(by, key=lambda k: (-k[1], k[0])):  # by level, then sweep
        e = by[(sweep, g)]
        core_s = sum(c for _, c in e["bed"] + e["drop"])
        drops = [rt for rt, _ in e["drop"]]
        out.append([sweep, "%g" % g, len(e["bed"]), "%.0f" % sum(rt for rt, _ in e["bed"]), len(drops),
                    "%.0f" % statistics.median(drops) if drops else "-", "%.0f" % max(drops) if drops else "-",
                    "/".join("%.0f" % x for x in e["fr1"]) or "-", "%.2f" % (core_s / 3600),
                    "%.2f" % ((e["t1"] - e["t0"]) / 3600)])
    print_table(["sweep", "gravity_m_s2", "beds", "bed_wall_s", "drops", "drop_wall_median_s", "drop_wall_max_s",
                 "drop_at_fr1_wall_s", "core_h", "span_h"], out)
    core_h = sum(r[7] for r in rows) / 3600
    span = (max(r[4] for r in rows) - min(r[3] for r in rows)) / 3600
    print(f"whole campaign: {core_h:.2f} core-hours; wall {span:.2f} h ({span * 3600:.0f} s) from the first claim to "
          f"the last completion ({core_h / cores:.2f} h if {cores} cores never idled)")


def estimate(data, cores):
    import h5py
    levels = ["9.81", "1.62", "0.1", "0.01", "0.001"]
    # The sweep's 50 drops: each level's folder and its at-rest rerun on the axis window (g<level>_axis).
    rows = list(csv.DictReader(open(os.path.join(data, "results.csv"))))
    print("the committed gravity sweep's records (data/gravity_sweep/results.csv and its beds' reports); "
          "runtime_s is each attempt's wall time on the host that ran it, beside other work: an upper bound")
    out, tot = [], 0.0
    for lv in levels:
        rs = [r for r in rows if r["folder"] in ("g" + lv, "g" + lv + "_axis")]
        drop_s = sum(float(r["runtime_s"]) * int(float(r["threads"] or 1)) for r in rs)
        beds = sorted({r["bed_job_id"] for r in rs})
        bed_s = 0.0
        for b in beds:
            with h5py.File(os.path.join(data, "beds", b + ".h5"), "r") as f:
                rep = json.loads(f.attrs["report"])
            bed_s += rep.get("wall_time_s", 0) * rep.get("threads", 1)
        tot += drop_s + bed_s
        out.append([lv, len(rs), "%.2f" % (drop_s / 3600), ",".join(b[:8] for b in beds), "%.2f" % (bed_s / 3600),
                    "%.2f" % ((drop_s + bed_s) / 3600), "%.2f" % ((drop_s + bed_s) / 3600 / cores)])
    print_table(["gravity_m_s2", "drops", "drop_core_h", "bed", "bed_core_h", "level_core_h",
                 f"wall_h_on_{cores}_cores"], out)
    print(f"whole sweep: {tot / 3600:.2f} core-hours, {tot / 3600 / cores:.2f} h on {cores} cores if none idled")


if __name__ == "__main__":
    mode, where, cores = sys.argv[1], sys.argv[2], int(sys.argv[3])
    {"report": report, "estimate": estimate}[mode](where, cores)
