"""The browser viewer end to end: ``rd.viewer.show`` serves the scene, headless Chromium
(Debian's ``chromium`` and ``chromium-driver``, driven by selenium) renders it with WebGL
(SwiftShader), and the screenshots show the robot, its motion under the time slider and the
play button's effect on the server. Skipped only when no Chromium binary exists."""

from __future__ import annotations

import io
import shutil
import socket
import time
import warnings

import numpy as np
import pytest
from PIL import Image

import robodyn as rd
from conftest import example_robot_data_dir
from robodyn.errors import RobodynWarning
from robodyn.io.log import write_log

CHROMIUM = next((p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None)
pytestmark = [pytest.mark.browser, pytest.mark.skipif(
    CHROMIUM is None, reason="no Chromium binary (apt-get install chromium chromium-driver)")]

SIZE = (800, 600)


@pytest.fixture
def browser(tmp_path):
    from selenium import webdriver

    driver_path = shutil.which("chromedriver")
    assert driver_path, "Chromium is installed but chromedriver is not: apt-get install chromium-driver"
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--no-first-run", "--enable-unsafe-swiftshader",
                f"--window-size={SIZE[0]},{SIZE[1]}", f"--user-data-dir={tmp_path / 'chromium-profile'}"):
        options.add_argument(arg)
    driver = webdriver.Chrome(service=webdriver.ChromeService(driver_path), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def shot(driver) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB"), dtype=int)


def changed(a, b) -> float:
    """The fraction of the pixels of the 3-D view (its left 55 %, clear of the GUI panel) that differ."""
    w = a.shape[1] * 11 // 20
    return float((np.abs(a[:, :w] - b[:, :w]).sum(-1) > 40).mean())


def settle(driver, differs_from=None, timeout=60.0) -> np.ndarray:
    """The screenshot once the view has stopped changing for three shots in a row, at least
    two seconds (the scene fades in as it loads), and differs from ``differs_from``."""
    end, shots = time.monotonic() + timeout, [(time.monotonic(), shot(driver))]
    while time.monotonic() < end:
        time.sleep(0.7)
        now = shot(driver)
        if changed(now, shots[-1][1]) >= 1e-4 or (differs_from is not None and changed(now, differs_from) < 0.005):
            shots = []
        shots.append((time.monotonic(), now))
        if len(shots) >= 3 and shots[-1][0] - shots[0][0] >= 2.0:
            return now
    raise AssertionError("the view did not settle")


def test_viewer_shows_the_robot_and_plays_the_trajectory(browser, tmp_path):
    path = example_robot_data_dir() / "solo_description/robots/solo12.urdf"  # STL meshes, 50k triangles
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RobodynWarning)
        model = rd.load_urdf(path, floating_base=True)
    t = np.linspace(0.0, 2.0, 41)
    q = np.tile([0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 1.0] + [0.0, 0.8, -1.6] * 4, (len(t), 1))
    yaw = np.linspace(0.0, 1.2, len(t))  # the body turns about z
    q[:, 5], q[:, 6] = np.sin(yaw / 2), np.cos(yaw / 2)
    q[:, 7::3] = np.linspace(0.0, 0.6, len(t))[:, None]  # and spreads its legs
    log = tmp_path / "turn.csv"
    write_log(log, model, t, q)
    viewer = rd.viewer.show(model, trajectory=log, visuals=path, port=0, block=False)
    port = viewer.server.get_port()
    try:
        browser.get(viewer.url)
        robot = settle(browser)
        for frame in viewer.bodies + [viewer.world]:  # the same view without the robot
            frame.visible = False
        empty = settle(browser, differs_from=robot)
        assert changed(robot, empty) > 0.01  # the robot covers part of the view
        for frame in viewer.bodies + [viewer.world]:
            frame.visible = True
        settle(browser, differs_from=empty)
        viewer.slider.value = 2.0  # the end of the motion: the arm has turned
        assert viewer.sample == 40
        moved = settle(browser, differs_from=robot)
        assert changed(robot, moved) > 0.005
        button = next(b for b in browser.find_elements("tag name", "button") if b.text.strip() == "Play")
        button.click()  # from the browser: the server plays (the slider wraps to the start, then moves on)
        deadline = time.monotonic() + 10
        while not (viewer.playing and 0.2 < viewer.slider.value < 1.9) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert viewer.playing and 0.2 < viewer.slider.value < 1.9
    finally:
        viewer.stop()
    with pytest.raises(ConnectionRefusedError):  # the server is gone
        socket.create_connection(("127.0.0.1", port), timeout=2).close()
