# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""morea.batch: cohorts of phantom problems on a Dask LocalCluster, each
registration `morea register` (MOREA_BIN) on a worker."""
import csv
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time

import pytest
from conftest import TINY

import morea

# A dependency of the package (pip install .); the build tree's interpreter may lack it.
LocalCluster = pytest.importorskip("distributed").LocalCluster
from morea.cohort import RESOURCE, main, make_cluster  # noqa: E402

CASES = ("pelvis", "bladder-emptying", "static-bones")


@pytest.fixture(scope="module")
def problems(tmp_path_factory):
    """Three phantom cases and a bad input: the pelvis with its fixed image cut short."""
    folder = tmp_path_factory.mktemp("cohort-problems")
    for case in CASES:
        subprocess.run([os.environ["MOREA_BIN"], "phantom", "--case", case, "--spacing", "4", "-o",
                        str(folder / case)], check=True, capture_output=True)
    shutil.copytree(folder / "pelvis", folder / "truncated")
    data = (folder / "pelvis" / "fixed.nii.gz").read_bytes()
    (folder / "truncated" / "fixed.nii.gz").write_bytes(data[:len(data) // 3])
    parameters = folder / "tiny.toml"
    parameters.write_text("".join(f"{k} = {v}\n" for k, v in TINY.items()))
    return folder


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_cohort_with_a_bad_input_finishes_the_others_and_a_rerun_skips_them(problems, tmp_path):
    table = problems / "cohort.csv"
    table.write_text("id,problem,seed\n"
                     "pelvis,pelvis,1\nemptying,bladder-emptying,2\nbones,static-bones,3\nbroken,truncated,4\n")
    out = tmp_path / "batch"
    result = morea.batch(str(table), str(out), cluster="local-cpu", workers=2, parameters=problems / "tiny.toml",
                         backend="cpu", progress=False)
    status = {r["id"]: r for r in result.records}
    assert [r["id"] for r in result.records] == ["pelvis", "emptying", "bones", "broken"]
    assert [status[i]["status"] for i in ("pelvis", "emptying", "bones")] == ["finished"] * 3
    assert status["broken"]["status"] == "failed"
    assert "truncated" in status["broken"]["error"] and "fixed.nii.gz" in status["broken"]["error"]
    # Whole results only: the bad input left no folder, the others no staging folder.
    assert not (out / "broken").exists()
    for rid in ("pelvis", "emptying", "bones"):
        summary = json.loads((out / rid / "summary.json").read_text())
        assert summary["backend"] == "cpu" and summary["generations"] == TINY["ea_num_generations"]
        assert summary["problem_id"] == rid
        assert not (out / rid / ".outputs.partial").exists()
    assert json.loads((out / "pelvis" / "summary.json").read_text())["seed"] == 1
    assert json.loads((out / "bones" / "summary.json").read_text())["seed"] == 3
    # The table of registrations and the summary per registration, solution and structure.
    registrations = read_csv(out / "registrations.csv")
    assert [(r["id"], r["status"]) for r in registrations] == [
        ("pelvis", "finished"), ("emptying", "finished"), ("bones", "finished"), ("broken", "failed")]
    assert all(float(r["seconds"]) > 0 and r["backend"] == "cpu" for r in registrations[:3])
    rows = read_csv(out / "cohort_summary.csv")
    bladder = {(r["id"], r["solution"]): r for r in rows if r["structure"] == "bladder"}
    for rid in ("pelvis", "emptying", "bones"):
        for solution in ("rigid_baseline", "best_guidance", "knee"):
            row = bladder[(rid, solution)]
            assert 0.0 <= float(row["dice"]) <= 1.0 and float(row["hausdorff95_mm"]) >= 0.0
            assert row["backend"] == "cpu" and float(row["seconds_optimisation"]) > 0
    scores = json.loads((out / "bones" / "summary.json").read_text())["solutions"]["knee"]["scores"]
    assert float(bladder[("bones", "knee")]["dice"]) == pytest.approx(scores["structures"]["bladder"]["dice"], rel=1e-5)
    failed = [r for r in rows if r["id"] == "broken"]
    assert len(failed) == 1 and "truncated" in failed[0]["error"]
    assert (out / "plots" / "dice.png").stat().st_size > 0 and (out / "plots" / "hausdorff95.png").stat().st_size > 0
    assert "truncated" in (out / "logs" / "broken.log").read_text()

    # A rerun skips the finished three (their folders untouched) and tries the bad one again.
    written = {rid: (out / rid / "summary.json").stat().st_mtime_ns for rid in ("pelvis", "emptying", "bones")}
    again = morea.batch(str(table), str(out), cluster="local-cpu", workers=2, parameters=problems / "tiny.toml",
                        backend="cpu", progress=False)
    assert [r["status"] for r in again.records] == ["skipped", "skipped", "skipped", "failed"]
    assert {rid: (out / rid / "summary.json").stat().st_mtime_ns for rid in written} == written
    rows = read_csv(out / "cohort_summary.csv")
    assert {r["id"] for r in rows if r["solution"] == "best_guidance"} == {"pelvis", "emptying", "bones"}


def test_table_errors_are_refused_before_anything_runs(problems, tmp_path):
    bad_column = problems / "bad-column.csv"
    bad_column.write_text("id,problem,generations\na,pelvis,3\n")
    with pytest.raises(ValueError, match="unknown column.*generations"):
        morea.batch(str(bad_column), str(tmp_path / "a"), progress=False)
    twice = problems / "twice.csv"
    twice.write_text("id,problem\na,pelvis\na,static-bones\n")
    with pytest.raises(ValueError, match="one id 'a'"):
        morea.batch(str(twice), str(tmp_path / "b"), progress=False)
    no_problem = problems / "no-problem.csv"
    no_problem.write_text("id,fixed\na,pelvis/fixed.nii.gz\n")
    with pytest.raises(ValueError, match="row 2: give a problem folder"):
        morea.batch(str(no_problem), str(tmp_path / "c"), progress=False)
    with pytest.raises(ValueError, match="checkpoint_every '10 generations'"):
        morea.batch(str(twice), str(tmp_path / "e"), checkpoint_every="10 generations", progress=False)
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists() and not (tmp_path / "e").exists()
    # The command line says so and exits with 2.
    assert main([str(twice), "-o", str(tmp_path / "d"), "--quiet"], morea=os.environ["MOREA_BIN"]) == 2


def test_jobqueue_clusters_get_one_registration_per_worker(tmp_path):
    pytest.importorskip("dask_jobqueue")
    cluster, note = make_cluster("slurm", jobs=0, options={
        "queue": "gpu", "cores": 16, "memory": "64GB", "walltime": "02:00:00",
        "job_extra_directives": ["--gres=gpu:1"], "log_directory": str(tmp_path)})
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    assert "SLURMCluster" in note
    assert "#SBATCH -p gpu" in script and "#SBATCH --gres=gpu:1" in script and "#SBATCH -t 02:00:00" in script
    assert f"--resources {RESOURCE}=1" in script


KILL_GENERATIONS = 150


def _parent_of(pid):
    with open(f"/proc/{pid}/stat") as f:
        return int(f.read().rsplit(")", 1)[1].split()[1])


def _last_generation(log):
    """The last generation a registration's log reports (0: none yet)."""
    if not log.exists():
        return 0
    found = re.findall(rf"generation (\d+)/{KILL_GENERATIONS}", log.read_text())
    return int(found[-1]) if found else 0


def test_a_killed_worker_s_registration_resumes_from_its_checkpoint_to_the_same_front(problems, tmp_path):
    out = tmp_path / "batch"
    rows = [{"id": rid, "problem": str(problems / "pelvis"), "seed": 5} for rid in ("killed", "whole")]
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, resources={RESOURCE: 1},
                           dashboard_address=":0")
    outcome = {}

    def run():
        try:
            outcome["result"] = morea.batch(rows, str(out), cluster=cluster, parameters=problems / "tiny.toml",
                                            overrides={"ea_num_generations": KILL_GENERATIONS}, backend="cpu",
                                            checkpoint_every=2, progress=False, plots=False)
        except BaseException as e:  # reported by the main thread
            outcome["error"] = e

    batch = threading.Thread(target=run)
    batch.start()
    try:
        # Once the checkpoint of generation 10 is whole, kill the worker running it.
        # Checkpoints are written behind the run, one at a time (the next one
        # starts only after it), and a generation is logged after its own
        # checkpoint has started: a logged generation past 10 means 10 is on disk.
        log = out / "logs" / "killed.log"
        deadline = time.monotonic() + 240
        while _last_generation(log) <= 10:
            assert time.monotonic() < deadline and batch.is_alive(), outcome.get("error")
            time.sleep(0.2)
        assert (out / "killed" / "checkpoint.bin").exists()
        child = int((out / "killed" / ".morea.lock").read_text().split()[0])
        worker = _parent_of(child)
        assert worker in {w.process.pid for w in cluster.workers.values()}
        os.kill(worker, signal.SIGKILL)
        batch.join(timeout=300)
        assert not batch.is_alive(), "the batch did not finish"
    finally:
        batch.join(timeout=60)
        cluster.close()
    assert "error" not in outcome, outcome.get("error")
    # The registration died with its worker (it did not run on, holding its folder).
    with pytest.raises(ProcessLookupError):
        os.kill(child, 0)
    records = {r["id"]: r for r in outcome["result"].records}
    assert records["killed"]["status"] == "finished" and records["whole"]["status"] == "finished"
    assert int(records["killed"]["resumed_at_generation"]) >= 10
    assert int(records["whole"]["resumed_at_generation"]) == 0
    log = (out / "logs" / "killed.log").read_text()
    assert log.count("$ ") == 2 and "resumed from generation" in log
    front = lambda rid: (out / rid / "front.csv").read_text()  # noqa: E731
    assert front("killed") == front("whole")
    summaries = [json.loads((out / rid / "summary.json").read_text()) for rid in ("killed", "whole")]
    assert summaries[0]["generations"] == summaries[1]["generations"] == KILL_GENERATIONS


def test_a_worker_that_finishes_early_takes_the_next_registration(problems, tmp_path):
    # Two workers, one long registration and two short ones: the second short
    # one waits for room and goes to the worker the first short one freed,
    # not to a queue behind the long one.
    pelvis = problems / "pelvis"
    table = tmp_path / "cohort.csv"
    table.write_text("id,problem,seed,set\n"
                     f"long,{pelvis},1,ea_num_generations=80\nshort1,{pelvis},2,ea_num_generations=3\n"
                     f"short2,{pelvis},3,ea_num_generations=3\n")
    result = morea.batch(str(table), str(tmp_path / "out"), cluster="local-cpu", workers=2, threads=1,
                         parameters=problems / "tiny.toml", backend="cpu", progress=False, plots=False)
    records = {r["id"]: r for r in result.records}
    assert [records[i]["status"] for i in ("long", "short1", "short2")] == ["finished"] * 3
    assert records["short2"]["worker"] == records["short1"]["worker"] != records["long"]["worker"]


def test_morea_batch_runs_the_python_package(problems, tmp_path):
    table = tmp_path / "cohort.csv"
    table.write_text(f"id,problem,seed,set\none,{problems / 'static-bones'},7,ea_num_generations=3\n")
    env = {**os.environ, "MOREA_PYTHON": sys.executable}
    done = subprocess.run([os.environ["MOREA_BIN"], "batch", str(table), "-o", str(tmp_path / "out"),
                           "--cluster", "local-cpu", "--workers", "1", "--parameters", str(problems / "tiny.toml"),
                           "--backend", "cpu", "--no-plots"], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "1 finished, 0 skipped, 0 failed" in done.stderr
    assert json.loads((tmp_path / "out" / "one" / "summary.json").read_text())["generations"] == 3
    # With a Python that lacks the package the command says what is missing.
    bare = shutil.which("python3", path="/usr/bin:/bin")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    if bare is None or subprocess.run([bare, "-c", "import morea"], env=env, cwd=tmp_path,
                                      capture_output=True).returncode == 0:
        pytest.skip("no Python without the package here")
    missing = subprocess.run([os.environ["MOREA_BIN"], "batch", str(table)], capture_output=True, text=True,
                             env={**env, "MOREA_PYTHON": bare}, cwd=tmp_path, timeout=120)
    assert missing.returncode == 2
    assert "the Python package 'morea' is not importable" in missing.stderr
