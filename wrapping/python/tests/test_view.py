# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""The front navigator (morea.view, `morea view`) and the plots every run
writes: the page driven in a real headless browser (Chromium with
chromedriver, through selenium), runs made by Python and by the command
line, and folders that are not complete runs."""
import fcntl
import json
import os
import shutil
import subprocess
import sys
import threading
import time
import urllib.request

import numpy as np
import pytest
import SimpleITK as sitk
from conftest import TINY

import morea
from morea import view

PNG = b"\x89PNG\r\n\x1a\n"
# A run with a front of a few distinct solutions, still small.
# The page's test needs front members whose slices differ. In so short a run,
# the rigid strain limit keeps most of the population near its start (it
# violates the limit at first), so the limit is off here.
PARAMETERS = dict(TINY, ea_num_generations=8, morea_rigid_strain_limit=0.0)


@pytest.fixture(scope="module")
def python_run(phantom, tmp_path_factory):
    """A run made by morea.register and saved with result.save."""
    result = morea.register(phantom["fixed"], phantom["moving"], structures=phantom["masks"], parameters=PARAMETERS,
                            backend="cpu", select="best-guidance,knee", seed=5, progress=False)
    folder = tmp_path_factory.mktemp("view") / "python-run"
    result.save(folder)
    return folder, result


@pytest.fixture(scope="module")
def cli_run(phantom, tmp_path_factory):
    """A run made by `morea register`."""
    root = tmp_path_factory.mktemp("view-cli")
    toml = root / "tiny.toml"
    toml.write_text("".join(f"{k} = {v}\n" for k, v in PARAMETERS.items()))
    folder = root / "cli-run"
    subprocess.run([os.environ["MOREA_BIN"], "register", "--problem", str(phantom["folder"]), "--parameters", str(toml),
                    "--backend", "cpu", "-o", str(folder)], check=True, capture_output=True)
    return folder


def served(folder):
    """The page of `folder` served on a free port in this process; (url, server)."""
    server = view.serve(folder, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    host, port = server.server_address[:2]
    return f"http://{host}:{port}/", server


def fetch(url, method="GET"):
    with urllib.request.urlopen(urllib.request.Request(url, method=method), timeout=120) as response:
        return response.read()


def test_every_run_writes_plots_and_keeps_its_front(python_run, cli_run):
    folder, result = python_run
    for run in (folder, cli_run):
        for name in ("plot_front.png", "plot_convergence.png", "front_meshes.bin", "preprocessed/fixed.mha",
                     "preprocessed/problem.json"):
            assert (run / name).is_file(), f"{run}/{name}"
        for label in ("best_guidance", "knee"):
            for axis in ("axial", "coronal", "sagittal"):
                plot = run / label / f"plot_{axis}.png"
                data = plot.read_bytes()
                assert data.startswith(PNG), plot
                width = int.from_bytes(data[16:20], "big")
                assert width >= 800, f"{plot} is {width} px wide"
        assert int.from_bytes((run / "plot_front.png").read_bytes()[16:20], "big") >= 800


def test_pages_of_cli_and_python_runs_answer(python_run, cli_run):
    for folder in (python_run[0], cli_run):
        url, server = served(folder)
        try:
            run = json.loads(fetch(url + "api/run"))
            assert len(run["front"]) == json.loads((folder / "summary.json").read_text())["front_size"]
            # One solution may be both (its label then "best_guidance;knee").
            assert {c for s in run["front"] for c in s["chosen"].split(";")} >= {"best_guidance", "knee"}
            page = fetch(url).decode()
            assert "/static/view.js" in page and "http" not in page.replace("http-equiv", "")
            assert fetch(url + "api/slice?solution=0&axis=coronal&view=jacobian").startswith(PNG)
            assert fetch(url + "static/view.css")
        finally:
            server.shutdown()
            server.server_close()


def browser():
    """Headless Chromium through chromedriver; skipped when absent unless
    MOREA_REQUIRE_BROWSER is set (CI installs them)."""
    required = os.environ.get("MOREA_REQUIRE_BROWSER") == "1"
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        if required:
            raise
        pytest.skip("selenium is not installed")
    driver_path = shutil.which("chromedriver") or "/usr/bin/chromedriver"
    chromium = shutil.which("chromium") or shutil.which("chromium-browser") or shutil.which("google-chrome")
    if not os.path.exists(driver_path) or chromium is None:
        if required:
            pytest.fail("chromium and chromedriver are needed (apt-get install chromium chromium-driver)")
        pytest.skip("chromium or chromedriver is not installed")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                     "--window-size=1400,1000"):
        options.add_argument(argument)
    return webdriver.Chrome(service=Service(driver_path), options=options)


def wait_for(driver, script, timeout=120):
    """Waits until `script` (JavaScript returning a value) returns a truthy value; returns it."""
    end = time.time() + timeout
    while time.time() < end:
        value = driver.execute_script(script)
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for: {script}")


SHOWN = """
const img = document.getElementById('slice-image'), scores = document.getElementById('scores');
if (!img.dataset.loaded || img.dataset.solution !== arguments[0] || scores.dataset.solution !== arguments[0]
    || !img.complete || img.naturalWidth === 0) return null;
const canvas = document.createElement('canvas');
canvas.width = img.naturalWidth; canvas.height = img.naturalHeight;
canvas.getContext('2d').drawImage(img, 0, 0);
return [canvas.toDataURL('image/png'), scores.innerText, img.naturalWidth];
"""


def show(driver, index):
    """Clicks solution `index` in the scatter plot; returns (slice image pixels, scores text, width)."""
    driver.find_element("css selector", f"#scatter circle.point[data-index='{index}']").click()
    return driver.execute_script(SHOWN.replace("arguments[0]", repr(str(index)))) or wait_for(
        driver, SHOWN.replace("arguments[0]", repr(str(index))))


def test_the_page_in_a_browser_shows_solutions_and_exports_one(python_run):
    folder, result = python_run
    url, server = served(folder)
    driver = browser()
    try:
        driver.get(url)
        wait_for(driver, "return document.body.dataset.ready === '1'")
        points = driver.find_elements("css selector", "#scatter circle.point")
        lines = driver.find_elements("css selector", "#parallel polyline.line")
        assert len(points) == len(result.front) == len(lines)
        assert "guidance" in driver.find_element("id", "scatter").text
        order = np.argsort(result.front["guidance"], kind="stable")
        first, second = int(order[0]), int(order[-1])
        assert first != second
        image_a, scores_a, width = show(driver, first)
        image_b, scores_b, _ = show(driver, second)
        assert width >= 256
        assert image_a != image_b, "the slice image did not change with the solution"
        assert scores_a != scores_b, "the scores did not change with the solution"
        assert "Dice" in scores_b and "bladder" in scores_b
        # Another axis and view of the same solution.
        driver.find_element("css selector", "button.axis[data-axis='coronal']").click()
        wait_for(driver, "return document.getElementById('slice-image').dataset.loaded.includes('axis=coronal')")
        # Export writes a transform SimpleITK reads, the solution's own.
        driver.find_element("id", "export").click()
        exported = wait_for(driver, "return document.getElementById('export-status').dataset.folder")
        assert os.path.basename(exported) == f"solution_{int(result.front['id'][second])}"
        transform = sitk.ReadTransform(os.path.join(exported, "fixed_to_moving.h5"))
        solution = morea.Solution(result, second, "exported")
        for p in ((5.0, -12.0, 20.0), (-20.0, 10.0, -5.0)):
            assert np.allclose(transform.TransformPoint(p), solution.fixed_to_moving.TransformPoint(p), atol=1e-6)
        field = sitk.ReadImage(os.path.join(exported, "preprocessed_fixed_to_moving.nii.gz"))
        assert np.allclose(sitk.GetArrayFromImage(field), solution.fields()[0][0], atol=1e-9)
        scores = json.loads(open(os.path.join(exported, "scores.json")).read())
        assert scores["scores"]["structures"]["bladder"]["dice"] == pytest.approx(
            solution.scores["structures"]["bladder"]["dice"], abs=1e-12)
        assert not [n for n in os.listdir(folder) if n.startswith(".") and n != ".morea.lock"]
    finally:
        driver.quit()
        server.shutdown()
        server.server_close()


def run_view(folder, *arguments, command=None):
    command = command or [sys.executable, "-m", "morea.view"]
    return subprocess.run(command + [str(folder), "--port", "0", *arguments], capture_output=True, text=True,
                          timeout=120)


def test_folders_that_are_not_complete_runs_are_refused(python_run, phantom, tmp_path):
    folder, _ = python_run
    empty = tmp_path / "empty"
    empty.mkdir()
    half = tmp_path / "half"
    shutil.copytree(folder, half)
    (half / "summary.json").unlink()
    (half / ".outputs.partial").mkdir()
    cases = [(empty, "is not a MOREA run folder"), (tmp_path / "absent", "does not exist"),
             (phantom["folder"], "is not a MOREA run folder"), (half, "holds no complete run"),
             (folder / "front.csv", "is not a folder")]
    for path, message in cases:
        for command in (None, [os.environ["MOREA_BIN"], "view"]):
            done = run_view(path, command=command)
            assert done.returncode != 0, (path, done.stdout)
            assert message in done.stderr, (path, done.stderr)
    # A run still writing its folder (it holds the folder's lock).
    busy = tmp_path / "busy"
    shutil.copytree(folder, busy)
    with open(busy / ".morea.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        done = run_view(busy)
    assert done.returncode != 0 and "is being written by a run right now" in done.stderr, done.stderr
    with pytest.raises(view.RunNotViewable, match="holds no complete run"):
        view.serve(half, port=0)


def test_morea_view_command_serves_a_cli_run(cli_run):
    env = dict(os.environ, MOREA_PYTHON=sys.executable)
    process = subprocess.Popen([os.environ["MOREA_BIN"], "view", str(cli_run), "--port", "0"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    try:
        url = None
        for _ in range(5):
            line = process.stdout.readline()
            if "serving" in line:
                url = line.split("serving ")[1].split()[0]
                break
        assert url, process.stderr.read() if process.poll() is not None else "no URL printed"
        front = json.loads(fetch(url + "api/run"))["front"]
        assert front
        last = len(front) - 1
        assert fetch(url + f"api/slice?solution={last}&axis=sagittal&view=grid").startswith(PNG)
        exported = json.loads(fetch(url + f"api/export?solution={last}", method="POST"))["folder"]
        assert sitk.ReadTransform(os.path.join(exported, "moving_to_fixed.h5"))
    finally:
        process.terminate()
        process.wait(timeout=30)
