#!/usr/bin/env python3
# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""Screenshot of the front navigator page of a run (docs/images/front-navigator.png).

    PYTHONPATH=build/python python tools/navigator-screenshot.py RUN_DIR OUT.png [--solution-rank N] [--view VIEW]

Serves RUN_DIR's page in this process, opens it in headless Chromium
(chromium and chromium-driver from Debian, selenium from PyPI), chooses the
solution of rank N by guidance (default: the run's first chosen one) and
writes the screenshot.
"""
import argparse
import shutil
import sys
import threading
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

from morea import view


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run")
    parser.add_argument("output")
    parser.add_argument("--solution-rank", type=int, default=None)
    parser.add_argument("--view", default="overlay")
    parser.add_argument("--size", default="1400,1180")
    args = parser.parse_args()
    server = view.serve(args.run, port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    url = "http://%s:%d/" % server.server_address[:2]
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--hide-scrollbars",
                     f"--window-size={args.size}"):
        options.add_argument(argument)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver") or "/usr/bin/chromedriver"),
                              options=options)
    try:
        driver.get(url)
        def wait(script, timeout=300):
            end = time.time() + timeout
            while not driver.execute_script(script):
                if time.time() > end:
                    raise RuntimeError(f"timed out waiting for: {script}")
                time.sleep(0.1)

        wait("return document.body.dataset.ready === '1'")
        if args.solution_rank is not None:
            index = driver.execute_script(f"return state.order[{args.solution_rank}]")
            driver.find_element("css selector", f"#scatter circle.point[data-index='{index}']").click()
        driver.execute_script(f"document.getElementById('view').value = '{args.view}';"
                              "document.getElementById('view').dispatchEvent(new Event('change'));")
        wait("const i = document.getElementById('slice-image'); return i.dataset.loaded && i.complete && "
             "document.getElementById('scores').dataset.solution !== ''")
        time.sleep(0.3)
        driver.save_screenshot(args.output)
    finally:
        driver.quit()
        server.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
