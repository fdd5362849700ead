# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Tables (CSV, Markdown), Mann-Whitney U tests, plots and renders of a study."""
from __future__ import annotations

import csv
import itertools
import math
import platform
from pathlib import Path

import numpy as np

from . import evaluation

METHOD_LABEL = {"morea": "MOREA", "elastix": "elastix", "ants": "ANTs SyN",
                "rigid baseline": "rigid baseline"}
KIND_ORDER = ("bone", "wall", "organ", "soft")


def method_label(key: str) -> str:
    """A chosen-configuration key: a method, or "morea:<configuration>"."""
    if key.startswith("morea:"):
        return f"MOREA ({key.split(':', 1)[1].replace('-', ' ')})"
    return METHOD_LABEL.get(key, key)


def method_keys(chosen: dict) -> list[str]:
    """The chosen configurations in table order: MOREA's first, then elastix, ANTs."""
    return sorted(chosen, key=lambda k: (0 if k == "morea" else 1 if k.startswith("morea:")
                                         else 2 if k == "elastix" else 3, k))


def _fmt(v, digits=3):
    if v is None or v == "":
        return ""
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if v != 0 and abs(v) < 1e-3:
            return f"{v:.1e}"
        return f"{v:.{digits}f}"
    return str(v)


def write_csv(path: Path, rows: list[dict]) -> None:
    cols = []
    for r in rows:
        for k in r:
            if k not in cols:
                cols.append(k)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow(r)


def score_columns(rows: list[dict], pair) -> list[str]:
    structures = sorted({k.split(":", 1)[1] for r in rows for k in r if k.startswith("dice:")},
                        key=lambda s: (s != pair.primary_structure, s))
    cols = []
    for s in structures:
        if pair.landmarks_by_kind:
            # Phantom suite: the body outline never changes; HD (the maximum) is in results.csv.
            if s != "body":
                cols += [f"dice:{s}", f"hd95:{s}"]
        else:
            cols += [f"dice:{s}", f"hd95:{s}", f"hd:{s}"]
    kinds = sorted({k.split(":", 1)[1] for r in rows for k in r if k.startswith("tre_mean_mm:")},
                   key=lambda k: (KIND_ORDER.index(k) if k in KIND_ORDER else 99, k))
    cols[0:0] = [f"tre_mean_mm:{k}" for k in kinds]
    if any("tre_mean_mm" in r for r in rows):
        cols.insert(0, "tre_mean_mm")
    cols += ["jacobian_nonpositive_fraction", "ic_mean_mm", "seconds"]
    return cols


def column_label(c: str) -> str:
    if c.startswith("tre_mean_mm:"):
        return f"{c.split(':', 1)[1]} TRE mm"
    if ":" in c:
        kind, s = c.split(":", 1)
        return f"{s} {'Dice' if kind == 'dice' else kind.upper() + ' mm'}"
    return {"tre_mean_mm": "TRE mean mm", "jacobian_nonpositive_fraction": "Jacobian <= 0",
            "ic_mean_mm": "inverse consistency mm", "seconds": "time s"}.get(c, c)


def mann_whitney(chosen: dict, pair) -> list[dict]:
    from scipy.stats import mannwhitneyu
    out = []
    if "morea" not in chosen:
        return out
    morea_rows = chosen["morea"][1]
    for comp in ("elastix", "ants"):
        if comp not in chosen:
            continue
        for crit in pair.criteria:
            a = [r[crit.column] for r in morea_rows if r.get(crit.column) is not None]
            b = [r[crit.column] for r in chosen[comp][1] if r.get(crit.column) is not None]
            if not a or not b:
                continue
            if len(set(a + b)) == 1:
                p = 1.0
            else:
                p = float(mannwhitneyu(a, b, alternative="two-sided").pvalue)
            ma, mb = float(np.median(a)), float(np.median(b))
            better = (ma > mb) if crit.higher_is_better else (ma < mb)
            out.append({"comparison": f"MOREA vs {METHOD_LABEL[comp]} ({chosen[comp][0]})",
                        "score": crit.label, "n_morea": len(a), "n_other": len(b),
                        "median_morea": ma, "median_other": mb, "p_value": p,
                        "significant_at_0.025": p < 0.025,
                        "direction": ("MOREA better" if better else
                                      ("equal medians" if ma == mb else "MOREA worse"))})
    return out


def summary_rows(chosen: dict, baseline: dict | None, cols: list[str]) -> list[dict]:
    rows = []
    if baseline:
        rows.append({"method": "rigid baseline", "config": "", "n": 1,
                     **{c: baseline.get(c) for c in cols}})
    for m in method_keys(chosen):
        cfg, rs = chosen[m]
        row = {"method": method_label(m), "config": cfg, "n": len(rs)}
        for c in cols:
            vals = [r[c] for r in rs if r.get(c) is not None]
            if vals:
                row[c] = float(np.median(vals))
                row[c + " (min-max)"] = (float(np.min(vals)), float(np.max(vals)))
        rows.append(row)
    return rows


def markdown_table(header: list[str], rows: list[list]) -> str:
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join("---" for _ in header) + " |"]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(v) for v in r) + " |")
    return "\n".join(lines)


def parallel_coordinates(path: Path, chosen: dict, baseline: dict | None, pair,
                         rows_all: list[dict]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cols = [c for c in score_columns(rows_all, pair)
            if c.startswith(("dice:", "hd95:")) or c == "tre_mean_mm"]
    if not cols:
        return
    series = []
    colors = {"morea": "tab:red", "elastix": "tab:blue", "ants": "tab:green", "rigid baseline": "tab:gray"}
    for m in method_keys(chosen):
        cfg, rs = chosen[m]
        for r in rs:
            series.append((m, [r.get(c, np.nan) for c in cols]))
    if baseline:
        series.append(("rigid baseline", [baseline.get(c, np.nan) for c in cols]))
    data = np.array([s[1] for s in series], dtype=float)
    lo, hi = np.nanmin(data, axis=0), np.nanmax(data, axis=0)
    span = np.where(hi - lo > 1e-12, hi - lo, 1.0)
    norm = (data - lo) / span
    # Dice: higher is better; distances: lower is better -> flip so "up" is better.
    for j, c in enumerate(cols):
        if not c.startswith("dice:"):
            norm[:, j] = 1.0 - norm[:, j]
    # Side rows (other configurations, knees) get colours of their own, in
    # the order they come; knees are dotted, the baseline dashed.
    others = itertools.cycle(["tab:orange", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan"])
    for m, _ in series:
        if m not in colors:
            colors[m] = next(others)
    fig, ax = plt.subplots(figsize=(1.6 * len(cols) + 2, 3.6), dpi=80)
    seen = set()
    for (m, _), y in zip(series, norm):
        label = method_label(m)
        style = "--" if m == "rigid baseline" else (":" if m.endswith("knee") else "-")
        ax.plot(range(len(cols)), y, color=colors[m], ls=style, alpha=0.8, marker="o", ms=3,
                label=None if label in seen else label)
        seen.add(label)
    ax.set_xticks(range(len(cols)))
    ax.set_xticklabels([f"{column_label(c)}\n[{_fmt(lo[j], 2)}, {_fmt(hi[j], 2)}]"
                        for j, c in enumerate(cols)], fontsize=7)
    ax.set_yticks([0, 1])
    ax.set_yticklabels(["worst", "best"], fontsize=7)
    ax.set_title(f"{pair.name}: chosen configurations, all seeds (axes scaled to their range)",
                 fontsize=8)
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def renders(study, chosen: dict) -> dict:
    """`morea evaluate --render` of seed 1 (or the first seed) of each chosen
    configuration and of the baseline."""
    out = {}
    rdir = study.out / "renders"
    rdir.mkdir(exist_ok=True)
    focus = study.pair.primary_structure
    base_prefix = rdir / "baseline"
    if not (rdir / "baseline_coronal.png").exists():
        evaluation.evaluate(study.morea, study.problem, rdir / "baseline.json",
                            render=base_prefix, focus=focus)
    out["rigid baseline"] = base_prefix
    for m in method_keys(chosen):
        cfg, rs = chosen[m]
        method = m.split(":", 1)[0]
        seed = min(r["seed"] for r in rs)
        d = study.config_dir(method, cfg, seed)
        # MOREA runs made on a GPU (bench/run-study-morea.sh) bring their renders
        # under this name instead of their fields.
        prefix = rdir / f"{method}_{cfg}_seed{seed}"
        if not Path(str(prefix) + "_coronal.png").exists():
            if not (d / "fixed_to_moving.nii.gz").exists():
                study.say(f"renders: {d.relative_to(study.out)} has neither fields nor renders")
                continue
            evaluation.evaluate(study.morea, study.problem, rdir / f"{method}.json",
                                d / "fixed_to_moving.nii.gz", d / "moving_to_fixed.nii.gz",
                                render=prefix, focus=focus)
        out[m] = prefix
    return out


def render_montage(path: Path, rend: dict) -> None:
    """One PNG: rows axial / coronal / sagittal, a column per method (fixed
    contours and warped moving contours as `morea evaluate --render` draws them)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt
    order = ["rigid baseline"] if "rigid baseline" in rend else []
    order += method_keys({k: None for k in rend if k != "rigid baseline"})
    views = ("axial", "coronal", "sagittal")
    fig, axes = plt.subplots(len(views), len(order), figsize=(2.2 * len(order), 6.2), dpi=90,
                             squeeze=False)
    for j, k in enumerate(order):
        for i, v in enumerate(views):
            ax = axes[i][j]
            p = Path(f"{rend[k]}_{v}.png")
            if p.exists():
                ax.imshow(mpimg.imread(str(p)), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if i == 0:
                ax.set_title(f"{method_label(k)}\n{Path(str(rend[k])).name}", fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


# The abdominal pair at the paper's budgets: the scores on which MOREA's chosen
# solution must be at least as good as the best per-pair-tuned competitor.
ABDOMEN_SCORES = [("dice:Stomach_duo_CBCT", True, "stomach Dice"),
                  ("hd95:Stomach_duo_CBCT", False, "stomach HD95"),
                  ("dice:Bowel_sm_CBCT", True, "bowel Dice"),
                  ("hd95:Bowel_sm_CBCT", False, "bowel HD95")]


def acceptance(pair, chosen: dict) -> list[dict]:
    """The acceptance checks of issue 48 on the medians over seeds. The phantom
    suite: MOREA's mean TRE <= ANTs SyN's + 0.2 mm; bladder Dice >= ANTs SyN's;
    bone TRE <= 0.5 mm with and without bones guiding (every seed). The
    abdominal pair at the paper's budgets: stomach and bowel Dice and HD95 at
    least as good as the better competitor's. Both: no voxel with Jacobian
    determinant <= 0 (every MOREA run)."""
    if "morea" not in chosen or not (pair.phantom_case or (pair.morea_on_gpu and pair.data_pair == "abdomen")):
        return []
    checks = []

    def values(key, col):
        return [r[col] for r in chosen[key][1] if r.get(col) is not None] if key in chosen else []

    def med(key, col):
        v = values(key, col)
        return float(np.median(v)) if v else None

    if not pair.phantom_case:
        for col, higher, label in ABDOMEN_SCORES:
            m = med("morea", col)
            rivals = [(med(k, col), k) for k in ("elastix", "ants") if med(k, col) is not None]
            if m is None or not rivals:
                continue
            ref, key = max(rivals) if higher else min(rivals)
            checks.append({"check": f"{label} {'>=' if higher else '<='} the better competitor "
                                    f"({method_label(key)})",
                           "MOREA": m, "reference": ref, "passed": m >= ref if higher else m <= ref})
        j = values("morea", "jacobian_nonpositive_fraction")
        if j:
            checks.append({"check": "no voxel with Jacobian <= 0, worst seed", "MOREA": float(np.max(j)),
                           "reference": 0.0, "passed": float(np.max(j)) == 0.0})
        return checks

    m_tre, a_tre = med("morea", "tre_mean_mm"), med("ants", "tre_mean_mm")
    if m_tre is not None and a_tre is not None:
        checks.append({"check": "mean TRE (all landmarks) <= ANTs SyN + 0.2 mm",
                       "MOREA": m_tre, "reference": a_tre + 0.2,
                       "passed": m_tre <= a_tre + 0.2})
    m_d, a_d = med("morea", "dice:bladder"), med("ants", "dice:bladder")
    if m_d is not None and a_d is not None:
        checks.append({"check": "bladder Dice >= ANTs SyN", "MOREA": m_d, "reference": a_d,
                       "passed": m_d >= a_d})
    # The chosen solutions' checks; knees are side rows.
    for key in [k for k in method_keys(chosen) if k.startswith("morea") and not k.endswith("knee")]:
        v = values(key, "tre_mean_mm:bone")
        if v:
            checks.append({"check": f"bone TRE <= 0.5 mm, {method_label(key)}, worst seed",
                           "MOREA": float(np.max(v)), "reference": 0.5,
                           "passed": float(np.max(v)) <= 0.5})
        j = values(key, "jacobian_nonpositive_fraction")
        if j:
            checks.append({"check": f"no voxel with Jacobian <= 0, {method_label(key)}, worst seed",
                           "MOREA": float(np.max(j)), "reference": 0.0,
                           "passed": float(np.max(j)) == 0.0})
    return checks


def profile_lines(study) -> list[str]:
    st = study.settings
    e, a = st.get("elastix", {}), st.get("ants", {})
    lines = [f"Competitors' budget profile: **{study.profile_name}**."]
    if e:
        lines.append(f"- elastix: {e.get('iterations')} iterations per resolution (4 resolutions, "
                     f"mask step and image step), {e.get('spatial_samples')} random samples, "
                     f"final B-spline grid {e.get('grid_spacing')} mm, step-size estimation "
                     f"{e.get('parameter_estimation')}; weights {e.get('weights')}.")
    if a:
        lines.append(f"- ANTs SyN: iterations {'x'.join(str(i) for i in a.get('iterations', ()))} "
                     f"(caps; convergence window 10, threshold 1e-6), CC radius "
                     f"{a.get('cc_radius')} voxels, gradient step 1.0, update regularisation "
                     f"4.0; total regularisation {a.get('weights')}.")
    return lines


def write_all(study, rows: list[dict], chosen: dict) -> None:
    pair = study.pair
    out = study.out
    write_csv(out / "results.csv", rows)
    baseline = next((r for r in rows if r["method"] == "rigid baseline"), None)
    cols = score_columns(rows, pair)
    summ = summary_rows(chosen, baseline, cols)
    write_csv(out / "summary.csv", [{k: (f"{v[0]}..{v[1]}" if isinstance(v, tuple) else v)
                                     for k, v in r.items()} for r in summ])
    tests = mann_whitney(chosen, pair)
    write_csv(out / "tests.csv", tests)
    conv = study.convergence()
    write_csv(out / "convergence.csv", conv)
    checks = acceptance(pair, chosen)
    write_csv(out / "acceptance.csv", checks)
    parallel_coordinates(out / "parallel_coordinates.png", chosen, baseline, pair, rows)
    try:
        rend = renders(study, chosen)
        render_montage(out / "renders.png", rend)
    except Exception as exc:
        rend = {}
        study.say(f"renders failed: {exc}")

    md = [f"# Comparison study: {pair.description}", ""]
    md.append(f"Machine: {platform.node() or 'unknown'} ({platform.machine()}), "
              f"{study.args.threads} threads per run; mode: {'quick' if study.args.quick else 'full'}.")
    md.append(f"Problem: `{study.problem}` (preprocessed with `{pair.morea_parameters.name}`); "
              f"every method scored by `morea evaluate` on it.")
    md += profile_lines(study)
    hosts = sorted({str(common_host(study, r)) for r in rows if r.get("method") == "morea"} - {"None"})
    if hosts:
        md.append(f"MOREA ran on: {', '.join(hosts)}.")
    md.append("")
    md.append("## Chosen configurations (median over seeds; min-max in summary.csv)")
    header = ["method", "config", "n"] + [column_label(c) for c in cols]
    md.append(markdown_table(header, [[r.get("method"), r.get("config"), r.get("n")] +
                                      [r.get(c) for c in cols] for r in summ]))
    md.append("")
    md.append("## Mann-Whitney U, two-sided (Bonferroni alpha 0.025)")
    md.append(markdown_table(["comparison", "score", "median MOREA", "median other", "p",
                              "p < 0.025", "direction"],
                             [[t["comparison"], t["score"], t["median_morea"], t["median_other"],
                               t["p_value"], "yes" if t["significant_at_0.025"] else "no",
                               t["direction"]] for t in tests]))
    md.append("")
    if checks:
        md.append("## Acceptance (issue 48; medians over seeds unless stated)")
        md.append(markdown_table(["check", "MOREA", "reference", "passed"],
                                 [[c["check"], c["MOREA"], c["reference"],
                                   "yes" if c["passed"] else "NO"] for c in checks]))
        md.append("")
    if conv:
        md.append(f"## Convergence check (best configuration, seed 1, twice the iterations, "
                  f"doubled again while not converged; converged: |change| of "
                  f"{pair.criteria[0].label} < 1 %)")
        md.append(markdown_table(
            ["method", "config", "iterations", "used", "score", "iterations x2", "used x2",
             "score x2", "relative change", "converged", "time s", "time x2 s"],
            [[METHOD_LABEL[c["method"]], c["config"], _iters(c["iterations"]),
              _iters(c["iterations_used"]), c["score_at_budget"], _iters(c["iterations_doubled"]),
              _iters(c["iterations_used_doubled"]), c["score_doubled"],
              (None if c["relative_change"] is None else f"{100 * c['relative_change']:.2f} %"),
              "yes" if c["converged"] else "NO", c["seconds"], c["seconds_doubled"]]
             for c in conv]))
        md.append("")
    md.append("## Regularisation sweep (seed 1)")
    sweep = [r for r in rows if r["method"] in ("elastix", "ants") and r.get("seed") == 1
             and "-x" not in str(r.get("config"))]
    md.append(markdown_table(["method", "config"] + [column_label(c) for c in cols],
                             [[METHOD_LABEL[r["method"]], r["config"]] +
                              [("FAILED" if r.get("failed") else r.get(c)) for c in cols]
                              for r in sorted(sweep, key=lambda r: (r["method"], r["config"]))]))
    md.append("")
    md.append("## All runs: results.csv. Renders: " +
              ", ".join(f"{method_label(k)} `{Path(v).name}_*.png`" for k, v in rend.items()))
    (out / "report.md").write_text("\n".join(md) + "\n")


def _iters(v):
    if v is None:
        return ""
    if isinstance(v, (list, tuple)):
        return "x".join(str(i) for i in v)
    return str(v)


def common_host(study, row):
    d = study.config_dir("morea", row["config"], row["seed"]) if row.get("seed") else None
    if d is None or not (d / "run.json").exists():
        return None
    import json
    rec = json.loads((d / "run.json").read_text())
    return rec.get("host") or (f"this machine ({rec.get('backend')})" if rec.get("backend") else None)
