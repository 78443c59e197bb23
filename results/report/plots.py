# Figures of `gravsweep report` / `gravsweep model fit --plot`, from the CSV files that
# results/report/report.cpp writes into the report folder. Usage: plots.py DIR [all|errors]
# Debian's python3-matplotlib and python3-numpy; no other dependency.
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def num(x):
    try:
        v = float(x)
        return v if math.isfinite(v) else float("nan")
    except (TypeError, ValueError):
        return float("nan")


D = sys.argv[1]
WHICH = sys.argv[2] if len(sys.argv) > 2 else "all"
COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
written = []


def save(fig, name):
    p = os.path.join(D, name)
    fig.tight_layout()
    fig.savefig(p, dpi=110)
    plt.close(fig)
    written.append(p)


def plot_errors():
    rows = read(os.path.join(D, "errors.csv"))
    keys = [("trace_rel_pct", "trace RMS (%)"), ("zstop_rel_pct", "zstop (%)"),
            ("tstop_rel_pct", "tstop (%)"), ("apeak_rel_pct", "apeak (%)")]
    fig, ax = plt.subplots(figsize=(8, 4))
    w = 0.8 / max(1, len(rows))
    for i, r in enumerate(rows):
        xs = [k + i * w for k in range(len(keys))]
        ys = [num(r[k]) for k, _ in keys]
        ax.bar(xs, ys, width=w, label=r["model"], color=COLORS[i % len(COLORS)])
        for x, y in zip(xs, ys):
            if math.isfinite(y):
                ax.text(x, y, f"{y:.0f}", ha="center", va="bottom", fontsize=7)
    ax.set_xticks([k + 0.4 - w / 2 for k in range(len(keys))])
    ax.set_xticklabels([l for _, l in keys])
    ax.set_ylabel("held-out relative RMS error (%)")
    ax.set_title("Held-out error, whole trials left out (grouped CV)")
    ax.legend(fontsize=8)
    save(fig, "error_falls.png")


def by_g(rows):
    gs = sorted({num(r["gravity_m_s2"]) for r in rows}, reverse=True)
    return gs


def plot_fig9():
    trials = read(os.path.join(D, "trials.csv"))
    curves = read(os.path.join(D, "model_curves.csv"))
    gs = by_g(trials)
    models = []
    for r in curves:
        if r["model"] not in models:
            models.append(r["model"])
    fig, axs = plt.subplots(3, len(gs), figsize=(4 * len(gs), 9), squeeze=False)
    for j, g in enumerate(gs):
        t = [r for r in trials if num(r["gravity_m_s2"]) == g]
        for i, (key, lab, sc) in enumerate([("apeak_m_s2", "apeak (m/s2)", 1), ("zstop_m", "zstop (cm)", 100),
                                            ("tstop_s", "tstop (ms)", 1000)]):
            ax = axs[i][j]
            ax.plot([num(r["vc_m_s"]) for r in t], [sc * num(r[key]) for r in t], "ko", ms=3, label="measured")
            for k, m in enumerate(models):
                c = [r for r in curves if r["model"] == m and num(r["gravity_m_s2"]) == g]
                ax.plot([num(r["vc_m_s"]) for r in c], [sc * num(r[key]) for r in c], "-",
                        color=COLORS[k % len(COLORS)], label=m)
            ax.set_xlabel("collision velocity vc (m/s)")
            ax.set_ylabel(lab)
            if i == 0:
                ax.set_title(f"g = {g:g} m/s2")
            if i == 0 and j == 0:
                ax.legend(fontsize=7)
    save(fig, "fig9_metrics_vs_vc.png")


def plot_residuals():
    rows = read(os.path.join(D, "residuals.csv"))
    rcols = [k for k in rows[0].keys() if k.startswith("r_")]
    gs = by_g(rows)
    fig, axs = plt.subplots(len(rcols), 2, figsize=(10, 3.6 * len(rcols)), squeeze=False)
    for i, rc in enumerate(rcols):
        for j, (ax_key, lab, sc) in enumerate([("depth_m", "depth z (cm)", 100), ("speed_m_s", "speed v (m/s)", 1)]):
            ax = axs[i][j]
            allr = []
            for k, g in enumerate(gs):
                s = [r for r in rows if num(r["gravity_m_s2"]) == g]
                xs = [sc * num(r[ax_key]) for r in s]
                ys = [num(r[rc]) / g for r in s]
                allr += ys
                ax.plot(xs, ys, ".", ms=1, alpha=0.25, color=COLORS[k % len(COLORS)])
                # binned means (10 quantile bins): the structure the scatter hides
                pairs = sorted(zip(xs, ys))
                nb = 10
                bx, by = [], []
                for b in range(nb):
                    chunk = pairs[b * len(pairs) // nb:(b + 1) * len(pairs) // nb]
                    if chunk:
                        bx.append(sum(p[0] for p in chunk) / len(chunk))
                        by.append(sum(p[1] for p in chunk) / len(chunk))
                ax.plot(bx, by, "o-", ms=4, lw=1.5, color=COLORS[k % len(COLORS)], label=f"g = {g:g} m/s2 (bin means)")
            ax.axhline(0, color="k", lw=0.8)
            srt = sorted(allr)
            if srt:
                lo, hi = srt[int(0.02 * len(srt))], srt[int(0.98 * len(srt)) - 1]
                pad = 0.1 * (hi - lo)
                ax.set_ylim(lo - pad, hi + pad)
            ax.set_xlabel(lab)
            ax.set_ylabel("residual a_meas - a_model (g)")
            ax.set_title(rc[2:].replace("_m_s2", ""))
            if i == 0 and j == 0:
                ax.legend(fontsize=7)
    save(fig, "residual_vs_depth_speed.png")


def plot_fig10():
    trials = read(os.path.join(D, "trials.csv"))
    gs = by_g(trials)
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for k, g in enumerate(gs):
        t = [r for r in trials if num(r["gravity_m_s2"]) == g]
        H = [num(r["drop_height_m"]) + num(r["zstop_m"]) for r in t]
        z = [num(r["zstop_m"]) for r in t]
        ax.loglog([100 * h for h in H], [100 * x for x in z], "o", ms=3, color=COLORS[k % len(COLORS)],
                  label=f"g = {g:g} m/s2")
    curves = read(os.path.join(D, "model_curves.csv"))
    models = []
    for r in curves:
        if r["model"] not in models:
            models.append(r["model"])
    styles = ["-", "--", ":", "-."]
    for k, g in enumerate(gs):
        for mi, m in enumerate(models):
            c = [r for r in curves if r["model"] == m and num(r["gravity_m_s2"]) == g and num(r["zstop_m"]) > 0]
            H = [100 * (num(r["vc_m_s"]) ** 2 / (2 * g) + num(r["zstop_m"])) for r in c]
            z = [100 * num(r["zstop_m"]) for r in c]
            ax.loglog(H, z, styles[mi % len(styles)], lw=1, color=COLORS[k % len(COLORS)],
                      label=m if k == 0 else None)
    ax.set_xlabel("H = drop height + zstop (cm)")
    ax.set_ylabel("zstop (cm)")
    ax.set_title("Penetration depth vs total height (Fig. 10)")
    ax.legend(fontsize=8)
    save(fig, "fig10_zstop_vs_H.png")


def plot_ranking():
    p = os.path.join(D, "ranking.csv")
    if not os.path.exists(p):
        return
    rows = [r for r in read(p) if r["round"] == "1"]
    if not rows:
        return
    fig, ax = plt.subplots(figsize=(7, 3.5))
    names = [r["term"] for r in rows]
    vals = [100 * num(r["mean_rel_improvement"]) for r in rows]
    cols = ["tab:green" if r["significant"] == "1" else "tab:gray" for r in rows]
    ax.barh(names[::-1], vals[::-1], color=cols[::-1])
    ax.set_xlabel("mean held-out improvement of trace MSE per trial (%)")
    ax.set_title("Candidate terms (green: significant, signed-rank test over trials)")
    save(fig, "ranking.png")


# ---- `gravsweep plot results`: one metric against one parameter from a results table --------
# xy.csv holds the columns x, y, group (group may be empty); xy.json the labels and the output.
# Units follow the column names' suffixes and are shown as the paper does (cm, ms, m/s2).
UNITS = [("_m_s2", 1.0, "m/s2"), ("_m_s", 1.0, "m/s"), ("_kg_m3", 1.0, "kg/m3"), ("_hz", 1.0, "Hz"),
         ("_m", 100.0, "cm"), ("_s", 1000.0, "ms")]
NAMES = {"zstop_m": "penetration depth zstop", "tstop_s": "collision duration tstop",
         "apeak_m_s2": "peak acceleration apeak", "vc_m_s": "collision velocity vc",
         "impact_speed_m_s": "impact speed", "fill_height_m": "fill height",
         "gravity_m_s2": "gravity g", "mu_rolling": "rolling friction mu_r"}


def scale_of(col):
    for suffix, sc, unit in UNITS:
        if col.endswith(suffix):
            return sc, unit
    return 1.0, ""


def label_of(col):
    sc, unit = scale_of(col)
    name = NAMES.get(col, col)
    return f"{name} ({unit})" if unit else name


def plot_xy():
    import json
    spec = json.load(open(os.path.join(D, "xy.json")))
    rows = read(os.path.join(D, "xy.csv"))
    xs_, ys_ = scale_of(spec["x"])[0], scale_of(spec["y"])[0]
    groups = []
    for r in rows:
        if r["group"] not in groups:
            groups.append(r["group"])
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for k, gname in enumerate(groups):
        pts = [(num(r["x"]) * xs_, num(r["y"]) * ys_) for r in rows if r["group"] == gname]
        pts = [p for p in pts if math.isfinite(p[0]) and math.isfinite(p[1])]
        c = COLORS[k % len(COLORS)]
        lab = f"{spec['group']} = {gname}" if spec.get("group") else "runs"
        ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color=c, alpha=0.35, ms=4,
                label=f"{lab} (each run)")
        xs = sorted({p[0] for p in pts})
        mean = [sum(p[1] for p in pts if p[0] == x) / sum(1 for p in pts if p[0] == x) for x in xs]
        sd = []
        for x, m in zip(xs, mean):
            v = [p[1] for p in pts if p[0] == x]
            sd.append(math.sqrt(sum((y - m) ** 2 for y in v) / (len(v) - 1)) if len(v) > 1 else 0.0)
        ax.errorbar(xs, mean, yerr=sd, fmt="-s", color=c, ms=5, capsize=3,
                    label=f"{lab} (mean +/- std)")
    ax.set_xlabel(label_of(spec["x"]))
    ax.set_ylabel(label_of(spec["y"]))
    if spec.get("title"):
        ax.set_title(spec["title"], fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(spec["out"], dpi=120)
    plt.close(fig)
    written.append(spec["out"])


def plot_trace():
    """Sunday et al. 2021 Fig. 2 for one record: a, v, z against time, raw and processed."""
    import json
    spec = json.load(open(os.path.join(D, "trace.json")))
    rows = read(os.path.join(D, "trace.csv"))
    m = spec["metrics"]
    t = [1000 * num(r["t_s"]) for r in rows]
    fig, axs = plt.subplots(3, 1, figsize=(7, 8.5), sharex=True)
    panels = [("accel_raw_m_s2", "accel_m_s2", "acceleration, up (m/s2)", 1.0),
              ("velocity_raw_m_s", "velocity_m_s", "velocity, down (m/s)", 1.0),
              ("depth_raw_m", "depth_m", "depth below the surface (cm)", 100.0)]
    for ax, (raw, proc, lab, sc) in zip(axs, panels):
        if rows and rows[0].get(raw, "") != "":
            ax.plot(t, [sc * num(r[raw]) for r in rows], color="0.6", lw=0.7, label="raw record")
        if proc == "accel_m_s2":
            plab = "500 Hz Butterworth (paper)"
        elif spec.get("source") == "dem":
            plab = "the engine's own (DEM)"
        else:
            plab = "integrated from the filtered a"
        ax.plot(t, [sc * num(r[proc]) for r in rows], color="tab:green", lw=1.4, label=plab)
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
        for key, style in (("t_start_s", "--"), ("t_end_s", ":")):
            if m.get(key) is not None:
                ax.axvline(1000 * m[key], color="k", ls=style, lw=0.8)
    if m.get("apeak_m_s2") is not None:
        axs[0].axhline(m["apeak_m_s2"], color="tab:red", lw=0.8,
                       label=f"apeak = {m['apeak_m_s2']:.1f} m/s2")
    if m.get("vc_m_s") is not None:
        axs[1].axhline(m["vc_m_s"], color="tab:blue", lw=0.8, label=f"vc = {m['vc_m_s']:.3f} m/s")
    if m.get("zstop_m") is not None:
        axs[2].axhline(100 * m["zstop_m"], color="tab:purple", lw=0.8,
                       label=f"zstop = {100 * m['zstop_m']:.2f} cm")
    if m.get("tstop_s") is not None:
        axs[2].plot([], [], "k--", lw=0.8, label=f"start / end (tstop = {1000 * m['tstop_s']:.1f} ms)")
    for ax in axs:
        ax.legend(fontsize=7, loc="best")
    axs[2].invert_yaxis()
    axs[2].set_xlabel("time since release (ms)")
    axs[0].set_title(spec.get("title", ""), fontsize=9)
    fig.tight_layout()
    fig.savefig(spec["out"], dpi=120)
    plt.close(fig)
    written.append(spec["out"])


if WHICH == "trace":
    plot_trace()
if WHICH == "xy":
    plot_xy()
if WHICH in ("all", "errors"):
    plot_errors()
if WHICH == "all":
    plot_fig9()
    plot_residuals()
    plot_fig10()
    plot_ranking()
for p in written:
    print(p)
