#!/usr/bin/env python3
"""Draws the work-precision plot of `clothlab bench accuracy` from its CSV.

    python3 plot_accuracy.py accuracy.csv work-precision.svg

Two panels, both log-log, one line per integrator, only the runs that stayed stable: the error
at the end time against the wall time per simulated second (what it costs on this machine), and
against the force evaluations per simulated second (what it costs on any machine). Along a line
the step shrinks from left to right: the cost grows, the error falls, and the slope is minus the
method's order. The output format follows the file's extension (.svg, .png, .pdf).
"""
import csv
import sys

STYLE = {
    "explicit-euler": ("tab:red", "o"),
    "symplectic-euler": ("tab:orange", "s"),
    "midpoint": ("tab:green", "^"),
    "rk4": ("tab:blue", "D"),
    "velocity-verlet": ("tab:purple", "v"),
    "position-verlet": ("tab:pink", "<"),
    "implicit-euler": ("tab:brown", "P"),
}


def read_runs(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    expected = {"problem", "integrator", "dt", "steps", "error", "wall_s_per_sim_s",
                "force_evals_per_sim_s", "stable"}
    missing = expected - set(rows[0].keys() if rows else [])
    if missing:
        sys.exit(f"{path}: not a `clothlab bench accuracy` CSV (missing {sorted(missing)})")
    return rows


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    csv_path, out_path = sys.argv[1], sys.argv[2]
    try:
        import matplotlib
    except ImportError:
        sys.exit("the plot needs matplotlib: sudo apt-get install -y python3-matplotlib")
    matplotlib.use("Agg")
    matplotlib.rcParams["svg.hashsalt"] = "clothlab"  # the same data gives the same file
    import matplotlib.pyplot as plt

    rows = read_runs(csv_path)
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
        color, marker = STYLE.get(name, ("black", "x"))
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
    fig.tight_layout()
    fig.savefig(out_path, metadata={"Date": None} if out_path.endswith(".svg") else None)
    print(f"  plot: {out_path}")


if __name__ == "__main__":
    main()
