"""The run viewer in a real browser (headless Chromium driven by Playwright, the system's
browser): a reduced main job's report.html (`hrm run --duration`) and a synthetic spatial run's
page (hrm.view_html). No console errors, the picture changes with time, the slider, play and
the keyboard move it, dragging turns the 3-D view, and screenshots at fixed times match the
references in tests/browser-references within a pixel tolerance.

Skipped when Playwright, Chromium or the `hrm` binary is missing, unless HRM_REQUIRE_ENGINES=1
(CI), where that fails. HRM_UPDATE_SCREENSHOTS=1 rewrites the references (look at them).
"""

import io
import json
import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import hrm
from engines import require

ROOT = pathlib.Path(__file__).resolve().parents[3]
REFERENCES = pathlib.Path(__file__).resolve().parent / "browser-references"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
VIEWPORT = {"width": 1280, "height": 1000}


def hrm_binary():
    """The `hrm` command cargo built (HRM_BIN, else the target folder's debug or release)."""
    if os.environ.get("HRM_BIN"):
        return pathlib.Path(os.environ["HRM_BIN"])
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("debug", "release"):
        if (target / profile / "hrm").is_file():
            return target / profile / "hrm"
    require(False, f"the hrm binary (cargo build -p hrm-cli) in {target}/debug or release")


@pytest.fixture(scope="module")
def browser():
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        require(False, "Playwright (pip install playwright)")
    require(os.path.exists(CHROMIUM), "Chromium (apt-get install chromium)")
    with sync_playwright() as p:
        # No sandbox: CI runs as root, where Chromium's sandbox refuses to start.
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        yield b
        b.close()


def open_page(browser, path):
    page = browser.new_page(viewport=VIEWPORT, device_scale_factor=1)
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(path.as_uri())
    page.wait_for_function("document.querySelectorAll('.hrm-view').length > 0 && "
                           "[...document.querySelectorAll('.hrm-view')].every(v => v.hrmViewer)")
    return page, errors


def set_time(page, view, t):
    page.evaluate("([i, t]) => document.querySelectorAll('.hrm-view')[i].hrmViewer.setTime(t)", [view, t])


def arm(page, view):
    return page.locator(".hrm-view").nth(view).locator("canvas.hrm-arm").first


def pixels(png):
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)


def differs(a, b):
    """The fraction of pixels whose colour differs by more than 40 in a channel."""
    a, b = pixels(a), pixels(b)
    if a.shape != b.shape:
        return 1.0
    return float(np.mean(np.abs(a - b).max(axis=2) > 40))


def matches_reference(png, name, tolerance=0.01):
    path = REFERENCES / name
    if os.environ.get("HRM_UPDATE_SCREENSHOTS") == "1":
        REFERENCES.mkdir(exist_ok=True)
        path.write_bytes(png)
    assert path.is_file(), f"no reference {path}: run with HRM_UPDATE_SCREENSHOTS=1 and look at it"
    fraction = differs(png, path.read_bytes())
    if fraction > tolerance:
        (REFERENCES.parent / f"actual-{name}").write_bytes(png)
    assert fraction <= tolerance, f"{name}: {fraction:.2%} of the pixels differ (actual-{name} written)"


@pytest.fixture(scope="module")
def main_job(tmp_path_factory):
    out = tmp_path_factory.mktemp("main-job") / "out"
    subprocess.run([str(hrm_binary()), "run", "--duration", "1.5", "--out", str(out)],
                   check=True, capture_output=True, timeout=600)
    return out


def test_the_main_jobs_report_plays_every_scenario(browser, main_job):
    page, errors = open_page(browser, main_job / "report.html")
    views = page.locator(".hrm-view")
    assert views.count() == len(list(main_job.glob("*/fuzzy/timeseries.csv")))
    tables = page.locator("table")
    assert tables.count() == views.count()
    text = page.locator("body").inner_text()
    assert "e+" not in text and "e-0" not in text, "numbers in plain notation"
    # paper-tracking: every controller, its time series beside the arm.
    index = next(i for i, h in enumerate(page.locator("section.hrm-scene h3").all())
                 if h.inner_text().startswith("paper-tracking:"))
    view = views.nth(index)
    view.scroll_into_view_if_needed()
    set_time(page, index, 0.0)
    start = arm(page, index).screenshot()
    set_time(page, index, 1.5)
    end = arm(page, index).screenshot()
    assert differs(start, end) > 0.002, "the arm moves"
    matches_reference(end, "paper-tracking-1.5s.png")
    # The slider, the keyboard and play move the frame.
    view.locator("input.hrm-slider").fill("500")
    assert abs(float(view.get_attribute("data-time")) - 0.75) < 0.01
    view.focus()
    page.keyboard.press("Home")
    assert float(view.get_attribute("data-time")) == 0.0
    page.keyboard.press("ArrowRight")
    assert float(view.get_attribute("data-time")) > 0.0
    view.locator("button.hrm-play").click()
    page.wait_for_timeout(400)
    assert float(view.get_attribute("data-time")) > 0.1
    view.locator("button.hrm-play").click()
    # Comparison: a second controller side by side gives a second arm.
    view.locator("select.hrm-run-b").select_option(label="pd")
    assert view.locator("canvas.hrm-arm").count() == 2
    view.locator("select.hrm-layout").select_option("overlay")
    assert view.locator("canvas.hrm-arm").count() == 1
    # The scene as a reader sees it: both arms side by side and the time series.
    view.locator("select.hrm-layout").select_option("side")
    set_time(page, index, 1.0)
    matches_reference(page.locator("section.hrm-scene").nth(index).screenshot(),
                      "paper-tracking-compare-1.0s.png", tolerance=0.02)
    assert errors == [], errors


def spatial_scene(samples=120, links=8):
    """A synthetic spatial arm whose bending plane turns about the vertical, with a sphere, a
    capsule, a box and a channel, joint torques with limits and a clearance series."""
    t = np.linspace(0.0, 2.0, samples)
    joints, torques = [], []
    for time in t:
        p = np.zeros(3)
        row = [*p]
        for i in range(links):
            bend = 0.15 * (i + 1) * (1 - 0.3 * time)
            turn = 0.6 * time + 0.4 * i
            p = p + 0.1 * np.array([np.sin(bend) * np.cos(turn), np.sin(bend) * np.sin(turn), np.cos(bend)])
            row.extend(p)
        joints.append(row)
        torques.append([(links - i) * np.sin(1 + time) for i in range(links)])
    run = {
        "label": "synthetic spatial",
        "dims": 3,
        "t": t.tolist(),
        "joints": joints,
        "tip_ref": [row[-3:] for row in joints],
        "joint_torque": torques,
        "torque_limit": [float(links)] * links,
        "series": [{"title": "clearance", "unit": "mm", "names": ["nearest obstacle"],
                    "values": [(50 - 10 * t).tolist()]}],
        "obstacles": [
            {"kind": "sphere", "centre": [0.3, 0.2, 0.5], "radius": 0.08},
            {"kind": "capsule", "a": [-0.3, 0, 0.2], "b": [-0.3, 0, 0.7], "radius": 0.04},
            {"kind": "box", "centre": [0, -0.35, 0.3], "half": [0.1, 0.05, 0.2]},
        ],
        "channels": [{"points": [[0, 0, 0], [0, 0, 0.9]], "width": 0.3}],
    }
    return {"title": "a spatial arm", "caption": "synthetic", "runs": [run]}


def test_a_spatial_run_turns_with_the_mouse(browser, tmp_path):
    path = tmp_path / "spatial.html"
    path.write_text(hrm.view_html(json.dumps(spatial_scene())))
    page, errors = open_page(browser, path)
    set_time(page, 0, 0.5)
    before = arm(page, 0).screenshot()
    matches_reference(before, "spatial-0.5s.png")
    set_time(page, 0, 1.5)
    later = arm(page, 0).screenshot()
    assert differs(before, later) > 0.002, "the arm moves"
    matches_reference(later, "spatial-1.5s.png")
    # Dragging orbits the camera and changes the picture; preset views change it too.
    yaw = page.evaluate("document.querySelector('.hrm-view').hrmViewer.camera().yaw")
    box = arm(page, 0).bounding_box()
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] / 2 + 90, box["y"] + box["height"] / 2 + 20, steps=5)
    page.mouse.up()
    turned = arm(page, 0).screenshot()
    assert page.evaluate("document.querySelector('.hrm-view').hrmViewer.camera().yaw") != yaw
    assert differs(later, turned) > 0.01
    page.locator("button[data-view=top]").click()
    top = arm(page, 0).screenshot()
    assert differs(turned, top) > 0.01
    matches_reference(top, "spatial-top-1.5s.png")
    page.mouse.move(box["x"] + box["width"] / 2, box["y"] + box["height"] / 2)
    page.mouse.wheel(0, -300)
    assert page.evaluate("document.querySelector('.hrm-view').hrmViewer.camera().scale") > 0
    assert differs(top, arm(page, 0).screenshot()) > 0.01, "the wheel zooms"
    assert errors == [], errors


def test_a_run_shows_itself_in_jupyter():
    scenario = hrm.Scenario.builtin("paper-tracking")
    scenario.duration = 0.3
    run = scenario.run("fuzzy")
    html = run._repr_html_()
    assert html.startswith("<iframe srcdoc=") and "hrm-view" in html
    page = run.view_html()
    assert page.startswith("<!DOCTYPE html>") and "http" not in page
    with pytest.raises(hrm.InvalidInput, match="dims"):
        bad = spatial_scene(4, 2)
        bad["runs"][0]["dims"] = 4
        hrm.view_html(json.dumps(bad))
    with pytest.raises(hrm.InvalidInput, match="scene"):
        hrm.view_html("{")
    # Finite, but beyond what the page's rounding holds: was written into the page as null.
    with pytest.raises(hrm.InvalidInput, match=r"t: value 1 is 1e304, more than 1e15 in magnitude"):
        huge = spatial_scene(4, 2)
        huge["runs"][0]["t"][1] = 1e304
        hrm.view_html(json.dumps(huge))
