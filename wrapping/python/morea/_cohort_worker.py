# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""What a Dask worker does for one registration of a cohort: run `morea
register` on it (resuming from its checkpoint when an earlier attempt was
killed), keep its log, and return a record of how it went. A registration
that fails is a record with its error, not an exception, so that the batch
goes on and Dask does not run it again."""
import ctypes
import errno
import fcntl
import json
import os
import re
import signal
import socket
import subprocess
import time

from ._cohort_table import SUMMARY

EVENT_TOPIC = "morea-batch"
LOCK_FILE = ".morea.lock"
_GENERATION = re.compile(r"generation (\d+)/(\d+)")
_RESUMED = re.compile(r"resumed from generation (\d+)")
_ERROR = re.compile(r"^morea: error: (.*)$")

try:
    _prctl = ctypes.CDLL(None, use_errno=True).prctl
except (OSError, AttributeError):  # not Linux
    _prctl = None


def _die_with_parent():
    """In the child before exec: SIGKILL when the worker that started it dies,
    so that a killed worker leaves no registration running on (and holding
    its folder's lock) when Dask runs it again elsewhere."""
    if _prctl is not None:
        _prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG


def _worker():
    try:
        from distributed import get_worker

        return get_worker()
    except (ImportError, ValueError):
        return None


def _event(worker, message):
    if worker is None:
        return
    try:
        worker.log_event(EVENT_TOPIC, message)
    except Exception:  # progress is a courtesy; the registration goes on
        pass


def _wait_for_folder(output, seconds):
    """Waits until no process holds the output folder's lock (a registration
    killed with its worker may take a moment to go); True when free."""
    path = os.path.join(output, LOCK_FILE)
    deadline = time.monotonic() + seconds
    while True:
        try:
            fd = os.open(path, os.O_RDONLY)
        except FileNotFoundError:
            return True
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            fcntl.flock(fd, fcntl.LOCK_UN)
            return True
        except OSError as e:
            if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN):
                return True
        finally:
            os.close(fd)
        if time.monotonic() > deadline:
            return False
        time.sleep(0.5)


def available_cores():
    """The cores this process may run on (a cluster job's share, not the whole machine's)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def _gpu_name(note):
    """The device's name in the backend note ('auto: CUDA device 0 (NVIDIA H200, ...')."""
    m = re.search(r"CUDA device \d+ \(([^,)]+)", note or "")
    return m.group(1) if m else ""


def _error_of(lines, returncode):
    errors = [m.group(1) for m in (_ERROR.match(line) for line in lines) if m]
    if errors:
        return " ".join(errors)
    tail = [line for line in lines if line.strip() and not line.startswith("Run with --help")]
    if returncode < 0:
        name = signal.Signals(-returncode).name if -returncode in signal.Signals._value2member_map_ else -returncode
        return f"morea register was killed by signal {name}" + (f" after: {tail[-1]}" if tail else "")
    return " ".join(tail[-3:]) or f"morea register failed with exit status {returncode}"


def finished_record(registration, status):
    """The record of a registration whose folder holds a complete result."""
    with open(os.path.join(registration.output, SUMMARY)) as f:
        summary = json.load(f)
    seconds = summary.get("seconds", {})
    return {"id": registration.id, "status": status, "error": "", "output": registration.output,
            "backend": summary.get("backend", ""), "gpu": _gpu_name(summary.get("backend_note", "")),
            "seed": summary.get("seed", ""), "front_size": summary.get("front_size", ""),
            "generations": summary.get("generations", ""), "seconds_command": seconds.get("command", ""),
            "seconds_optimisation": seconds.get("optimisation", "")}


def run_registration(registration, morea, log_folder, threads=0, checkpoint_every="30s"):
    """Runs one registration with `morea register` and returns its record.
    An earlier attempt's checkpoint (its worker died) is resumed; a folder
    with a complete result is not touched."""
    worker = _worker()
    started = time.time()
    record = {"id": registration.id, "output": registration.output,
              "worker": worker.name if worker is not None else socket.gethostname(),
              "host": socket.gethostname(),
              # the GPU it runs on: the first of those visible (LocalCUDACluster lists them all, its own first)
              "device": os.environ.get("CUDA_VISIBLE_DEVICES", "").split(",")[0].strip(),
              "resumed_at_generation": 0}
    if registration.finished():
        return {**finished_record(registration, "skipped"), **record}
    if not _wait_for_folder(registration.output, 60):
        return {**record, "status": "failed", "seconds": 0.0,
                "error": f"the output folder {registration.output} stays locked by another process"}
    threads = int(threads) or available_cores()
    command = [morea, "register", *registration.arguments, "-o", registration.output, "--resume",
               "--checkpoint-every", str(checkpoint_every), "--threads", str(threads),
               "--set", "num_runs=1", "--set", "zip=false"]
    os.makedirs(log_folder, exist_ok=True)
    log_path = os.path.join(log_folder, registration.id + ".log")
    record["log"] = log_path
    _event(worker, {"id": registration.id, "state": "running", "worker": record["worker"],
                    "device": record["device"], "time": started})
    lines = []
    with open(log_path, "a", buffering=1) as log:
        log.write(f"== {time.strftime('%Y-%m-%d %H:%M:%S')} on {record['host']} ({record['worker']}"
                  f"{', CUDA_VISIBLE_DEVICES=' + record['device'] if record['device'] else ''})\n")
        log.write("$ " + " ".join(command) + "\n")
        try:
            child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                     bufsize=1, stdin=subprocess.DEVNULL, preexec_fn=_die_with_parent)
        except OSError as e:
            return {**record, "status": "failed", "seconds": time.time() - started,
                    "error": f"cannot run '{morea}': {e.strerror}"}
        for line in child.stdout:
            log.write(line)
            line = line.rstrip("\n")
            lines.append(line)
            del lines[:-200]
            m = _GENERATION.search(line)
            if m:
                _event(worker, {"id": registration.id, "state": "generation", "generation": int(m.group(1)),
                                "total": int(m.group(2)), "time": time.time()})
            m = _RESUMED.search(line)
            if m:
                record["resumed_at_generation"] = int(m.group(1))
        returncode = child.wait()
        log.write(f"== exit status {returncode}\n")
    seconds = time.time() - started
    if returncode == 0 and registration.finished():
        out = {**finished_record(registration, "finished"), **record, "seconds": seconds}
    else:
        out = {**record, "status": "failed", "seconds": seconds, "error": _error_of(lines, returncode)}
    _event(worker, {"id": registration.id, "state": out["status"], "time": time.time()})
    return out
