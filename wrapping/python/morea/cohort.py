# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Cohorts: a table of registrations run on Dask (dask.distributed).

    morea.batch("cohort.csv", "cohort-out")                    # this machine's GPUs, else its CPUs
    morea.batch("cohort.csv", "cohort-out", cluster="slurm", jobs=8,
                cluster_options={"queue": "gpu", "cores": 16, "memory": "64GB",
                                 "job_extra_directives": ["--gres=gpu:1"]})
    python3 -m morea.cohort cohort.csv -o cohort-out           # what `morea batch` runs

Each registration is `morea register` on one worker, one at a time per
worker (one worker per GPU, CUDA_VISIBLE_DEVICES pinned). A folder that
holds a complete result (summary.json) is skipped; a registration whose
worker dies resumes from its checkpoint on another worker; one that fails is
recorded with its error and the others go on. The report folder gets
registrations.csv, cohort_summary.csv, plots/ and logs/.
"""
import argparse
import ast
import logging
import os
import shutil
import socket
import subprocess
import sys
import threading
import time

from ._cohort_report import write_report, write_text
from ._cohort_table import parse_cohort, read_rows
from ._cohort_worker import EVENT_TOPIC, available_cores, finished_record, run_registration
from ._morea import parse_checkpoint_every

__all__ = ["batch", "BatchResult", "local_gpus", "make_cluster", "main"]

RESOURCE = "registration"  # each worker holds one: one registration at a time
JOBQUEUE = {"slurm": "SLURMCluster", "pbs": "PBSCluster", "sge": "SGECluster", "lsf": "LSFCluster",
            "oar": "OARCluster", "moab": "MoabCluster", "htcondor": "HTCondorCluster"}


class BatchResult:
    """What morea.batch returns: a record per registration (id, status
    'finished', 'skipped' or 'failed', error, output, times, backend, GPU,
    worker, ...) and the report's files."""

    def __init__(self, records, paths, seconds, note):
        self.records = records
        self.paths = paths
        self.seconds = seconds
        self.note = note

    def __repr__(self):
        counts = ", ".join(f"{self.count(s)} {s}" for s in ("finished", "skipped", "failed"))
        return f"BatchResult({len(self.records)} registrations: {counts}; {self.seconds:.1f} s)"

    def count(self, status):
        return sum(r["status"] == status for r in self.records)

    @property
    def failed(self):
        return [r for r in self.records if r["status"] == "failed"]

    def table(self):
        """The cohort summary (cohort_summary.csv) as a pandas DataFrame."""
        import pandas as pd

        return pd.read_csv(self.paths["summary"])


def find_morea(morea=None):
    """The `morea` executable the workers run: the one given, $MOREA_BIN, or `morea` on the PATH."""
    for candidate in (morea, os.environ.get("MOREA_BIN"), shutil.which("morea")):
        if candidate:
            path = shutil.which(candidate) or candidate
            if os.path.isfile(path) and os.access(path, os.X_OK):
                return os.path.abspath(path)
            if candidate is morea:
                raise ValueError(f"morea: '{morea}' is not an executable file")
    raise RuntimeError("a batch runs the command line `morea register` on each worker, and no `morea` was found: "
                       "build and install it (cmake --install), put it on the PATH or set MOREA_BIN")


def local_gpus():
    """This machine's GPUs as CUDA_VISIBLE_DEVICES names them (its value when
    set, else nvidia-smi's list); [] without GPUs."""
    visible = os.environ.get("CUDA_VISIBLE_DEVICES")
    if visible is not None:
        return [g.strip() for g in visible.split(",") if g.strip() and g.strip() != "-1"]
    smi = shutil.which("nvidia-smi")
    if smi is None:
        return []
    try:
        out = subprocess.run([smi, "--query-gpu=index", "--format=csv,noheader"], capture_output=True, text=True,
                             timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return []
    return [line.strip() for line in out.stdout.splitlines() if line.strip().isdigit()] if out.returncode == 0 else []


def _count(n, what):
    return f"{n} {what}{'' if n == 1 else 's'}"


def _quiet():
    return {"silence_logs": logging.ERROR, "dashboard_address": ":0"}


def _gpu_cluster(gpus):
    """One worker per GPU, CUDA_VISIBLE_DEVICES pinned to it, one thread:
    dask_cuda.LocalCUDACluster when installed, else the same layout from
    distributed's own parts (a nanny per GPU with the variable set)."""
    try:
        from dask_cuda import LocalCUDACluster
    except ImportError:
        LocalCUDACluster = None
    if LocalCUDACluster is not None:
        cluster = LocalCUDACluster(CUDA_VISIBLE_DEVICES=",".join(gpus), threads_per_worker=1,
                                   resources={RESOURCE: 1}, **_quiet())
        return cluster, f"dask_cuda.LocalCUDACluster: {_count(len(gpus), 'worker')}, one per GPU ({', '.join(gpus)})"
    from distributed import Nanny, Scheduler, SpecCluster

    workers = {f"gpu{g}": {"cls": Nanny, "options": {
        "nthreads": 1, "resources": {RESOURCE: 1}, "name": f"gpu{g}", "host": "127.0.0.1",
        "silence_logs": logging.ERROR,
        "env": {"CUDA_VISIBLE_DEVICES": g}}} for g in gpus}
    scheduler = {"cls": Scheduler, "options": {"dashboard_address": ":0", "host": "127.0.0.1"}}
    cluster = SpecCluster(workers=workers, scheduler=scheduler, silence_logs=logging.ERROR, name="morea-gpus")
    return cluster, (f"local GPU cluster: {_count(len(gpus), 'worker')}, one per GPU ({', '.join(gpus)}), "
                     "CUDA_VISIBLE_DEVICES pinned (dask_cuda not installed)")


def make_cluster(kind="local", workers=None, gpus=None, jobs=None, options=None):
    """A Dask cluster for a batch, and a line saying what it is.

    kind: "local" (this machine's GPUs, one worker each; its CPUs when it has
        none), "local-gpu", "local-cpu", or a dask-jobqueue scheduler
        ("slurm", "pbs", "sge", "lsf", "oar", "moab", "htcondor"), whose
        keyword arguments (queue, cores, memory, walltime,
        job_extra_directives, ...) come from `options` and dask's jobqueue
        configuration; `jobs` jobs are asked for, one worker each.
    workers: CPU workers of a local CPU cluster (default: one per 8 cores).
    gpus: the GPUs of a local GPU cluster (default: all visible)."""
    options = dict(options or {})
    if kind in ("local", "local-gpu", "local-cpu"):
        found = [str(g) for g in gpus] if gpus is not None else (local_gpus() if kind != "local-cpu" else [])
        if kind == "local-gpu" and not found:
            raise RuntimeError("local-gpu: no GPU found (nvidia-smi lists none and CUDA_VISIBLE_DEVICES names none)")
        if found and kind != "local-cpu":
            return _gpu_cluster(found)
        from distributed import LocalCluster

        n = int(workers) if workers else max(1, (os.cpu_count() or 1) // 8)
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, resources={RESOURCE: 1},
                               **_quiet(), **options)
        return cluster, f"LocalCluster: {_count(n, 'CPU worker')}"
    if kind in JOBQUEUE:
        try:
            import dask_jobqueue
        except ImportError:
            raise RuntimeError(f"cluster '{kind}' needs dask-jobqueue: pip install dask-jobqueue") from None
        extra = list(options.pop("worker_extra_args", []))
        if "--resources" not in extra:
            extra += ["--resources", f"{RESOURCE}=1"]
        options.setdefault("processes", 1)
        cluster = getattr(dask_jobqueue, JOBQUEUE[kind])(worker_extra_args=extra, **options)
        n = int(jobs if jobs is not None else (workers or 1))
        cluster.scale(jobs=n)
        return cluster, f"dask_jobqueue.{JOBQUEUE[kind]}: {_count(n, 'job')} of one worker"
    raise ValueError(f"cluster must be local, local-gpu, local-cpu or one of {', '.join(JOBQUEUE)}, not {kind!r}")


class _Progress:
    """The whole batch's state from the workers' events: done, running,
    failed, and the time left from the registrations' durations and the
    running ones' generations."""

    def __init__(self, total, skipped, workers, show, status_path):
        self.total, self.skipped, self.show, self.status_path = total, skipped, show, status_path
        self.workers = max(1, workers)
        self.lock = threading.Lock()
        self.running = {}  # id -> {"since", "generation", "total"}
        self.durations = []
        self.finished = self.failed = 0
        self.started = time.time()
        self.last_line = ""
        self.last_print = 0.0
        self.terminal = show and sys.stderr.isatty()

    def event(self, event):
        message = event[1] if isinstance(event, tuple) and len(event) == 2 else event
        if not isinstance(message, dict) or "id" not in message:
            return
        with self.lock:
            state = message.get("state")
            if state == "running":
                self.running[message["id"]] = {"since": message.get("time", time.time()), "fraction": 0.0}
            elif state == "generation" and message["id"] in self.running:
                self.running[message["id"]]["fraction"] = message["generation"] / max(1, message["total"])

    def done(self, record):
        with self.lock:
            self.running.pop(record["id"], None)
            if record["status"] == "failed":
                self.failed += 1
            else:
                self.finished += 1
                if record["status"] == "finished" and record.get("seconds"):
                    self.durations.append(float(record["seconds"]))

    def seconds_left(self):
        """Registrations left times the mean duration, spread over the workers."""
        now = time.time()
        mean = sum(self.durations) / len(self.durations) if self.durations else None
        if mean is None:
            estimates = [(now - r["since"]) / r["fraction"] for r in self.running.values() if r["fraction"] > 0.05]
            mean = sum(estimates) / len(estimates) if estimates else None
        if mean is None:
            return None
        waiting = self.total - self.finished - self.failed - len(self.running)
        left = sum(max(0.0, mean - (now - r["since"])) for r in self.running.values())
        return (left + waiting * mean) / min(self.workers, max(1, waiting + len(self.running)))

    def report(self, force=False):
        with self.lock:
            left = self.seconds_left()
            running = len(self.running)
            text = (f"batch: {self.finished + self.skipped}/{self.total + self.skipped} done"
                    f"{f' ({self.skipped} skipped)' if self.skipped else ''}, {running} running, "
                    f"{self.failed} failed, {time.time() - self.started:.0f} s"
                    + (f", about {_duration(left)} left" if left is not None and running else ""))
            status = {"total": self.total + self.skipped, "done": self.finished + self.skipped,
                      "skipped": self.skipped, "running": sorted(self.running), "failed": self.failed,
                      "seconds": time.time() - self.started, "seconds_left": left}
        if self.status_path:
            import json

            write_text(self.status_path, json.dumps(status, indent=1) + "\n")
        if not self.show:
            return
        now = time.time()
        counts = text.split(", about")[0].rsplit(",", 1)[0]  # without the clock and the estimate
        if self.terminal:
            print("\r" + text + "   ", end="\n" if force else "", file=sys.stderr, flush=True)
        elif force or counts != self.last_line or now - self.last_print >= 30:
            print(text, file=sys.stderr, flush=True)
            self.last_print = now
        self.last_line = counts


def _duration(seconds):
    seconds = int(round(seconds))
    return f"{seconds // 3600} h {seconds % 3600 // 60:02d} min" if seconds >= 3600 else (
        f"{seconds // 60} min {seconds % 60:02d} s" if seconds >= 60 else f"{seconds} s")


def _threads(client, given):
    """Host threads per registration: as given; else, when every worker runs
    on this machine, its cores shared among them; else 0 (each worker takes
    the cores its process may use: a cluster job's own)."""
    if given is not None:
        return int(given)
    from urllib.parse import urlparse

    hosts = [urlparse(address).hostname for address in _workers(client)]
    names = {"127.0.0.1", "localhost", "::1", socket.gethostname()}
    try:
        names.update(socket.gethostbyname_ex(socket.gethostname())[2])
    except OSError:
        pass
    if hosts and all(h in names for h in hosts):
        return max(1, available_cores() // len(hosts))
    return 0


def batch(cohort, output=None, cluster="local", scheduler=None, workers=None, gpus=None, jobs=None,
          cluster_options=None, threads=None, parameters=None, overrides=None, variables=None, seed=None,
          backend=None, select=None, checkpoint_every="30s", morea=None, progress=True, plots=True):
    """Runs a cohort of registrations on Dask; returns a BatchResult.

    cohort: a CSV file (one registration per row) or a list of dicts with
        its columns: id, problem (a problem folder) or fixed, moving,
        fixed_structures and moving_structures ("NAME=SOURCE;..."),
        fixed_body, moving_body, fixed_landmarks, moving_landmarks,
        initial_transform; parameters (a TOML file), set ("KEY=VALUE;..."),
        var ("NAME=VALUE;..."), seed, backend, select; output (a folder;
        default OUTPUT/ID). Relative paths are the table's folder's.
    output: the report folder (registrations.csv, cohort_summary.csv,
        plots/, logs/, and the registrations' folders not named in the
        table); default: beside the table, its name with "-batch".
    cluster: "local", "local-gpu", "local-cpu", "slurm", "pbs", ... (see
        make_cluster), or a distributed Cluster or Client to use as it is.
    scheduler: the address of a running Dask scheduler (instead of cluster).
    parameters, overrides ({key: value} or ["KEY=VALUE"]), variables, seed,
        backend, select: for every row, which a row's columns override.
    threads: host threads per registration (default: the machine's cores
        shared by its workers).
    checkpoint_every: how often each registration writes its checkpoint (a
        killed worker's registration resumes from the last one): a number of
        generations (10) or a duration ("30s", "5min"; on the GPU ten
        generations take about a second).
    morea: the `morea` executable (default: $MOREA_BIN, or on the PATH).
    """
    started = time.time()
    try:
        parse_checkpoint_every(str(checkpoint_every))  # as morea register reads it
    except ValueError:
        raise ValueError(f"checkpoint_every '{checkpoint_every}': expected a number of generations (10), "
                         "a duration (30s, 2.5min) or 0 (only at the end)") from None
    morea = find_morea(morea)
    if output is None:
        if isinstance(cohort, (str, os.PathLike)):
            path = os.path.abspath(os.fspath(cohort))
            output = os.path.join(os.path.dirname(path), read_rows(path)[2] + "-batch")
        else:
            output = os.path.abspath("cohort-batch")
    output = os.path.abspath(os.fspath(output))
    defaults = {"parameters": os.fspath(parameters) if parameters else None, "seed": seed, "backend": backend,
                "select": select, "set": _assignments(overrides, "overrides"),
                "var": _assignments(variables, "variables")}
    registrations = parse_cohort(cohort, output, defaults)
    os.makedirs(output, exist_ok=True)
    logs = os.path.join(output, "logs")
    records = {}
    for r in registrations:
        if r.finished():
            records[r.id] = {**finished_record(r, "skipped"), "resumed_at_generation": ""}
    pending = [r for r in registrations if r.id not in records]
    note = "nothing to run"
    if pending:
        client, close, note = _connect(cluster, scheduler, workers, gpus, jobs, cluster_options)
        try:
            _run(client, pending, records, morea, logs, threads, checkpoint_every, progress, output, note)
        finally:
            close()
    elif progress:
        print(f"batch: all {len(registrations)} registrations are finished already", file=sys.stderr)
    ordered = [records[r.id] for r in registrations]
    paths = write_report(output, ordered, plots=plots)
    paths["logs"] = logs
    result = BatchResult(ordered, paths, time.time() - started, note)
    if progress:
        print(f"batch: {result.count('finished')} finished, {result.count('skipped')} skipped, "
              f"{result.count('failed')} failed in {result.seconds:.1f} s; summary {paths['summary']}",
              file=sys.stderr)
        for r in result.failed:
            print(f"  failed: {r['id']}: {r['error']}", file=sys.stderr)
    return result


def _assignments(values, what):
    if values is None:
        return []
    if isinstance(values, dict):
        return [f"{k}={_toml_text(v)}" for k, v in values.items()]
    if isinstance(values, str):
        values = [values]
    out = [str(v) for v in values]
    for v in out:
        if "=" not in v:
            raise ValueError(f"{what}: '{v}' must have the form NAME=VALUE")
    return out


def _toml_text(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ", ".join(str(v) for v in value)
    return str(value)


def _connect(cluster, scheduler, workers, gpus, jobs, options):
    """A client on the cluster asked for; returns (client, close, note)."""
    from distributed import Client

    if scheduler is not None:
        client = Client(scheduler)
        return client, client.close, f"scheduler at {client.scheduler.address}"
    if isinstance(cluster, Client):
        return cluster, lambda: None, f"the client given ({cluster.scheduler.address})"
    if not isinstance(cluster, str):  # a Cluster object
        client = Client(cluster)
        return client, client.close, f"the cluster given ({type(cluster).__name__})"
    made, note = make_cluster(cluster, workers=workers, gpus=gpus, jobs=jobs, options=options)
    client = Client(made)

    def close():
        client.close()
        made.close()

    return client, close, note


def _run(client, pending, records, morea, logs, threads, checkpoint_every, show, output, note):
    from distributed import as_completed

    if show:
        print(f"batch: {len(pending)} registrations to run ({len(records)} finished already) on {note}",
              file=sys.stderr, flush=True)
    try:
        client.wait_for_workers(1, timeout=600)
    except Exception:
        raise RuntimeError(f"no Dask worker joined within 10 minutes ({note})") from None
    info = _workers(client)
    with_resource = all(RESOURCE in w.get("resources", {}) for w in info.values())
    if not with_resource and show:
        print(f"batch: the workers do not all offer the resource '{RESOURCE}'; start them with "
              f"--resources {RESOURCE}=1 (or --nthreads 1) for one registration per worker at a time",
              file=sys.stderr)
    per_registration = _threads(client, threads)
    progress = _Progress(len(pending), len(records), len(info), show, os.path.join(output, "status.json"))
    client.subscribe_topic(EVENT_TOPIC, progress.event)
    # Registrations go out as workers have room, not all at once: Dask hands
    # resource-bound tasks to workers when they are submitted, so a worker
    # that finished early would otherwise wait while another still had two.
    waiting = list(pending)
    futures = {}
    completed = as_completed()
    lock = threading.Lock()

    def submit_more():
        with lock:
            room = _slots(client, with_resource) - len(futures)
            while waiting and room > 0:
                r = waiting.pop(0)
                future = client.submit(run_registration, r, morea, logs, per_registration, checkpoint_every,
                                       key=f"morea-register-{r.id}-{os.getpid()}-{int(time.time() * 1000)}",
                                       pure=False, resources={RESOURCE: 1} if with_resource else None)
                futures[future] = r
                completed.add(future)
                room -= 1

    submit_more()
    progress.report(force=True)
    stop = threading.Event()

    def tick():  # also gives workers that joined since (a Slurm job that started) their registrations
        while not stop.wait(5.0):
            progress.report()
            try:
                submit_more()
            except Exception:  # the scheduler is going away; the main loop says why
                pass

    ticker = threading.Thread(target=tick, daemon=True)
    ticker.start()
    try:
        for future in completed:
            with lock:
                r = futures.pop(future)
            try:
                record = future.result()
            except Exception as e:  # the worker died too often (KilledWorker), or the task itself broke
                record = {"id": r.id, "status": "failed", "output": r.output,
                          "error": f"{type(e).__name__}: {e}"}
            records[r.id] = record
            progress.done(record)
            progress.report(force=record["status"] == "failed")
            submit_more()
    finally:
        stop.set()
        ticker.join()
        try:
            client.unsubscribe_topic(EVENT_TOPIC)
        except Exception:
            pass


def _workers(client):
    """{address: info} of every worker (distributed 2025.x lists five unless asked for all)."""
    try:
        return client.scheduler_info(n_workers=-1)["workers"]
    except TypeError:  # a distributed without n_workers lists them all
        return client.scheduler_info()["workers"]


def _slots(client, with_resource):
    """Registrations the workers can run at once: their GPUs (the resource),
    else their threads; at least one, so that a batch waits for workers."""
    workers = _workers(client).values()
    if with_resource:
        count = sum(int(w.get("resources", {}).get(RESOURCE, 0)) for w in workers)
    else:
        count = sum(int(w.get("nthreads", 1)) for w in workers)
    return max(1, count)


def _option_value(text):
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def main(argv=None, morea=None):
    """`morea batch` / `python3 -m morea.cohort`: returns the exit status
    (0: all finished or skipped, 1: some failed, 2: the batch could not run)."""
    parser = argparse.ArgumentParser(
        prog="morea batch", description="Run a cohort of registrations (a CSV table, one per row) on Dask: "
        "this machine's GPUs (one worker each), its CPUs, a Slurm/PBS/SGE/LSF cluster (dask-jobqueue) or a running "
        "scheduler. Finished registrations are skipped; a killed worker's registration resumes from its checkpoint.")
    parser.add_argument("cohort", help="CSV table: id, problem (or fixed, moving, fixed_structures, "
                        "moving_structures, ...), parameters, set, var, seed, backend, select, output")
    parser.add_argument("-o", "--output", help="report folder (default: beside the table, NAME-batch)")
    parser.add_argument("--cluster", default="local", help="local (GPUs, else CPUs), local-gpu, local-cpu, "
                        + ", ".join(JOBQUEUE) + " (default: local)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler (instead of --cluster)")
    parser.add_argument("--gpus", help="GPUs of a local GPU cluster, comma-separated (default: all)")
    parser.add_argument("--workers", type=int, help="CPU workers of a local CPU cluster (default: one per 8 cores)")
    parser.add_argument("--jobs", type=int, help="jobs of a jobqueue cluster, one worker each (default: 1)")
    parser.add_argument("--cluster-option", action="append", default=[], metavar="KEY=VALUE",
                        help="keyword of the jobqueue cluster (queue=gpu, cores=16, memory=64GB, "
                        "job_extra_directives=['--gres=gpu:1'], ...)")
    parser.add_argument("--threads", type=int, help="host threads per registration")
    parser.add_argument("--parameters", help="TOML parameter file for rows without their own")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="parameter for every row")
    parser.add_argument("--var", action="append", default=[], metavar="NAME=VALUE", help="placeholder value")
    parser.add_argument("--seed", type=int, help="seed for rows without their own")
    parser.add_argument("--backend", help="auto, cuda, cuda-exact or cpu for rows without their own")
    parser.add_argument("--select", help="solutions to write, for rows without their own")
    parser.add_argument("--checkpoint-every", default="30s",
                        help="each registration's checkpoints: every N generations (10) or so long (30s, 5min)")
    parser.add_argument("--no-plots", action="store_true", help="no score plots")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    parser.add_argument("--morea", default=morea, help="the morea executable the workers run")
    args = parser.parse_args(argv)
    options = {}
    for item in args.cluster_option:
        key, eq, value = item.partition("=")
        if not eq:
            parser.error(f"--cluster-option '{item}' must have the form KEY=VALUE")
        options[key.strip()] = _option_value(value.strip())
    try:
        result = batch(args.cohort, args.output, cluster=args.cluster, scheduler=args.scheduler,
                       workers=args.workers, gpus=args.gpus.split(",") if args.gpus else None, jobs=args.jobs,
                       cluster_options=options, threads=args.threads, parameters=args.parameters,
                       overrides=args.set, variables=args.var, seed=args.seed, backend=args.backend,
                       select=args.select, checkpoint_every=args.checkpoint_every, morea=args.morea,
                       progress=not args.quiet, plots=not args.no_plots)
    except (ValueError, RuntimeError, TypeError) as e:
        print(f"morea batch: error: {e}", file=sys.stderr)
        return 2
    return 1 if result.failed else 0


if __name__ == "__main__":
    sys.exit(main())
