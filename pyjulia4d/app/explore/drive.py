"""Driving the explorer from a script: ``pyjulia4d explore`` in a child process, and headless
Chromium on its page (selenium; Debian's chromium and chromium-driver) - what the browser tests
and benchmarks/speed/explore_latency.py use."""
from __future__ import annotations

import queue
import shutil
import subprocess
import sys
import threading
from typing import Any, Sequence

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
BROWSER_ARGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1400,1000")
HOW_TO_GET = ("needs headless Chromium, its driver and selenium: apt-get install chromium chromium-driver, and "
              "pip install selenium (in the test extras)")


def browser_paths() -> tuple[str | None, str | None]:
    """(the Chromium binary, chromedriver), each None where it is not on PATH."""
    return next((p for p in map(shutil.which, BROWSERS) if p), None), shutil.which("chromedriver")


def headless_chromium() -> Any:
    """A selenium driver of headless Chromium; RuntimeError saying how to get one where missing."""
    chromium, driver = browser_paths()
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        chromium = None
    if chromium is None or driver is None:
        raise RuntimeError(HOW_TO_GET)
    options = webdriver.ChromeOptions()
    for arg in BROWSER_ARGS:
        options.add_argument(arg)
    options.binary_location = chromium
    return webdriver.Chrome(service=Service(driver), options=options)


def start_server(args: Sequence[str], env: dict | None = None, timeout: float = 120.0
                 ) -> tuple[subprocess.Popen, str]:
    """``python -m pyjulia4d explore --no-browser --port 0 ARGS`` in a child process: the
    process and the address its first line says it listens on.  RuntimeError, with what it
    printed, where it does not start within ``timeout`` seconds."""
    proc = subprocess.Popen([sys.executable, "-m", "pyjulia4d", "explore", "--no-browser", "--port", "0", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(x) for x in proc.stdout], daemon=True).start()
    try:
        line = lines.get(timeout=timeout)
    except queue.Empty:
        line = ""
    if "listening on " not in line:
        stop_server(proc)
        raise RuntimeError(f"explore did not start: {line.strip()} {proc.stderr.read().strip()}")
    return proc, line.split("listening on ")[1].split()[0]


def stop_server(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.wait(15)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
