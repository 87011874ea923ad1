"""The explorer in a real browser: headless Chromium (Debian's chromium and chromium-driver)
driven by selenium opens the page `pyjulia4d explore` serves, moves its controls, drags the
picture, saves the scene, which `pyjulia4d render` turns into the same picture, and watches a
path-traced picture refine at rest and its lens focus where the picture is clicked.

Skipped, with the reason, where no browser is installed (.ci/run installs one)."""
import base64
import io
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from PIL import Image

from pyjulia4d.scene.model import Scene

from pyjulia4d.app.explore.drive import HOW_TO_GET, browser_paths, headless_chromium, start_server, stop_server

try:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:   # pragma: no cover
    ActionChains = None

pytestmark = pytest.mark.skipif(ActionChains is None or None in browser_paths(), reason=HOW_TO_GET)

WIDTH, HEIGHT = 200, 150   # small: the final stage of each change comes quickly


def _device_args():
    return ["--device", os.environ["PYJULIA4D_DEVICE"]] if os.environ.get("PYJULIA4D_DEVICE") else []


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("explore")


@pytest.fixture(scope="module")
def server(folder):
    """`pyjulia4d explore` in a child process: its address."""
    proc, url = start_server(["--folder", str(folder), "--set", f"image.width={WIDTH}",
                              "--set", f"image.height={HEIGHT}", *_device_args()])
    assert url.startswith("http://127.0.0.1:")
    yield url
    stop_server(proc)


@pytest.fixture(scope="module")
def browser():
    driver = headless_chromium()
    yield driver
    driver.quit()


@pytest.fixture
def page(server, browser):
    browser.get(server)
    wait_final(browser, 0)
    return browser


def view(driver):
    return driver.find_element(By.ID, "view")


def count(driver) -> int:
    return int(view(driver).get_attribute("data-count") or 0)


def wait_final(driver, after: int, timeout: float = 60) -> None:
    """Until a picture after the ``after``-th is the final stage."""
    WebDriverWait(driver, timeout).until(
        lambda d: count(d) > after and view(d).get_attribute("data-stage") == "final")


def picture(driver) -> np.ndarray:
    """The PNG the page shows, read back through its blob URL."""
    data = driver.execute_async_script("""
        const done = arguments[arguments.length - 1];
        fetch(document.getElementById('view').src).then(r => r.arrayBuffer()).then(b => {
            const u = new Uint8Array(b); let s = '';
            for (let i = 0; i < u.length; i += 8192) s += String.fromCharCode(...u.subarray(i, i + 8192));
            done(btoa(s));
        });""")
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(data))))


def field(driver, name):
    return driver.find_element(By.NAME, name)


def type_into(driver, name, text):
    el = field(driver, name)
    el.clear()
    el.send_keys(text, Keys.TAB)   # the change event


def test_the_page_opens_to_a_picture_of_the_set(page):
    img = picture(page)
    assert img.shape == (HEIGHT, WIDTH, 3)
    lit = np.mean(np.any(img > 8, axis=2))
    assert 0.05 < lit < 0.95, lit
    facts = page.find_element(By.ID, "facts").text
    assert f"{WIDTH}x{HEIGHT}" in facts and "pixels hit" in facts
    assert page.find_element(By.ID, "error").text == ""


def test_moving_a_control_changes_the_picture(page):
    before, n = picture(page), count(page)
    type_into(page, "fractal.c[1]", "0.55")
    wait_final(page, n)
    after = picture(page)
    assert np.mean(np.any(after != before, axis=2)) > 0.02


def test_dragging_a_slider_renders_as_it_moves_then_at_rest(page):
    n = count(page)
    slider = page.find_element(By.CSS_SELECTOR, 'input[type=range][data-for="slice.distance"]')
    ActionChains(page).click_and_hold(slider).perform()
    for _ in range(6):
        ActionChains(page).move_by_offset(6, 0).perform()
        time.sleep(0.05)
    ActionChains(page).release().perform()
    wait_final(page, n)
    assert float(field(page, "slice.distance").get_attribute("value")) != 0.0
    assert count(page) > n


def test_dragging_the_picture_orbits_the_camera(page):
    before, n = picture(page), count(page)
    x0 = float(field(page, "camera.position[0]").get_attribute("value"))
    ActionChains(page).click_and_hold(view(page)).move_by_offset(40, 0).move_by_offset(40, 10).release().perform()
    wait_final(page, n)
    assert float(field(page, "camera.position[0]").get_attribute("value")) != x0
    assert np.mean(np.any(picture(page) != before, axis=2)) > 0.02


def test_a_value_out_of_range_is_one_line_in_the_page_and_the_page_goes_on(page):
    type_into(page, "fractal.c[0]", "5000")
    WebDriverWait(page, 10).until(lambda d: d.find_element(By.ID, "error").text)
    error = page.find_element(By.ID, "error").text
    assert error.startswith("fractal.c[0]: must be in [-1e3, 1e3]") and "\n" not in error
    assert "invalid" in field(page, "fractal.c[0]").get_attribute("class")
    n = count(page)
    type_into(page, "fractal.c[0]", "-0.25")
    wait_final(page, n)
    assert page.find_element(By.ID, "error").text == ""


def test_the_saved_scene_renders_to_the_same_picture_from_the_command_line(page, folder, tmp_path):
    n = count(page)
    type_into(page, "fractal.c[2]", "0.1")
    wait_final(page, n)
    shown = picture(page)
    name = page.find_element(By.ID, "scene-name")
    name.clear()
    name.send_keys("saved.toml")
    page.find_element(By.ID, "save-scene").click()
    WebDriverWait(page, 10).until(lambda d: d.find_element(By.ID, "status").text.startswith("saved"))
    saved = folder / "saved.toml"
    assert Scene.from_toml(saved).fractal.c[2] == 0.1
    out = tmp_path / "cli.png"
    subprocess.run([sys.executable, "-m", "pyjulia4d", "render", str(saved), "-o", str(out), *_device_args()],
                   check=True, capture_output=True, timeout=120)
    cli = np.asarray(Image.open(out))[..., :3]
    assert np.array_equal(cli, shown)


def facts_shown(driver) -> dict:
    """The facts panel's terms and values, read in one go (the page replaces them whole)."""
    return driver.execute_script("""
        const out = {};
        for (const dt of document.querySelectorAll('#facts dt')) out[dt.textContent] = dt.nextElementSibling.textContent;
        return out;""")


def paths_shown(driver) -> int:
    """The paths per pixel the facts panel gives (0 where it gives none)."""
    got = facts_shown(driver).get("paths per pixel", "")
    return int(got) if got.isdigit() else 0


def test_a_path_traced_picture_refines_at_rest_and_a_click_focuses_its_lens(page):
    """The path tracer in the page: at rest its paths accumulate (2, then 4, 8 and 16 a pixel),
    each picture with its stated noise; a click on the picture focuses the lens on the surface
    there (camera.focus), and the page says so."""
    from selenium.webdriver.support.ui import Select

    type_into(page, "image.samples", "16")
    Select(field(page, "shading.integrator")).select_by_value("path")
    seen = set()

    def refined(d):
        seen.add(paths_shown(d))
        return paths_shown(d) == 16

    WebDriverWait(page, 120, poll_frequency=0.05).until(refined)
    assert len(seen - {0}) >= 2 and seen <= {0, 2, 4, 8, 16}, seen   # the page may skip a batch it was sent late
    facts = facts_shown(page)
    assert facts["noise"] and facts["noise"] != "-", facts
    img = picture(page)
    assert 0.05 < np.mean(np.any(img > 8, axis=2)) < 0.95
    ActionChains(page).move_to_element(view(page)).click().perform()   # the picture's centre, on the set
    WebDriverWait(page, 30).until(lambda d: d.find_element(By.ID, "status").text.startswith("focus: "))
    assert "along the view axis (camera.focus)" in page.find_element(By.ID, "status").text
    assert page.find_element(By.ID, "error").text == ""
