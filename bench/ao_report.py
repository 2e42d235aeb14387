"""The AO benchmark's report (bench/ao_bench.py): the Markdown table of
speed-ups at MeshLab's error and the two plots (error against time per mesh,
speed-up against vertex count)."""

OURS = ("ours, per vertex", "ours, shared", "ours, shared, adaptive", "ours, adaptive strata")


def load_range(loads):
    """The range of the 1-minute load averages recorded around a method's runs ("8.1-10.3"), or "-"."""
    one = []
    for l in loads or []:
        if isinstance(l, dict):
            one += [x[0] for x in (l.get("before"), l.get("after")) if x]
        elif l:
            one.append(l[0])
    if not one:
        return "-"
    return "%.1f" % one[0] if len(one) == 1 else "%.1f-%.1f" % (min(one), max(one))


def speedup_table(summary):
    """Markdown: per mesh and MeshLab setting, MeshLab's time and RMS error, and for each of ours the time and rays
    per vertex to reach that error and the speed-up; the load averages around each side's runs."""
    lines = ["| mesh (vertices) | MeshLab views, depth map | MeshLab time | MeshLab RMS (raw) | load, MeshLab | "
             "ours per vertex | ours shared, fixed | ours shared, adaptive | ours adaptive strata | load, ours |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    keys = []
    for s in summary:
        if (s["scene"], s["views"], s["tex"]) not in keys:
            keys.append((s["scene"], s["views"], s["tex"]))
    for scene, views, tex in keys:
        by = {s["ours"]: s for s in summary if (s["scene"], s["views"], s["tex"]) == (scene, views, tex)}
        s = next(iter(by.values()))
        cells, loads = [], []
        for ours in OURS:
            o = by.get(ours)
            if o is None or o["ours_seconds"] is None:
                cells.append("not reached")
            else:
                cells.append("%.2f s, %.0f rays: %.1fx" % (o["ours_seconds"], o["ours_rays_per_vertex"], o["speedup"]))
            if o is not None:
                loads += o["ours_load_average"]
        lines.append("| %s (%s) | %d, %d^2 | %.1f s | %.4f (%.4f) | %s | %s | %s |" % (
            scene, "{:,}".format(s["vertices"]), views, tex, s["meshlab_seconds"], s["meshlab_rms"],
            s["meshlab_rms_raw"], load_range(s["meshlab_load_average"]), " | ".join(cells), load_range(loads)))
    return lines


def plot(rows, scene_names, summary, path, speedup_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(scene_names), figsize=(4.6 * len(scene_names), 4.2))
    if len(scene_names) == 1:
        axes = [axes]
    for ax, scene in zip(axes, scene_names):
        for method in sorted({r["method"] for r in rows if r["scene"] == scene}):
            pts = sorted((r["filter_seconds"], r["rms_error"]) for r in rows if r["scene"] == scene and r["method"] == method)
            ax.loglog([p[0] for p in pts], [max(p[1], 1e-5) for p in pts], "o-", ms=3, label=method)
        ax.set_title(scene)
        ax.set_xlabel("filter time (s)")
        ax.set_ylabel("RMS error vs reference (own normals)")
        ax.grid(True, which="both", lw=0.3)
    axes[0].legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(9.6, 4.6))
    for (views, tex), style in (((512, 512), "o-"), ((1024, 512), "s--"), ((512, 2048), "^-"), ((1024, 2048), "v--")):
        for ours, colour in (("ours, shared", "C0"), ("ours, per vertex", "C1"), ("ours, shared, adaptive", "C2"),
                             ("ours, adaptive strata", "C3")):
            pts = sorted((s["vertices"], s["speedup"]) for s in summary
                         if s["views"] == views and s["tex"] == tex and s["ours"] == ours and s["speedup"])
            if pts:
                ax.semilogx([p[0] for p in pts], [p[1] for p in pts], style, color=colour, ms=4,
                            label="%s vs MeshLab %d views, %d^2" % (ours, views, tex))
    ups = [s["speedup"] for s in summary if s["speedup"]] or [1.0]
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(min(0.8, 0.8 * min(ups)), max(45.0, 1.3 * max(ups)))
    ax.axhline(20, color="black", lw=0.8, ls=":")
    ax.axhline(30, color="black", lw=0.8, ls="-.")
    ax.text(ax.get_xlim()[0] * 1.1, 20 * 1.04, "goal 20x (all sizes)", fontsize=7)
    ax.text(ax.get_xlim()[0] * 1.1, 30 * 1.04, "goal 30x (500k and above)", fontsize=7)
    ax.set_xlabel("vertices")
    ax.set_ylabel("speed-up at MeshLab's error (x)")
    ax.set_title("time to MeshLab's RMS error: MeshLab's / ours", fontsize=9)
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(speedup_path, dpi=110)
    plt.close(fig)
