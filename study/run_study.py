# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The comparison study on one pair: MOREA against elastix and ANTs SyN.

    python3 -m study run --pair PAIR --out DIR [--profile reduced|paper] [--quick]
    python3 -m study prepare --pair PAIR --out DIR   (step 1 only: what the GPU needs)
    python3 -m study report --pair ... --out DIR     (tables and plots again)
    python3 -m study rescore --pair ... --out DIR    (scores again, then report)

PAIR: lung, abdomen, phantom (the small CI pair), the phantom suite at the
paper's MOREA configuration: phantom-pelvis, phantom-emptying, phantom-gas,
phantom-static, or the data pairs at the paper's budgets: lung-paper,
abdomen-paper (study/pairs.py).

Steps (each run is skipped when its scores.json exists, so a killed study resumes):
 1. `morea preprocess` with the MOREA parameter file of the pair -> DIR/problem,
    the problem every method registers and is scored on; the rigid baseline;
    for the phantom suite the landmarks per kind (DIR/landmarks/<kind>); the
    job of bench/run-study-morea.sh (DIR/morea_job.json, DIR/morea_parameters.toml).
 2. Sweep: elastix over its regularisation weights, ANTs over its total
    regularisation, with seed 1 (--sweep-seeds more).
 3. Best configuration per competitor: the best seed-1 value of the pair's
    first criterion (the paper's approach; the phantom suite: mean TRE of all
    landmarks, the truth being known).
 4. Convergence check (profile "paper"): the best configuration with seed 1
    again at twice the iterations; the budget counts as converged when the
    pair's first criterion changes by less than 1 %; a budget that is not is
    doubled again, up to 4x (report: convergence.csv, one row per doubling).
 5. Repeats: the best configurations and MOREA (each of the pair's MOREA
    configurations) with seeds 1..--seeds.
 6. results.csv (every run), tables (CSV, Markdown), two-sided Mann-Whitney U
    tests of MOREA against each competitor (Bonferroni: alpha 0.05 / 2 = 0.025),
    a parallel-coordinates plot and renders of seed 1 of each method.

MOREA at the paper's configuration (the phantom suite, lung-paper, abdomen-paper)
runs on a GPU: `prepare` here, bench/run-study-morea.sh
there, its archive unpacked into DIR; `run` then finds those runs' scores.json
and skips them (without them it registers MOREA here only with --local-morea).

`rescore` runs only `morea evaluate` again (after a change of its metrics) on the
baseline and on every finished run that still has both fields, replacing their
scores.json; nothing is registered again, and the run times stay those of run.json.
"""
from __future__ import annotations

import argparse
import math
import shutil
import time
import traceback
from pathlib import Path

from . import common, evaluation, pairs

WEIGHTS = [0.0, 0.001, 0.01, 0.1, 1.0, 10.0]

# Compute-budget profiles of the competitors (the paper's values are in the
# runners' PAPER_* constants; appendix C of the paper).
REDUCED = {
    "seeds": 5,
    "elastix": {"weights": WEIGHTS, "iterations": 100, "spatial_samples": 2000,
                "grid_spacing": 6.0, "parameter_estimation": "DisplacementDistribution"},
    # CC radius 4 voxels of 3 mm = 12 mm, the paper's 8 voxels of 1.5 mm.
    "ants": {"weights": WEIGHTS, "iterations": (100, 50, 25, 0), "cc_radius": 4},
}
FULL = REDUCED  # the name of the first study's profile
QUICK = {
    "seeds": 1,
    "elastix": {"weights": [0.01, 1.0], "iterations": 20, "spatial_samples": 1000,
                "grid_spacing": 12.0, "parameter_estimation": "DisplacementDistribution"},
    "ants": {"weights": [0.0, 3.0], "iterations": (10, 5, 2, 0), "cc_radius": 2},
}
# Appendix C: ANTs exactly (its caps 2000x1000x500x250 with the convergence
# window, which ends every level long before its cap), the CC radius and the
# B-spline grid in the paper's physical proportions (12 mm; 2 mm on 1.5 mm
# voxels = 4/3 of a voxel); elastix with fewer iterations and samples than the
# paper's 10000 and 20000 (a 2-core machine) and the cheap step-size estimation.
# The convergence check tells whether these iterations suffice.
PAPER = {
    "seeds": 5,
    "elastix": {"weights": WEIGHTS, "iterations": 200, "spatial_samples": 2000,
                "grid_spacing_voxels": 4.0 / 3.0,
                "parameter_estimation": "DisplacementDistribution"},
    "ants": {"weights": WEIGHTS, "iterations": (2000, 1000, 500, 250), "cc_radius_mm": 12.0},
    "convergence_check": True,
    # A budget that is not converged is doubled again (200 -> 400 -> 800 for
    # elastix), up to this multiple of the profile's iterations.
    "convergence_max_scale": 4,
}
PROFILES = {"reduced": REDUCED, "paper": PAPER, "quick": QUICK}
ALPHA = 0.025
CONVERGED_BELOW = 0.01   # relative change of the first criterion at twice the iterations
DOUBLED = "-x2"          # configuration suffix of the convergence check's runs
KNEE = "-knee"           # configuration suffix of a MOREA configuration's knee solution


def report_side_key(variant: str) -> str:
    """The report's key of a MOREA configuration's knee (a side row)."""
    return "morea:knee" if variant == "default" else f"morea:{variant}{KNEE}"


def config_name(method: str, weight: float | None, scale: int = 1, variant: str = "default") -> str:
    if method == "morea":
        return variant
    return f"w{weight:g}" + (DOUBLED if scale == 2 else (f"-x{scale}" if scale != 1 else ""))


def default_profile(pair: pairs.Pair, quick: bool) -> str:
    if quick:
        return "quick"
    return "paper" if pair.morea_on_gpu else "reduced"


def resolve_settings(profile: dict, spacing_mm: float | None) -> dict:
    """A profile with its voxel-relative settings made concrete for a problem of
    `spacing_mm` voxels: elastix's final grid spacing (mm) and ANTs' CC radius (voxels)."""
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in profile.items()}
    e, a = out["elastix"], out["ants"]
    if "grid_spacing_voxels" in e:
        if spacing_mm is None:
            raise ValueError("the profile needs the problem's voxel size")
        e["grid_spacing"] = round(e.pop("grid_spacing_voxels") * spacing_mm, 4)
    if "cc_radius_mm" in a:
        if spacing_mm is None:
            raise ValueError("the profile needs the problem's voxel size")
        a["cc_radius"] = max(1, int(round(a.pop("cc_radius_mm") / spacing_mm)))
    return out


def scaled_iterations(method: str, settings: dict, scale: int):
    it = settings[method]["iterations"]
    if method == "elastix":
        return int(it) * scale
    return tuple(int(i) * scale for i in it)


def relative_change(a: float | None, b: float | None) -> float | None:
    if a is None or b is None or (isinstance(a, float) and math.isnan(a)) \
            or (isinstance(b, float) and math.isnan(b)):
        return None
    if a == b:
        return 0.0
    return abs(b - a) / abs(a) if a != 0 else math.inf


class Study:
    def __init__(self, args):
        self.args = args
        self.out = Path(args.out).resolve()
        self.out.mkdir(parents=True, exist_ok=True)
        self.pair = pairs.make(args.pair, args.quick)
        self.profile_name = "quick" if args.quick else (args.profile or default_profile(self.pair, False))
        self.morea = common.find_morea(args.morea)
        self.problem = self.out / "problem"
        self.landmarks = self.out / "landmarks"
        self.methods = [m for m in ("morea", "elastix", "ants") if m not in (args.skip or [])]
        self.log = self.out / "logs" / "study.log"
        self.log.parent.mkdir(parents=True, exist_ok=True)
        self._settings = None

    @property
    def settings(self) -> dict:
        if self._settings is None:
            s = resolve_settings(PROFILES[self.profile_name], self.spacing())
            if self.args.seeds:
                s["seeds"] = self.args.seeds
            self._settings = s
        return self._settings

    def spacing(self) -> float | None:
        p = self.problem / "preprocess.json"
        return float(common.read_json(p)["spacing_mm"]) if p.exists() else None

    def say(self, msg: str) -> None:
        line = time.strftime("%H:%M:%S ") + msg
        print(line, flush=True)
        with open(self.log, "a") as f:
            f.write(line + "\n")

    def landmark_sets(self) -> dict | None:
        if not self.pair.landmarks_by_kind:
            return None
        from . import landmark_kinds
        return landmark_kinds.sets(self.landmarks) or None

    # -- 1 ------------------------------------------------------------------
    def prepare(self) -> None:
        pairs.resolve(self.pair, pairs.data_dir(self.args.data), self.out, self.morea)
        if not (self.problem / "preprocess.json").exists():
            self.say(f"preprocessing {self.pair.name}")
            common.run_command([self.morea, "preprocess", *self.pair.raw_args, "--parameters",
                                self.pair.morea_parameters, "-o", self.problem],
                               self.out / "logs" / "preprocess.log")
        if self.pair.landmarks_by_kind and not self.landmark_sets():
            from . import landmark_kinds
            kinds = common.read_json(self.out / "raw" / "phantom.json")["landmark_kinds"]
            landmark_kinds.split(kinds, self.problem, self.landmarks)
        base = self.out / "baseline"
        base.mkdir(exist_ok=True)
        if not (base / "scores.json").exists():
            evaluation.evaluate(self.morea, self.problem, base / "scores.json",
                                landmark_sets=self.landmark_sets())
        self.write_morea_job()

    def write_morea_job(self) -> None:
        """DIR/morea_job.json and DIR/morea_parameters.toml: what
        bench/run-study-morea.sh needs to run the pair's MOREA runs elsewhere
        (with the problem folder and the landmark sets)."""
        from . import morea_runner
        shutil.copyfile(self.pair.morea_parameters, self.out / "morea_parameters.toml")
        raw = self.out / "raw"
        job = {
            "pair": self.pair.name,
            "parameters": "morea_parameters.toml",
            "parameters_source": self.pair.morea_parameters.name,
            "variants": self.pair.morea_variants,
            "select": morea_runner.SELECT,
            "chosen": morea_runner.CHOSEN,
            "focus": self.pair.primary_structure,
            "initial_transform": ("problem/" + morea_runner.INITIAL_TRANSFORM
                                  if (self.problem / morea_runner.INITIAL_TRANSFORM).exists()
                                  else None),
            "landmark_kinds": sorted(self.landmark_sets() or {}),
            "seeds": list(range(1, self.settings["seeds"] + 1)),
        }
        if self.pair.phantom_case is not None or self.pair.name == "phantom":
            # The GPU machine writes the phantom again (deterministic): its raw
            # inputs need not travel; the checksums show it is the same.
            job["phantom_arguments"] = pairs.phantom_arguments(self.pair)
            job["raw_args"] = ["--problem", "{raw}"]
            job["raw_md5"] = {str(p.relative_to(raw)): common.md5(p)
                              for p in sorted(raw.rglob("*.nii.gz"))}
        else:
            # The data pair's files travel with the bundle (raw/, the same
            # relative paths), so that the GPU machine reads what was read here.
            data = pairs.data_dir(self.args.data).resolve()
            job["raw_args"], job["raw_files"] = [], []
            for a in map(str, self.pair.raw_args):
                path, sep, rest = a.rpartition("=")[2].partition(":")
                if Path(path).is_absolute() and Path(path).resolve().is_relative_to(data):
                    relative = str(Path(path).resolve().relative_to(data))
                    # A label map named by label (path:name) reads its names beside it.
                    names = Path(path).with_suffix(".txt")
                    extra = [str(names.resolve().relative_to(data))] if rest and names.exists() else []
                    for f in [relative, *extra]:
                        if f not in job["raw_files"]:
                            job["raw_files"].append(f)
                    a = a.replace(path, "{raw}/" + relative, 1)
                job["raw_args"].append(a)
        common.write_json(self.out / "morea_job.json", job)

    # -- one run --------------------------------------------------------------
    def config_dir(self, method: str, config: str, seed: int) -> Path:
        return self.out / "runs" / method / config / f"seed{seed}"

    def run_dir(self, method: str, weight, seed: int, scale: int = 1,
                variant: str = "default") -> Path:
        return self.config_dir(method, config_name(method, weight, scale, variant), seed)

    def run_one(self, method: str, weight, seed: int, scale: int = 1,
                variant: str = "default") -> dict | None:
        d = self.run_dir(method, weight, seed, scale, variant)
        scores_path = d / "scores.json"
        if scores_path.exists():
            return common.read_json(scores_path)
        if (d / "failed.json").exists() and not self.args.retry_failed:
            return None
        if method == "morea" and self.pair.morea_on_gpu and not self.args.local_morea:
            self.say(f"morea {variant} seed {seed}: no result (run bench/run-study-morea.sh on "
                     "a GPU and unpack its archive here, or pass --local-morea)")
            return None
        d.mkdir(parents=True, exist_ok=True)
        self.say(f"{method} {config_name(method, weight, scale, variant)} seed {seed}")
        threads = self.args.threads
        try:
            if method == "elastix":
                from . import elastix_runner
                e = self.settings["elastix"]
                rec = elastix_runner.run(self.problem, d, weight, seed,
                                         scaled_iterations("elastix", self.settings, scale),
                                         e["grid_spacing"], e["spatial_samples"], threads, True,
                                         e["parameter_estimation"])
            elif method == "ants":
                from . import ants_runner
                a = self.settings["ants"]
                rec = ants_runner.run(self.problem, d, weight, seed,
                                      scaled_iterations("ants", self.settings, scale),
                                      cc_radius=a["cc_radius"], threads=threads)
            else:
                from . import morea_runner
                rec = morea_runner.run(self.morea, self.pair.raw_args, self.pair.morea_parameters,
                                       self.problem, d, seed, threads,
                                       extra_args=self.pair.morea_variants[variant],
                                       config=variant)
            scores = evaluation.evaluate(self.morea, self.problem, d / "scores.tmp.json",
                                         d / "fixed_to_moving.nii.gz",
                                         d / "moving_to_fixed.nii.gz",
                                         landmark_sets=self.landmark_sets())
            (d / "scores.tmp.json").replace(scores_path)
            self.say(f"  {rec['seconds']['registration']:.1f} s")
            return scores
        except Exception as exc:  # a failed run is reported, not fatal
            self.say(f"  FAILED: {exc}")
            common.write_json(d / "failed.json", {"error": str(exc),
                                                  "traceback": traceback.format_exc()})
            return None

    # -- 2-5 ------------------------------------------------------------------
    def sweep_and_repeat(self) -> None:
        seeds = list(range(1, self.settings["seeds"] + 1))
        sweep_seeds = list(range(1, (self.args.sweep_seeds or 1) + 1))
        competitors = [m for m in ("elastix", "ants") if m in self.methods]
        for m in competitors:
            for w in self.settings[m]["weights"]:
                for s in sweep_seeds:
                    self.run_one(m, w, s)
        if self.settings.get("convergence_check") and not self.args.no_convergence_check:
            for m in competitors:
                best = self.best_weight(m)
                if best is None:
                    continue
                # Double until the score changes by < 1 % or the largest scale ran.
                scale = 2
                self.run_one(m, best, 1, scale=scale)
                while scale < self.settings.get("convergence_max_scale", 2):
                    step = self.convergence_step(m, best, scale // 2)
                    if step is None or step["converged"]:
                        break
                    scale *= 2
                    self.run_one(m, best, 1, scale=scale)
        for m in competitors:
            best = self.best_weight(m)
            if best is None:
                continue
            for s in seeds:
                self.run_one(m, best, s)
        if "morea" in self.methods:
            for variant in self.pair.morea_variants:
                for s in seeds:
                    self.run_one("morea", None, s, variant=variant)

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

    def convergence_step(self, method: str, weight, scale: int) -> dict | None:
        """The best configuration's seed-1 run at `scale` times the iterations
        against its run at twice that: the relative change of the pair's first
        criterion; None when either run has no scores."""
        crit = self.pair.criteria[0]
        a, b = self.run_dir(method, weight, 1, scale), self.run_dir(method, weight, 1, 2 * scale)
        if not (a / "scores.json").exists() or not (b / "scores.json").exists():
            return None
        va = evaluation.flatten(common.read_json(a / "scores.json")).get(crit.column)
        vb = evaluation.flatten(common.read_json(b / "scores.json")).get(crit.column)
        ra = common.read_json(a / "run.json") if (a / "run.json").exists() else {}
        rb = common.read_json(b / "run.json") if (b / "run.json").exists() else {}
        change = relative_change(va, vb)
        return {
            "method": method, "config": config_name(method, weight, scale), "score": crit.column,
            "iterations": ra.get("iterations", ra.get("iterations_per_resolution")),
            "iterations_used": ra.get("iterations_used"),
            "score_at_budget": va,
            "iterations_doubled": rb.get("iterations", rb.get("iterations_per_resolution")),
            "iterations_used_doubled": rb.get("iterations_used"),
            "score_doubled": vb, "relative_change": change,
            "converged": change is not None and change < CONVERGED_BELOW,
            "seconds": (ra.get("seconds") or {}).get("registration"),
            "seconds_doubled": (rb.get("seconds") or {}).get("registration"),
        }

    def convergence(self) -> list[dict]:
        """Per competitor: the best configuration's seed-1 run against its run at
        twice the iterations, and each further doubling that ran (x2 -> x4, ...):
        one row per step, the relative change of the pair's first criterion."""
        out = []
        for m in ("elastix", "ants"):
            if m not in self.settings:
                continue
            w = self.best_weight(m)
            if w is None:
                continue
            scale = 1
            while (step := self.convergence_step(m, w, scale)) is not None:
                out.append(step)
                scale *= 2
        return out

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
                                      border_margin=old.get("border_margin_mm"),
                                      landmark_sets=self.landmark_sets())
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

    # -- 6 ------------------------------------------------------------------
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
        """{method: (config, rows of its chosen configuration, all seeds)}; MOREA's
        configurations other than "default" under "morea:<name>"."""
        out = {}
        for m in ("morea", "elastix", "ants"):
            if m == "morea":
                cfgs = [(m if v == "default" else f"morea:{v}", v) for v in self.pair.morea_variants]
                # Each configuration's knee, where the GPU script scored it: beside, not tested.
                cfgs += [(report_side_key(v), f"{v}{KNEE}") for v in self.pair.morea_variants]
            else:
                if m not in self.settings:
                    continue
                w = self.best_weight(m)
                if w is None:
                    continue
                cfgs = [(m, config_name(m, w))]
            for key, cfg in cfgs:
                sel = [r for r in rows if r["method"] == m and r["config"] == cfg
                       and not r.get("failed")]
                if sel:
                    out[key] = (cfg, sel)
        return out

    def report(self) -> None:
        from . import report
        rows = self.collect()
        chosen = self.chosen_rows(rows)
        report.write_all(self, rows, chosen)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python3 -m study", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["run", "prepare", "report", "rescore"])
    ap.add_argument("--pair", required=True, choices=pairs.NAMES)
    ap.add_argument("--out", required=True)
    ap.add_argument("--quick", action="store_true", help="tiny settings, one seed (CI)")
    ap.add_argument("--profile", choices=["reduced", "paper"],
                    help="competitors' budgets: reduced (the first study's) or paper "
                         "(appendix C, with the convergence check); default: paper for the "
                         "phantom suite and the -paper pairs, reduced otherwise")
    ap.add_argument("--morea", help="the morea binary (default: $MOREA, build/bin/morea, PATH)")
    ap.add_argument("--data", help="folder with lung-ct-pair/ and abdomen-cbct-pair/")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, help="repeats per method (default 5, quick 1)")
    ap.add_argument("--sweep-seeds", type=int, default=1,
                    help="seeds per configuration in the regularisation sweep")
    ap.add_argument("--skip", nargs="*", choices=["morea", "elastix", "ants"])
    ap.add_argument("--local-morea", action="store_true",
                    help="pairs whose MOREA runs on a GPU: register it here when the GPU's "
                         "results are missing")
    ap.add_argument("--no-convergence-check", action="store_true")
    ap.add_argument("--retry-failed", action="store_true")
    ap.add_argument("--fresh", action="store_true",
                    help="delete --out first (default: resume, skipping finished runs)")
    args = ap.parse_args(argv)
    if args.fresh and args.command == "run" and Path(args.out).exists():
        shutil.rmtree(args.out)
    study = Study(args)
    start = time.perf_counter()
    if args.command in ("run", "prepare"):
        study.prepare()
        if args.command == "prepare":
            study.say(f"prepared {study.out}: problem/, morea_job.json (bench/run-study-morea.sh)")
            return 0
        study.say(f"profile {study.profile_name}: elastix {study.settings['elastix']}, "
                  f"ANTs {study.settings['ants']}")
        study.sweep_and_repeat()
    elif args.command == "rescore":
        study.rescore()
    study.report()
    study.say(f"done in {time.perf_counter() - start:.0f} s: {study.out / 'report.md'}")
    failed = [r for r in study.collect() if r.get("failed")]
    return 1 if failed and args.quick else 0
