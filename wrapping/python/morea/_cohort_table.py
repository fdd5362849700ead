# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""A cohort table: one registration per row, each turned into the
`morea register` command that runs it. Used by morea.cohort."""
import csv
import os
import re
from dataclasses import dataclass, field

# Columns whose value is a path (resolved against the table's folder).
PATH_COLUMNS = {"problem": "--problem", "fixed": "--fixed", "moving": "--moving", "fixed_body": "--fixed-body",
                "moving_body": "--moving-body", "fixed_landmarks": "--fixed-landmarks",
                "moving_landmarks": "--moving-landmarks", "initial_transform": "--initial-transform",
                "parameters": "--parameters"}
# Columns holding NAME=VALUE items separated by ';'.
LIST_COLUMNS = {"fixed_structures": "--fixed-structure", "moving_structures": "--moving-structure",
                "set": "--set", "var": "--var"}
COLUMNS = ("id", "output", "seed", "backend", "select") + tuple(PATH_COLUMNS) + tuple(LIST_COLUMNS)
BACKENDS = ("auto", "cuda", "cuda-texture", "cuda-exact", "cpu")
SUMMARY = "summary.json"


@dataclass
class Registration:
    """One row of the cohort: its id, output folder and the arguments of
    `morea register` (without the output folder and the run's settings)."""
    id: str
    output: str
    arguments: list = field(default_factory=list)
    row: int = 0
    source: dict = field(default_factory=dict)

    def finished(self):
        """Whether its output folder holds a complete result (summary.json is written last)."""
        return os.path.isfile(os.path.join(self.output, SUMMARY))


def _items(text, column, row):
    items = [t.strip() for t in re.split(r"[;\n]", text) if t.strip()]
    for item in items:
        name, eq, _ = item.partition("=")
        if not eq or not name.strip():
            raise ValueError(f"cohort row {row}: '{item}' in column '{column}' must have the form NAME=VALUE")
    return items


def _resolve(path, base):
    path = os.path.expanduser(path)
    return path if os.path.isabs(path) else os.path.normpath(os.path.join(base, path))


def _resolve_source(item, base):
    """NAME=SOURCE with SOURCE a path (optionally PATH:LABEL) made absolute."""
    name, _, source = item.partition("=")
    return f"{name.strip()}={_resolve(source.strip(), base)}"


def _safe_id(text):
    return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._") or "registration"


def read_rows(cohort):
    """The rows of a cohort: a CSV file's path, or a list of dicts. Returns
    (rows, base folder for relative paths, the table's name)."""
    if isinstance(cohort, (str, os.PathLike)):
        path = os.fspath(cohort)
        if not os.path.isfile(path):
            raise ValueError(f"cohort table '{path}' does not exist")
        with open(path, newline="", encoding="utf-8-sig") as f:
            lines = [line for line in f if line.strip() and not line.lstrip().startswith("#")]
        reader = csv.DictReader(lines)
        if reader.fieldnames is None:
            raise ValueError(f"cohort table '{path}' is empty")
        header = [h.strip() for h in reader.fieldnames]
        rows = [{header[i]: (v or "").strip() for i, v in enumerate(r.get(k) for k in reader.fieldnames)}
                for r in reader]
        stem = os.path.basename(path)
        return rows, os.path.dirname(os.path.abspath(path)), stem.rsplit(".", 1)[0]
    rows = []
    for r in cohort:
        if not isinstance(r, dict):
            raise TypeError(f"cohort: rows must be dicts of columns, not {type(r).__name__}")
        rows.append({str(k).strip(): ("" if v is None else str(v)).strip() for k, v in r.items()})
    return rows, os.getcwd(), "cohort"


def parse_cohort(cohort, output_root, defaults):
    """The registrations of a cohort table. `defaults` holds the batch's
    settings for every row (parameters, set, var, seed, backend, select),
    which a row's own columns override. Errors in the table (unknown columns,
    rows without a problem, ids or output folders used twice) are raised here,
    before anything runs; whether the files exist is for each registration to
    find out (a missing one fails that row only)."""
    rows, base, _ = read_rows(cohort)
    if not rows:
        raise ValueError("cohort: the table has no rows")
    unknown = sorted({k for r in rows for k in r if k not in COLUMNS and k})
    if unknown:
        raise ValueError(f"cohort: unknown column(s) {', '.join(unknown)}; the columns are {', '.join(COLUMNS)}")
    registrations, ids, outputs = [], {}, {}
    for n, r in enumerate(rows, start=1):
        row = n + 1  # counting the header as row 1
        if not r.get("problem") and not (r.get("fixed") and r.get("moving")):
            raise ValueError(f"cohort row {row}: give a problem folder ('problem') or the images "
                             "('fixed' and 'moving')")
        rid = r.get("id") or ""
        if not rid:
            named = r.get("output") or r.get("problem") or ""
            rid = os.path.basename(os.path.normpath(named)) if named else f"row{n}"
        rid = _safe_id(rid)
        if rid in ids:
            raise ValueError(f"cohort rows {ids[rid]} and {row} have one id '{rid}'; give each row its own 'id'")
        ids[rid] = row
        output = _resolve(r["output"], base) if r.get("output") else os.path.join(output_root, rid)
        output = os.path.abspath(output)
        if output in outputs:
            raise ValueError(f"cohort rows {outputs[output]} and {row} write one output folder '{output}'")
        outputs[output] = row
        args = []
        for column, option in PATH_COLUMNS.items():
            value = r.get(column) or (defaults.get(column) if column == "parameters" else None)
            if value:
                args += [option, _resolve(str(value), base if r.get(column) else os.getcwd())]
        # The summary's problem_id is the row's id unless a 'set' names one.
        args += ["--set", f"problem_id={rid}"]
        for column, option in LIST_COLUMNS.items():
            items = []
            if column in ("set", "var"):
                items += list(defaults.get(column) or [])
            items += _items(r.get(column) or "", column, row)
            for item in items:
                if column.endswith("structures"):
                    item = _resolve_source(item, base)
                args += [option, item]
        seed = r.get("seed") or defaults.get("seed")
        if seed not in (None, ""):
            try:
                seed = int(str(seed))
            except ValueError:
                raise ValueError(f"cohort row {row}: seed '{seed}' is not an integer") from None
            args += ["--set", f"seed={seed}"]
        backend = r.get("backend") or defaults.get("backend")
        if backend:
            if backend not in BACKENDS:
                raise ValueError(f"cohort row {row}: backend '{backend}' is not one of {', '.join(BACKENDS)}")
            args += ["--backend", backend]
        select = r.get("select") or defaults.get("select")
        if select:
            args += ["--select", select]
        # So is the parameter file's $problem_id, when it has one (a --var given earlier wins).
        args += ["--var", f"problem_id={rid}"]
        registrations.append(Registration(rid, output, args, row, dict(r)))
    return registrations
