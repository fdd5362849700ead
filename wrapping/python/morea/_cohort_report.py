# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""A cohort's report: the table of registrations, the summary of scores per
registration, solution and structure, and plots of the scores before (rigid
pre-alignment) and after MOREA per structure. Used by morea.cohort."""
import csv
import io
import json
import os

from ._cohort_table import SUMMARY

REGISTRATION_COLUMNS = ("id", "status", "error", "output", "seed", "backend", "gpu", "device", "worker", "host",
                        "seconds", "seconds_command", "seconds_optimisation", "front_size", "generations",
                        "resumed_at_generation", "log")
SCORE_COLUMNS = ("dice", "hausdorff_mm", "hausdorff95_mm", "mean_surface_distance_mm")
SUMMARY_COLUMNS = (("id", "status", "solution", "structure") + SCORE_COLUMNS +
                   ("landmark_tre_mean_mm", "jacobian_nonpositive_fraction", "magnitude", "intensity", "guidance",
                    "seed", "backend", "gpu", "device", "worker", "seconds", "seconds_command",
                    "seconds_optimisation", "front_size", "resumed_at_generation", "error", "output"))
BASELINE = "rigid_baseline"


def write_text(path, text):
    """Writes `path` whole: a temporary name, then a rename."""
    temporary = os.path.join(os.path.dirname(path) or ".", f".{os.path.basename(path)}.tmp{os.getpid()}")
    with open(temporary, "w", newline="") as f:
        f.write(text)
    os.replace(temporary, path)


def csv_text(columns, rows):
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=list(columns), extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: _cell(row.get(k, "")) for k in columns})
    return out.getvalue()


def _cell(value):
    if isinstance(value, float):
        return f"{value:.6g}"
    return value


def summary_rows(records):
    """One row per registration, solution (the rigid baseline first) and
    structure, with the registration's times, backend and GPU; a failed
    registration is one row with its error."""
    rows = []
    for record in records:
        common = {k: record.get(k, "") for k in SUMMARY_COLUMNS if k in record}
        summary_path = os.path.join(record.get("output", ""), SUMMARY)
        if record.get("status") == "failed" or not os.path.isfile(summary_path):
            rows.append({**common, "solution": "", "structure": ""})
            continue
        with open(summary_path) as f:
            summary = json.load(f)
        solutions = [(BASELINE, summary.get(BASELINE, {}), {})]
        for label, entry in summary.get("solutions", {}).items():
            solutions.append((label, entry.get("scores", {}), entry))
        for label, scores, entry in solutions:
            per_solution = {"solution": label, "jacobian_nonpositive_fraction": scores.get(
                "jacobian_nonpositive_fraction", ""), "landmark_tre_mean_mm": scores.get("landmarks", {}).get(
                "tre_mean_mm", ""), **{k: entry.get(k, "") for k in ("magnitude", "intensity", "guidance")}}
            structures = scores.get("structures", {})
            if not structures:
                rows.append({**common, **per_solution, "structure": ""})
            for name, values in structures.items():
                rows.append({**common, **per_solution, "structure": name,
                             **{k: values.get(k, "") for k in SCORE_COLUMNS}})
    return rows


def plot_scores(rows, folder):
    """Per score (Dice, HD95): one panel per structure with the cohort's
    values for the rigid baseline and each solution label, as box plots
    with the values on top. Returns the PNG paths written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [r for r in rows if r.get("solution") and r.get("structure") and r.get("dice", "") != ""]
    if not done:
        return []
    structures = sorted({r["structure"] for r in done})
    labels = [BASELINE] + sorted({r["solution"] for r in done} - {BASELINE})
    registrations = len({r["id"] for r in done})
    os.makedirs(folder, exist_ok=True)
    written = []
    for score, title in (("dice", "Dice"), ("hausdorff95_mm", "95th-percentile Hausdorff distance (mm)")):
        columns = min(4, len(structures))
        lines = (len(structures) + columns - 1) // columns
        figure, axes = plt.subplots(lines, columns, figsize=(3.6 * columns, 3.4 * lines), squeeze=False)
        for k, structure in enumerate(structures):
            ax = axes[k // columns][k % columns]
            values = [[float(r[score]) for r in done if r["structure"] == structure and r["solution"] == label]
                      for label in labels]
            ax.boxplot([v if v else [float("nan")] for v in values], widths=0.5, showfliers=False)
            for i, v in enumerate(values, start=1):
                ax.scatter([i] * len(v), v, s=12, color=f"C{i - 1}", alpha=0.8, zorder=3)
            ax.set_xticks(range(1, len(labels) + 1))
            ax.set_xticklabels(["before (rigid)" if lb == BASELINE else lb for lb in labels], rotation=20,
                               fontsize=8)
            ax.set_title(structure)
            if score == "dice":
                ax.set_ylim(0, 1.02)
        for k in range(len(structures), lines * columns):
            axes[k // columns][k % columns].axis("off")
        figure.suptitle(f"{title}: before and after, {registrations} registrations")
        figure.tight_layout()
        path = os.path.join(folder, f"{score.replace('_mm', '')}.png")
        temporary = os.path.join(folder, f".{os.path.basename(path)}.tmp{os.getpid()}.png")
        figure.savefig(temporary, dpi=90)
        plt.close(figure)
        os.replace(temporary, path)
        written.append(path)
    return written


def write_report(folder, records, plots=True):
    """registrations.csv (one row per registration) and cohort_summary.csv
    (per registration, solution and structure), and the plots unless
    `plots` is False. Returns {name: path}."""
    os.makedirs(folder, exist_ok=True)
    paths = {"registrations": os.path.join(folder, "registrations.csv"),
             "summary": os.path.join(folder, "cohort_summary.csv")}
    write_text(paths["registrations"], csv_text(REGISTRATION_COLUMNS, records))
    rows = summary_rows(records)
    write_text(paths["summary"], csv_text(SUMMARY_COLUMNS, rows))
    if plots:
        for path in plot_scores(rows, os.path.join(folder, "plots")):
            paths[os.path.splitext(os.path.basename(path))[0]] = path
    return paths
