#!/usr/bin/env python3
"""Draws the plots of `clothlab bench accuracy` and `clothlab bench methods` from their CSVs.

    python3 plot_accuracy.py accuracy.csv work-precision.svg
    python3 plot_methods.py methods.csv methods.svg

The commands write this one script under those two names; it tells the CSVs apart by their
columns. The output format follows the file's extension (.svg, .png, .pdf).

bench accuracy (lesson 07): two panels, both log-log, one line per integrator, only the runs that
stayed stable: the error at the end time against the wall time per simulated second (what it
costs on this machine), and against the force evaluations per simulated second (what it costs on
any machine). Along a line the step shrinks from left to right: the cost grows, the error falls,
and the slope is minus the method's order.

bench methods (lesson 12): one column per scene. Top: the error against the reference (RMS over
the frames, relative to the cloth's size) against the wall time per simulated second, one line per
method (XPBD's substep ladder, its iteration ladder and its runs of several steps a frame apart),
stable runs only; the dashed line is the reference's own difference at half its step, under which
no error can be trusted. Bottom: the worst spring strain against the same wall time, with the
reference's as a dashed line: a method above it lets the cloth stretch. Lower left is better.
"""
import csv
import sys

ACCURACY_COLUMNS = {"problem", "integrator", "dt", "steps", "error", "wall_s_per_sim_s",
                    "force_evals_per_sim_s", "stable"}
METHODS_COLUMNS = {"scene", "method", "dt", "substeps", "iterations", "steps", "error",
                   "worst_strain", "energy_lost", "wall_s_per_sim_s", "stable"}

ACCURACY_STYLE = {
    "explicit-euler": ("tab:red", "o"),
    "symplectic-euler": ("tab:orange", "s"),
    "midpoint": ("tab:green", "^"),
    "rk4": ("tab:blue", "D"),
    "velocity-verlet": ("tab:purple", "v"),
    "position-verlet": ("tab:pink", "<"),
    "implicit-euler": ("tab:brown", "P"),
}

METHODS_STYLE = {
    "symplectic-euler": ("tab:orange", "s"),
    "rk4": ("tab:blue", "D"),
    "implicit-euler": ("tab:brown", "P"),
    "xpbd substeps": ("tab:green", "o"),
    "xpbd iterations": ("tab:olive", "^"),
    "xpbd steps x substeps": ("tab:cyan", "*"),
    "local-global": ("tab:purple", "v"),
    "vbd 1 iteration": ("tab:gray", "X"),
    "vbd 10 iterations": ("black", "p"),
}

def line_name(row):
    """XPBD's rungs that add substeps, those that add iterations, and those that take several
    steps a frame (so that the colliders act more often) are three lines."""
    if row["method"] == "vbd":
        return "vbd 1 iteration" if int(row["iterations"]) == 1 else "vbd 10 iterations"
    if row["method"] != "xpbd":
        return row["method"]
    if float(row["dt"]) < 0.99 / 60.0:
        return "xpbd steps x substeps"
    return "xpbd iterations" if int(row["iterations"]) > 1 else "xpbd substeps"


def draw_accuracy(plt, rows):
    problem = rows[0]["problem"] if rows else "?"
    lines = {}
    for row in rows:
        if row["stable"] != "true":
            continue
        lines.setdefault(row["integrator"], []).append(
            (float(row["wall_s_per_sim_s"]), float(row["force_evals_per_sim_s"]),
             float(row["error"])))

    fig, (by_time, by_evals) = plt.subplots(1, 2, figsize=(11, 4.6), sharey=True)
    for name, points in lines.items():
        points.sort()
        color, marker = ACCURACY_STYLE.get(name, ("black", "x"))
        errors = [max(p[2], 1e-16) for p in points]
        by_time.loglog([p[0] for p in points], errors, marker=marker, color=color, label=name)
        by_evals.loglog([p[1] for p in points], errors, marker=marker, color=color, label=name)
    by_time.set_xlabel("wall time per simulated second [s]")
    by_evals.set_xlabel("force evaluations per simulated second")
    by_time.set_ylabel("relative error at the end time")
    for ax in (by_time, by_evals):
        ax.grid(True, which="major", alpha=0.4)
    by_evals.legend(loc="lower left", fontsize="small")
    fig.suptitle(f"work-precision: {problem} (stable runs only; lower left is better)")
    return fig


def draw_methods(plt, rows):
    scenes = list(dict.fromkeys(row["scene"] for row in rows))

    fig, axes = plt.subplots(2, len(scenes), figsize=(5.2 * len(scenes), 8.2), squeeze=False)
    for col, scene in enumerate(scenes):
        by_error, by_strain = axes[0][col], axes[1][col]
        lines = {}
        for row in rows:
            if row["scene"] != scene:
                continue
            if row["method"] == "reference":
                by_error.axhline(float(row["error"]), color="gray", ls="--",
                                 label="reference vs itself at dt/2")
                by_strain.axhline(float(row["worst_strain"]), color="gray", ls="--",
                                  label="reference")
                continue
            if row["stable"] != "true":
                continue
            lines.setdefault(line_name(row), []).append(
                (float(row["wall_s_per_sim_s"]), float(row["error"]), float(row["worst_strain"])))
        for name, points in lines.items():
            points.sort()
            color, marker = METHODS_STYLE.get(name, ("black", "x"))
            walls = [p[0] for p in points]
            by_error.loglog(walls, [max(p[1], 1e-16) for p in points], marker=marker,
                            color=color, label=name)
            by_strain.loglog(walls, [max(p[2], 1e-16) for p in points], marker=marker,
                             color=color, label=name)
        by_error.set_title(scene)
        by_strain.set_xlabel("wall time per simulated second [s]")
        for ax in (by_error, by_strain):
            ax.grid(True, which="major", alpha=0.4)
    axes[0][0].set_ylabel("error: RMS distance from the reference / cloth size")
    axes[1][0].set_ylabel("worst spring strain |l - l0| / l0")
    axes[0][0].legend(loc="lower left", fontsize="small")
    fig.suptitle("bench methods: error and stretch against cost (stable runs only)")
    return fig


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    csv_path, out_path = sys.argv[1], sys.argv[2]
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    columns = set(rows[0].keys() if rows else [])
    if ACCURACY_COLUMNS <= columns:
        draw = draw_accuracy
    elif METHODS_COLUMNS <= columns:
        draw = draw_methods
    else:
        sys.exit(f"{csv_path}: not a CSV of `clothlab bench accuracy` or `bench methods`")
    try:
        import matplotlib
    except ImportError:
        sys.exit("the plot needs matplotlib: sudo apt-get install -y python3-matplotlib")
    matplotlib.use("Agg")
    matplotlib.rcParams["svg.hashsalt"] = "clothlab"  # the same data gives the same file
    import matplotlib.pyplot as plt

    fig = draw(plt, rows)
    fig.tight_layout()
    fig.savefig(out_path, metadata={"Date": None} if out_path.endswith(".svg") else None)
    print(f"  plot: {out_path}")


if __name__ == "__main__":
    main()
