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


def save_spec(fig, spec):
    """Finishes a figure drawn for a spec file: its title (if any), then spec["out"] at 120 dpi."""
    if spec.get("title"):
        fig.suptitle(spec["title"], fontsize=10)
    fig.tight_layout()
    fig.savefig(spec["out"], dpi=120)
    plt.close(fig)
    written.append(spec["out"])


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
    t3 = read(os.path.join(D, "table3.csv")) if os.path.exists(os.path.join(D, "table3.csv")) else []
    gs = by_g(trials)
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    for k, g in enumerate(gs):
        t = [r for r in trials if num(r["gravity_m_s2"]) == g]
        H = [num(r["drop_height_m"]) + num(r["zstop_m"]) for r in t]
        z = [num(r["zstop_m"]) for r in t]
        ax.loglog([100 * h for h in H], [100 * x for x in z], "o", ms=3, color=COLORS[k % len(COLORS)],
                  label=f"g = {g:g} m/s2")
        # Fig. 10a's lines: zstop ~ H^alpha with Table 3's alpha (table3.csv); given alpha, the
        # least-squares intercept on log-log axes is the mean of log z - alpha log H.
        row = [r for r in t3 if abs(num(r["gravity_m_s2"]) - g) <= 1e-6 * max(1.0, g)]
        alpha = num(row[0]["alpha"]) if row else math.nan
        pts = [(h, x) for h, x in zip(H, z) if h > 0 and x > 0]
        if pts and math.isfinite(alpha):
            c = sum(math.log(x) - alpha * math.log(h) for h, x in pts) / len(pts)
            hs = [min(h for h, _ in pts), max(h for h, _ in pts)]
            ax.loglog([100 * h for h in hs], [100 * math.exp(c) * h ** alpha for h in hs], "-", lw=2, alpha=0.45,
                      color=COLORS[k % len(COLORS)], label=f"zstop ~ H^alpha, alpha = {alpha:.3f} (Table 3)")
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
    # The axes frame the trials (the model curves start at vc -> 0, far below any trial).
    allH = [100 * (num(r["drop_height_m"]) + num(r["zstop_m"])) for r in trials]
    allz = [100 * num(r["zstop_m"]) for r in trials]
    pos = [(h, x) for h, x in zip(allH, allz) if h > 0 and x > 0]
    if pos:
        ax.set_xlim(min(h for h, _ in pos) / 1.5, max(h for h, _ in pos) * 1.5)
        ax.set_ylim(min(x for _, x in pos) / 1.5, max(x for _, x in pos) * 1.5)
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


def column(rows, key, sc=1.0):
    """A column scaled, or None when the record does not have it (empty cells)."""
    if not rows or rows[0].get(key, "") == "":
        return None
    return [sc * num(r[key]) for r in rows]


# Fig. 2 colours as the paper: lab black, DEM blue (a second DEM red), the re-integration green.
FIG2_STYLE = {"lab": ("black", "0.55"), "dem": ("tab:blue", "lightsteelblue"), "dem2": ("tab:red", "lightsalmon")}


def plot_trace():
    """Sunday et al. 2021 Fig. 2: a, v, z against the time since the collision start, raw and
    processed (500 Hz Butterworth, v and z re-integrated from the filtered a: the green line),
    with vc, apeak, zstop and tstop marked for the first record; a second record laid over it."""
    import json
    spec = json.load(open(os.path.join(D, "trace.json")))
    plt.rcParams.update({"font.size": 10})
    fig, axs = plt.subplots(3, 1, figsize=(11, 9.5), sharex=True, layout="constrained")
    seen_dem = False
    xmax = 0.0
    for idx, rec in enumerate(spec["records"]):
        rows = read(os.path.join(D, rec["csv"]))
        t = [1000 * num(r["t_s"]) for r in rows]
        kind = rec["source"] if rec["source"] == "lab" else ("dem2" if seen_dem else "dem")
        seen_dem = seen_dem or rec["source"] == "dem"
        main, light = FIG2_STYLE[kind]
        lab = rec["label"]
        a_raw = column(rows, "accel_raw_m_s2")
        if a_raw is not None:
            axs[0].plot(t, a_raw, color=light, lw=0.6, label=f"{lab}: raw a ({'sensor' if kind == 'lab' else 'engine'})")
        axs[0].plot(t, column(rows, "accel_m_s2"), color=main, lw=1.5, label=f"{lab}: 500 Hz Butterworth")
        for ax, raw, integ, sc, what in ((axs[1], "velocity_raw_m_s", "velocity_int_m_s", 1.0, "v"),
                                         (axs[2], "depth_raw_m", "depth_int_m", 100.0, "z")):
            own = column(rows, raw, sc)
            if own is not None:
                ax.plot(t, own, color=main, lw=1.5, label=f"{lab}: {what} of the {'engine' if kind != 'lab' else 'record'}")
            itg = column(rows, integ, sc)
            if itg is not None:
                green = "tab:green" if kind != "lab" or own is not None else main
                ax.plot(t, itg, color=green, lw=1.3, ls="--" if own is not None else "-",
                        label=f"{lab}: {what} integrated from the filtered a")
        m = rec["metrics"]
        xmax = max(xmax, 1000 * (m["t_end_s"] - m["t_start_s"]))
        if idx == 0:
            mark_fig2(axs, rows, t, m)
        if rec.get("note"):
            axs[0].text(0.01, 0.02, rec["note"], transform=axs[0].transAxes, fontsize=7, color="tab:red")
    axs[0].set_ylabel("acceleration, up (m/s$^2$)")
    axs[1].set_ylabel("velocity, down (m/s)")
    axs[2].set_ylabel("depth below the surface (cm)")
    axs[2].invert_yaxis()
    axs[2].set_xlabel("time since the collision start (ms)")
    axs[0].set_xlim(-0.25 * xmax - 2, 1.35 * xmax + 2)
    for ax in axs:
        ax.grid(alpha=0.3)
        ax.axvline(0, color="k", ls="--", lw=0.7)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    axs[0].plot([], [], "k--", lw=0.7, label="collision start")
    axs[0].plot([], [], "k:", lw=0.8, label="collision end")
    axs[0].legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    axs[0].set_title(spec.get("title", ""), fontsize=10)
    fig.savefig(spec["out"], dpi=120)
    plt.close(fig)
    written.append(spec["out"])


def mark_fig2(axs, rows, t, m):
    """The paper's annotations: vc at the start, apeak at the peak, zstop at the end, tstop."""
    t_end = 1000 * (m["t_end_s"] - m["t_start_s"])
    for ax in axs:
        ax.axvline(t_end, color="k", ls=":", lw=0.8)
    a = column(rows, "accel_m_s2")
    inside = [i for i, x in enumerate(t) if 0 <= x <= t_end] or list(range(len(t)))
    ipk = max(inside, key=lambda i: a[i])
    box = dict(arrowstyle="->", color="k", lw=0.8)
    axs[0].annotate(f"apeak = {m['apeak_m_s2']:.1f} m/s$^2$", xy=(t[ipk], m["apeak_m_s2"]),
                    xytext=(t[ipk] + 0.25 * t_end + 1, m["apeak_m_s2"]), arrowprops=box, va="center", fontsize=9)
    y0, y1 = axs[0].get_ylim()
    yt = y0 + 0.1 * (y1 - y0)
    axs[0].annotate("", xy=(0, yt), xytext=(t_end, yt), arrowprops=dict(arrowstyle="<->", lw=0.8))
    axs[0].text(0.5 * t_end, yt, f"tstop = {m['tstop_s'] * 1000:.1f} ms", ha="center", va="bottom", fontsize=9,
                bbox=dict(facecolor="white", edgecolor="none", alpha=0.8, pad=1))
    axs[1].annotate(f"vc = {m['vc_m_s']:.3f} m/s", xy=(0, m["vc_m_s"]), xytext=(0.2 * t_end + 1, 0.85 * m["vc_m_s"]),
                    arrowprops=box, fontsize=9)
    axs[2].annotate(f"zstop = {100 * m['zstop_m']:.2f} cm", xy=(t_end, 100 * m["zstop_m"]),
                    xytext=(0.45 * t_end, 0.5 * 100 * m["zstop_m"]), arrowprops=box, fontsize=9)


def plot_bed():
    """Sunday et al. 2021 Fig. 1: the container cut through its axis (plane y = 0), the grains the
    plane cuts drawn at their cut radius, coloured by their radial position in the prepared bed;
    the projectile at release and at rest."""
    import json
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    spec = json.load(open(os.path.join(D, "bed.json")))
    panels = spec["panels"]
    Rc = 100 * spec["container_diameter_m"] / 2
    Hw = 100 * spec["wall_height_m"]
    plt.rcParams.update({"font.size": 10})
    # Up to 2 cm above the highest of the surface and the projectile (the walls may go higher).
    top = 100 * spec["surface_height_m"]
    for p in panels:
        if "projectile" in p:
            top = max(top, 100 * (p["projectile"]["z_m"] + p["projectile"]["radius_m"]))
    top = min(Hw, top + 2)
    height = min(9.0, max(3.5, 6.2 * (top + 2) / (2 * Rc + 2) + 1.8))
    fig, axs = plt.subplots(1, len(panels), figsize=(6.2 * len(panels) + 1.2, height), squeeze=False,
                            layout="constrained")
    mappable = None
    for ax, p in zip(axs[0], panels):
        rows = read(os.path.join(D, p["grains"]))
        circles, colours = [], []
        for r in rows:
            y, rad = num(r["y_m"]), num(r["radius_m"])
            if abs(y) >= rad:
                continue
            cut = math.sqrt(rad * rad - y * y)
            circles.append(Circle((100 * num(r["x_m"]), 100 * num(r["z_m"])), 100 * cut))
            colours.append(100 * num(r["r0_m"]))
        pc = PatchCollection(circles, cmap="viridis", edgecolor="none")
        pc.set_array(colours)
        pc.set_clim(0, Rc)
        ax.add_collection(pc)
        mappable = pc
        ax.plot([-Rc, -Rc, Rc, Rc], [Hw, 0, 0, Hw], color="k", lw=2, label="container (cut)")
        ax.axhline(100 * spec["surface_height_m"], color="0.3", ls="--", lw=0.8, label="mean bed surface")
        if "projectile" in p:
            pj = p["projectile"]
            y, rad = pj["y_m"], pj["radius_m"]
            cut = math.sqrt(max(rad * rad - y * y, 0.0))
            ax.add_patch(Circle((100 * pj["x_m"], 100 * pj["z_m"]), 100 * cut, facecolor="0.75", edgecolor="k",
                                lw=1.2, label=f"projectile ({200 * rad:.0f} cm)"))
        ax.set_xlim(-Rc - 1, Rc + 1)
        ax.set_ylim(-0.5, top)
        ax.set_aspect("equal")
        ax.set_xlabel("x (cm), cut through the axis at y = 0")
        ax.set_ylabel("height above the container floor (cm)")
        ax.set_title(p["title"], fontsize=10)
        if p.get("note"):
            ax.text(0.02, 0.97, p["note"], transform=ax.transAxes, fontsize=8, va="top", color="tab:red")
        ax.legend(fontsize=7, loc="upper right")
    cb = fig.colorbar(mappable, ax=list(axs[0]), shrink=0.8, pad=0.02)
    cb.set_label("initial radial position of the grain (cm)")
    fig.suptitle(spec.get("title", ""), fontsize=10)
    fig.savefig(spec["out"], dpi=120)
    plt.close(fig)
    written.append(spec["out"])


def plot_collapse():
    """zstop/D, tstop sqrt(g/D) and apeak/g against Fr = vc / sqrt(g D), one colour per gravity
    level (paper II's collapse), log axes, each level's mean +/- std at each Froude number."""
    import json
    spec = json.load(open(os.path.join(D, "collapse.json")))
    rows = read(os.path.join(D, "collapse.csv"))
    levels = sorted({num(r["gravity_m_s2"]) for r in rows}, reverse=True)
    cmap = plt.get_cmap("viridis")
    panels = [("zstop_over_D", "zstop / D"), ("tstop_sqrt_g_over_D", "tstop sqrt(g / D)"),
              ("apeak_over_g", "apeak / g")]
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.2))
    for ax, (key, lab) in zip(axs, panels):
        for k, g in enumerate(levels):
            c = cmap(k / max(1, len(levels) - 1))
            pts = [(num(r["froude"]), num(r[key])) for r in rows if num(r["gravity_m_s2"]) == g]
            pts = [p for p in pts if p[0] > 0 and p[1] > 0]
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color=c, ms=5, alpha=0.8,
                    label=f"g = {g:g} m/s2")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("Fr = vc / sqrt(g D)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3, which="both")
    for row in spec.get("rows", []):
        i = [p[0] for p in panels].index(row["metric"])
        f = [num(row[k]) for k in ("common_scatter_pct", "within_scatter_pct", "collapse_ratio")]
        axs[i].set_title(f"scatter about one curve {f[0]:.0f} %, within levels {f[1]:.0f} %, ratio {f[2]:.2f}",
                         fontsize=8)
    axs[0].legend(fontsize=7)
    save_spec(fig, spec)


def plot_law_g():
    """A saved law's zstop, tstop and apeak against g (log axes), one curve per fixed speed or
    Froude number with its 95 % band; outside the fitted g range shaded, extrapolated points
    dashed, refused ones (predicted with --extrapolate) dotted."""
    import json
    spec = json.load(open(os.path.join(D, "law_g.json")))
    rows = read(os.path.join(D, "law_g.csv"))
    curves = list(dict.fromkeys(r["curve"] for r in rows))
    cmap = plt.get_cmap("viridis")
    panels = [("zstop", "m", "zstop (m)"), ("tstop", "s", "tstop (s)"), ("apeak", "m_s2", "apeak (m/s2)")]
    fig, axs = plt.subplots(1, 3, figsize=(13, 4.2))
    gmin, gmax = num(spec["fitted_g_min"]), num(spec["fitted_g_max"])
    for ax, (key, unit, lab) in zip(axs, panels):
        for k, name in enumerate(curves):
            c = cmap(k / max(1, len(curves) - 1))
            pts = [r for r in rows if r["curve"] == name and num(r[f"{key}_{unit}"]) > 0]
            g = [num(r["gravity_m_s2"]) for r in pts]
            ax.fill_between(g, [num(r[f"{key}_lo_{unit}"]) for r in pts], [num(r[f"{key}_hi_{unit}"]) for r in pts],
                            color=c, alpha=0.15, lw=0)
            for flag, style in (("inside", "-"), ("extrapolated", "--"), ("refused", ":")):
                ys = [num(r[f"{key}_{unit}"]) if r["range"] == flag else float("nan") for r in pts]
                ax.plot(g, ys, style, color=c, lw=1.6, label=name if flag == "inside" else None)
        ax.axvspan(1e-300, gmin, color="0.85", alpha=0.5, lw=0)
        ax.axvspan(gmax, 1e300, color="0.85", alpha=0.5, lw=0)
        allg = [num(r["gravity_m_s2"]) for r in rows]
        ax.set_xlim(min(allg), max(allg))
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("g (m/s2)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3, which="both")
    axs[0].legend(fontsize=7)
    axs[1].set_title("shaded: outside the fitted g; dashed: extrapolated; dotted: refused", fontsize=8)
    save_spec(fig, spec)


if WHICH == "law_g":
    plot_law_g()
if WHICH == "collapse":
    plot_collapse()
if WHICH == "trace":
    plot_trace()
if WHICH == "bed":
    plot_bed()
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
