# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The comparison study on one pair: MOREA against elastix and ANTs SyN.

    python3 -m study run --pair lung|abdomen|phantom --out DIR [--quick]
    python3 -m study report --pair ... --out DIR        (tables and plots again)
    python3 -m study rescore --pair ... --out DIR       (scores again, then report)

Steps (each run is skipped when its scores.json exists, so a killed study resumes):
 1. `morea preprocess` with the MOREA parameter file of the pair -> DIR/problem,
    the problem every method registers and is scored on; the rigid baseline.
 2. Sweep: elastix over its regularisation weights, ANTs over its total
    regularisation, with seed 1 (--sweep-seeds more).
 3. Best configuration per competitor: the best seed-1 value of the pair's
    first criterion on the most-deforming structure (the paper's approach).
 4. Repeats: the best configurations and MOREA with seeds 1..--seeds.
 5. results.csv (every run), tables (CSV, Markdown), two-sided Mann-Whitney U
    tests of MOREA against each competitor (Bonferroni: alpha 0.05 / 2 = 0.025),
    a parallel-coordinates plot and renders of seed 1 of each method.

`rescore` runs only `morea evaluate` again (after a change of its metrics) on the
baseline and on every finished run that still has both fields, replacing their
scores.json; nothing is registered again, and the run times stay those of run.json.
"""
from __future__ import annotations

import argparse
import math
import time
import traceback
from pathlib import Path

from . import common, evaluation, pairs

WEIGHTS = [0.0, 0.001, 0.01, 0.1, 1.0, 10.0]

# Compute-budget settings (the paper's values are in the runners' PAPER_* constants).
FULL = {
    "seeds": 5,
    "elastix": {"weights": WEIGHTS, "iterations": 100, "spatial_samples": 2000,
                "grid_spacing": 6.0, "parameter_estimation": "DisplacementDistribution"},
    # CC radius 4 voxels of 3 mm = 12 mm, the paper's 8 voxels of 1.5 mm.
    "ants": {"weights": WEIGHTS, "iterations": (100, 50, 25, 0), "cc_radius": 4},
}
QUICK = {
    "seeds": 1,
    "elastix": {"weights": [0.01, 1.0], "iterations": 20, "spatial_samples": 1000,
                "grid_spacing": 12.0, "parameter_estimation": "DisplacementDistribution"},
    "ants": {"weights": [0.0, 3.0], "iterations": (10, 5, 2, 0), "cc_radius": 2},
}
ALPHA = 0.025


def config_name(method: str, weight: float | None) -> str:
    if method == "morea":
        return "default"
    return f"w{weight:g}"


class Study:
    def __init__(self, args):
        self.args = args
        self.out = Path(args.out).resolve()
        self.out.mkdir(parents=True, exist_ok=True)
        self.settings = QUICK if args.quick else FULL
        if args.seeds:
            self.settings = dict(self.settings, seeds=args.seeds)
        self.morea = common.find_morea(args.morea)
        self.pair = pairs.make(args.pair, args.quick)
        self.problem = self.out / "problem"
        self.methods = [m for m in ("morea", "elastix", "ants") if m not in (args.skip or [])]
        self.log = self.out / "logs" / "study.log"
        self.log.parent.mkdir(parents=True, exist_ok=True)

    def say(self, msg: str) -> None:
        line = time.strftime("%H:%M:%S ") + msg
        print(line, flush=True)
        with open(self.log, "a") as f:
            f.write(line + "\n")

    # -- 1 ------------------------------------------------------------------
    def prepare(self) -> None:
        pairs.resolve(self.pair, pairs.data_dir(self.args.data), self.out, self.morea)
        if not (self.problem / "preprocess.json").exists():
            self.say(f"preprocessing {self.pair.name}")
            common.run_command([self.morea, "preprocess", *self.pair.raw_args, "--parameters",
                                self.pair.morea_parameters, "-o", self.problem],
                               self.out / "logs" / "preprocess.log")
        base = self.out / "baseline"
        base.mkdir(exist_ok=True)
        if not (base / "scores.json").exists():
            evaluation.evaluate(self.morea, self.problem, base / "scores.json")

    # -- one run --------------------------------------------------------------
    def run_dir(self, method: str, weight, seed: int) -> Path:
        return self.out / "runs" / method / config_name(method, weight) / f"seed{seed}"

    def run_one(self, method: str, weight, seed: int) -> dict | None:
        d = self.run_dir(method, weight, seed)
        scores_path = d / "scores.json"
        if scores_path.exists():
            return common.read_json(scores_path)
        if (d / "failed.json").exists() and not self.args.retry_failed:
            return None
        d.mkdir(parents=True, exist_ok=True)
        self.say(f"{method} {config_name(method, weight)} seed {seed}")
        threads = self.args.threads
        try:
            if method == "elastix":
                from . import elastix_runner
                e = self.settings["elastix"]
                rec = elastix_runner.run(self.problem, d, weight, seed, e["iterations"],
                                         e["grid_spacing"], e["spatial_samples"], threads, True,
                                         e["parameter_estimation"])
            elif method == "ants":
                from . import ants_runner
                a = self.settings["ants"]
                rec = ants_runner.run(self.problem, d, weight, seed, a["iterations"],
                                      cc_radius=a["cc_radius"], threads=threads)
            else:
                from . import morea_runner
                rec = morea_runner.run(self.morea, self.pair.raw_args, self.pair.morea_parameters,
                                       self.problem, d, seed, threads)
            scores = evaluation.evaluate(self.morea, self.problem, d / "scores.tmp.json",
                                         d / "fixed_to_moving.nii.gz",
                                         d / "moving_to_fixed.nii.gz")
            (d / "scores.tmp.json").replace(scores_path)
            self.say(f"  {rec['seconds']['registration']:.1f} s")
            return scores
        except Exception as exc:  # a failed run is reported, not fatal
            self.say(f"  FAILED: {exc}")
            common.write_json(d / "failed.json", {"error": str(exc),
                                                  "traceback": traceback.format_exc()})
            return None

    # -- 2-4 ------------------------------------------------------------------
    def sweep_and_repeat(self) -> None:
        seeds = list(range(1, self.settings["seeds"] + 1))
        sweep_seeds = list(range(1, (self.args.sweep_seeds or 1) + 1))
        competitors = [m for m in ("elastix", "ants") if m in self.methods]
        for m in competitors:
            for w in self.settings[m]["weights"]:
                for s in sweep_seeds:
                    self.run_one(m, w, s)
        for m in competitors:
            best = self.best_weight(m)
            if best is None:
                continue
            for s in seeds:
                self.run_one(m, best, s)
        if "morea" in self.methods:
            for s in seeds:
                self.run_one("morea", None, s)

    def best_weight(self, method: str):
        crit = self.pair.criteria[0]
        best, best_val = None, None
        for w in self.settings[method]["weights"]:
            p = self.run_dir(method, w, 1) / "scores.json"
            if not p.exists():
                continue
            v = evaluation.flatten(common.read_json(p)).get(crit.column)
            if v is None or (isinstance(v, float) and math.isnan(v)):
                continue
            if best_val is None or (v > best_val if crit.higher_is_better else v < best_val):
                best, best_val = w, v
        return best

    # -- rescore ---------------------------------------------------------------
    def rescore(self) -> dict:
        """Scores the baseline and every run directory with scores.json and both
        fields again with the current `morea evaluate`, with the border margin the
        old scores were computed with; registers nothing (failed runs and run.json,
        hence the run times, are left as they are). Returns {column kind: largest
        absolute change} over all rescored rows (kind: "dice", "hd95", ...,
        "tre_mean_mm", ...), and logs it."""
        targets = []
        if (self.out / "baseline" / "scores.json").exists():
            targets.append((self.out / "baseline", None, None))
        for scores in sorted((self.out / "runs").glob("*/*/seed*/scores.json")):
            d = scores.parent
            f, g = d / "fixed_to_moving.nii.gz", d / "moving_to_fixed.nii.gz"
            if f.exists() and g.exists():
                targets.append((d, f, g))
            else:
                self.say(f"rescore: {d.relative_to(self.out)} has no fields; its scores are kept")
        changes: dict[str, float] = {}
        for d, f, g in targets:
            old = common.read_json(d / "scores.json")
            new = evaluation.evaluate(self.morea, self.problem, d / "rescore.json", f, g,
                                      border_margin=old.get("border_margin_mm"))
            (d / "rescore.json").replace(d / "scores.json")
            old_row, new_row = evaluation.flatten(old), evaluation.flatten(new)
            for k in sorted(set(old_row) | set(new_row)):
                kind = k.split(":", 1)[0]
                a, b = old_row.get(k), new_row.get(k)
                if a is None and b is None:
                    delta = 0.0
                elif a is None or b is None:
                    delta = math.inf
                elif math.isnan(a) or math.isnan(b):
                    delta = 0.0 if math.isnan(a) and math.isnan(b) else math.inf
                else:
                    delta = abs(b - a)
                changes[kind] = max(changes.get(kind, 0.0), delta)
        changed = {k: v for k, v in changes.items() if v > 1e-9}   # not summation noise
        self.say(f"rescored {len(targets)} results with {self.morea}; changed: "
                 + (", ".join(f"{k} (up to {v:.4g})" for k, v in sorted(changed.items()))
                    or "nothing")
                 + "; unchanged: " + (", ".join(sorted(set(changes) - set(changed))) or "-"))
        return changes

    # -- 5 ------------------------------------------------------------------
    def collect(self) -> list[dict]:
        rows = []
        base = self.out / "baseline" / "scores.json"
        if base.exists():
            rows.append({"pair": self.pair.name, "method": "rigid baseline", "config": "",
                         "seed": "", "seconds": None, **evaluation.flatten(common.read_json(base))})
        runs = self.out / "runs"
        if runs.exists():
            for scores in sorted(runs.glob("*/*/seed*/scores.json")):
                d = scores.parent
                rec = common.read_json(d / "run.json") if (d / "run.json").exists() else {}
                rows.append({"pair": self.pair.name, "method": d.parent.parent.name,
                             "config": d.parent.name, "seed": int(d.name[4:]),
                             "seconds": rec.get("seconds", {}).get("registration"),
                             **evaluation.flatten(common.read_json(scores))})
            for failed in sorted(runs.glob("*/*/seed*/failed.json")):
                d = failed.parent
                rows.append({"pair": self.pair.name, "method": d.parent.parent.name,
                             "config": d.parent.name, "seed": int(d.name[4:]), "failed": 1})
        return rows

    def chosen_rows(self, rows):
        """{method: rows of its chosen configuration (all seeds)}."""
        out = {}
        for m in ("morea", "elastix", "ants"):
            if m == "morea":
                cfg = "default"
            else:
                if m not in self.settings:
                    continue
                w = self.best_weight(m)
                if w is None:
                    continue
                cfg = config_name(m, w)
            sel = [r for r in rows if r["method"] == m and r["config"] == cfg and not r.get("failed")]
            if sel:
                out[m] = (cfg, sel)
        return out

    def report(self) -> None:
        from . import report
        rows = self.collect()
        chosen = self.chosen_rows(rows)
        report.write_all(self, rows, chosen)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m study", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["run", "report", "rescore"])
    ap.add_argument("--pair", required=True, choices=["lung", "abdomen", "phantom"])
    ap.add_argument("--out", required=True)
    ap.add_argument("--quick", action="store_true", help="tiny settings, one seed (CI)")
    ap.add_argument("--morea", help="the morea binary (default: $MOREA, build/bin/morea, PATH)")
    ap.add_argument("--data", help="folder with lung-ct-pair/ and abdomen-cbct-pair/")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, help="repeats per method (default 5, quick 1)")
    ap.add_argument("--sweep-seeds", type=int, default=1,
                    help="seeds per configuration in the regularisation sweep")
    ap.add_argument("--skip", nargs="*", choices=["morea", "elastix", "ants"])
    ap.add_argument("--retry-failed", action="store_true")
    ap.add_argument("--fresh", action="store_true",
                    help="delete --out first (default: resume, skipping finished runs)")
    args = ap.parse_args(argv)
    if args.fresh and args.command == "run" and Path(args.out).exists():
        import shutil
        shutil.rmtree(args.out)
    study = Study(args)
    start = time.perf_counter()
    if args.command == "run":
        study.prepare()
        study.sweep_and_repeat()
    elif args.command == "rescore":
        study.rescore()
    study.report()
    study.say(f"done in {time.perf_counter() - start:.0f} s: {study.out / 'report.md'}")
    failed = [r for r in study.collect() if r.get("failed")]
    return 1 if failed and args.quick else 0
