"""The viewer page in a real headless browser: Debian's Chromium driven by Playwright.

Skipped, with the reason printed in the summary, when no Chromium is found (``chromium`` on the
PATH or ``MECHSYS_CHROMIUM``) or Playwright for Python is missing; `.ci/run` installs Chromium
first so CI always runs them. Screenshots land in ``results/viewer/``.
"""

from __future__ import annotations

import os
import runpy
import shutil
from pathlib import Path

import numpy as np
import pytest

import mechsys as ms
from mechsys import viewer

ROOT = Path(__file__).resolve().parents[1]
SHOTS = ROOT / "results" / "viewer"
CHROMIUM = os.environ.get("MECHSYS_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
try:
    from playwright.sync_api import sync_playwright
except ImportError:  # pragma: no cover - the Makefile installs it
    sync_playwright = None

pytestmark = pytest.mark.skipif(
    CHROMIUM is None or sync_playwright is None,
    reason="browser tests need Chromium (Debian package 'chromium', or MECHSYS_CHROMIUM) and Playwright for Python",
)

# headless, software WebGL, and nothing that reaches for the network
ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
        "--disable-quic", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"]
G = 9.81


@pytest.fixture(scope="module")
def browser():
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=ARGS)
        yield b
        b.close()


class Page:
    """A loaded viewer page and the console messages and page errors it produced."""

    def __init__(self, browser, path: Path):
        self.page = browser.new_page(viewport={"width": 1200, "height": 700})
        self.messages: list[tuple[str, str]] = []
        self.page.on("console", lambda m: self.messages.append((m.type, m.text)))
        self.page.on("pageerror", lambda e: self.messages.append(("pageerror", str(e))))
        self.page.goto(path.resolve().as_uri())
        self.page.wait_for_function("window.mechsys && window.mechsys.ready", timeout=30000)

    def js(self, expr: str, arg=None):
        return self.page.evaluate(expr, arg)

    @property
    def errors(self) -> list:
        return [m for m in self.messages if m[0] in ("error", "pageerror")]


def pushed_block():
    m = ms.Model("pushed-block", gravity=(0, 0, -G))
    b = m.add_body("block", 1.0, ms.inertia.box(1.0, (0.2, 0.2, 0.2)))
    m.add_joint(ms.joints.Free("free", m.ground, b, q0=[0, 0, 0, 1, 0, 0, 0]))
    m.add_contact(ms.Contact("floor", b.contour(ms.contours.Point()), m.ground.contour(ms.contours.Plane(normal=(0, 0, 1))),
                             friction=ms.laws.Coulomb(mu=0.4, mu0=0.6)))
    m.add_visual(b, ms.contours.Box(half_extents=(0.1, 0.1, 0.1), center=(0, 0, 0.1)), name="block", color=(0.3, 0.5, 0.8))
    m.add_force(ms.forces.BodyForce("push", b, force=(1.0, 0.0, 0.0), function=ms.functions.Ramp(1.0)))
    return m


@pytest.fixture(scope="module")
def block_page(browser, tmp_path_factory):
    res = ms.simulate(pushed_block(), t_end=8.0, integrator=ms.EventDriven(), output_dt=0.01)
    path = viewer.to_html(res, tmp_path_factory.mktemp("view") / "block.html", trails=["block:0,0,0.2"],
                          signals=["contact/floor/friction_force", "joint/free/q"])
    return res, Page(browser, path)


def test_the_page_loads_with_no_console_error_and_draws_the_scene(block_page):
    res, p = block_page
    assert p.errors == []
    SHOTS.mkdir(parents=True, exist_ok=True)
    shot = SHOTS / "pushed_block.png"
    p.js("window.mechsys.setFrame(Math.floor(window.mechsys.frames * 0.9))")
    p.page.wait_for_timeout(300)
    p.page.locator("#scene canvas").screenshot(path=str(shot))
    import matplotlib.image as mpimg

    img = mpimg.imread(shot)[..., :3]
    # not blank: many colours, and the block's blue among them
    colours = np.unique((img * 255).astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 50
    blue = (img[..., 2] > img[..., 0] + 0.15)
    assert blue.mean() > 0.001


def test_the_scene_holds_the_models_bodies_and_contacts(block_page):
    res, p = block_page
    assert p.js("window.mechsys.sceneBodyCount()") == len(res.model["bodies"]) == 1
    assert p.js("window.mechsys.contactCount") == 1
    assert p.js("window.mechsys.plotCount") == 2


def test_scrubbing_moves_the_body_to_its_recorded_pose(block_page):
    res, p = block_page
    for fraction in (0.25, 0.8, 1.0):
        k = p.js("(f) => Math.round(f * (window.mechsys.frames - 1))", fraction)
        p.page.locator("#scrub").evaluate("(el, v) => { el.value = String(v); el.dispatchEvent(new Event('input')); }", k)
        assert p.js("window.mechsys.frame()") == k
        t = p.js("window.mechsys.time()")
        i = int(np.argmin(np.abs(res.t - t)))
        assert abs(res.t[i] - t) < 1e-9
        np.testing.assert_allclose(p.js("window.mechsys.bodyPosition('block')"), res["body/block/position"][i], atol=1e-6)
        np.testing.assert_allclose(p.js("window.mechsys.bodyQuaternion('block')"), res["body/block/orientation"][i], atol=1e-6)
        label = p.page.locator("#time").inner_text()
        assert label.startswith("t = ") and abs(float(label.split()[2]) - t) < 1e-3


def test_contact_colour_follows_its_state(block_page):
    res, p = block_page
    state = res["contact/floor/state"]
    for want, colour in ((1, 0x2F6FD6), (2, 0xE8871E)):
        i = int(np.flatnonzero(state == want)[len(np.flatnonzero(state == want)) // 2])
        p.js("(t) => window.mechsys.setTime(t)", float(res.t[i]))
        assert p.js("window.mechsys.contactColor(0)") == colour


def test_frame_step_play_and_a_click_on_a_plot(block_page):
    res, p = block_page
    p.js("window.mechsys.setFrame(10)")
    p.page.keyboard.press("ArrowRight")
    assert p.js("window.mechsys.frame()") == 11
    p.page.click("#next")
    assert p.js("window.mechsys.frame()") == 12
    p.page.click("#play")
    p.page.wait_for_timeout(600)
    p.page.click("#play")
    assert p.js("window.mechsys.frame()") > 12
    # a click at the middle of the first plot's drawing area moves the timeline there
    over = p.page.locator(".plot .u-over").first
    box = over.bounding_box()
    over.click(position={"x": box["width"] / 2, "y": box["height"] / 2})
    t_mid = p.js("window.mechsys.time()")
    assert abs(t_mid - 0.5 * (res.t[0] + res.t[-1])) < 0.02 * (res.t[-1] - res.t[0])
    cursor = p.page.locator(".plot .cursor").first.bounding_box()
    assert abs(cursor["x"] - (box["x"] + box["width"] / 2)) < 3


def test_frames_toggle_and_follow(block_page):
    res, p = block_page
    assert p.js("window.mechsys.triadsVisible()") is False
    p.page.check("#show-frames")
    assert p.js("window.mechsys.triadsVisible()") is True
    p.page.select_option("#follow", "block")
    p.js("window.mechsys.setFrame(0)")
    before = np.array(p.js("window.mechsys.cameraTarget()"))
    p.js("window.mechsys.setFrame(window.mechsys.frames - 1)")
    after = np.array(p.js("window.mechsys.cameraTarget()"))
    # the camera's target moved with the block
    np.testing.assert_allclose(after - before, res["body/block/position"][-1] - res["body/block/position"][0], atol=1e-5)


def test_the_woodpecker_example_page(browser, tmp_path):
    """The showcase: a short woodpecker run from the example's model; its screenshot is the
    README's."""
    ns = runpy.run_path(str(ROOT / "examples" / "woodpecker.py"), run_name="not_main")
    sim = dict(ns["simulation"])
    sim["t_end"] = 0.3
    res = ms.simulate(ns["model"], **sim)
    path = viewer.to_html(res, tmp_path / "woodpecker.html", trails=["bird"])
    p = Page(browser, path)
    assert p.errors == []
    assert p.js("window.mechsys.sceneBodyCount()") == 2 and p.js("window.mechsys.contactCount") == 5
    # a flash at an impact: step over the first impact's time
    impact = next(e["t"] for e in res.events if e["event"] == "impact" and e["t"] > 0.01)
    p.js("(t) => window.mechsys.setTime(t - 2e-3)", impact)
    p.js("(t) => window.mechsys.advanceTo(t + 2e-3)", impact)
    assert p.js("window.mechsys.flashCount()") >= 1
    SHOTS.mkdir(parents=True, exist_ok=True)
    p.js("(t) => window.mechsys.setTime(t)", 0.2)
    p.page.wait_for_timeout(300)
    p.page.screenshot(path=str(SHOTS / "woodpecker.png"))


def test_a_mode_shape_page(browser, tmp_path):
    m = ms.Model("two-rods", gravity=(0, -G, 0))
    a = m.add_body("upper", 1.0, [1e-4, 1 / 12, 1 / 12], com=(0.5, 0, 0))
    b = m.add_body("lower", 1.0, [1e-4, 1 / 12, 1 / 12], com=(0.5, 0, 0))
    m.add_joint(ms.joints.Revolute("shoulder", "ground", a, axis=(0, 0, 1), q0=[-np.pi / 2]))
    m.add_joint(ms.joints.Revolute("elbow", a, b, axis=(0, 0, 1), parent_frame=ms.Frame(position=(1, 0, 0))))
    anim = viewer.mode_results(ms.linear.linearize(m), 1)
    p = Page(browser, viewer.to_html(anim, tmp_path / "mode.html"))
    assert p.errors == []
    k = p.js("Math.floor(window.mechsys.frames / 4)")
    p.js("(k) => window.mechsys.setFrame(k)", k)
    np.testing.assert_allclose(p.js("window.mechsys.bodyPosition('lower')"), anim.position[k, 1], atol=1e-6)
    assert "mode 2" in p.page.locator("#title").inner_text()


@pytest.mark.parametrize("example, t_end", [("woodpecker", 0.05), ("sphere_pile", 0.05), ("four_bar", 0.2), ("rotor_bearing", 0.02)])
def test_each_showcase_example_gives_a_page_from_mechsys_view(browser, tmp_path, example, t_end):
    """The acceptance examples, each run briefly from its own model and settings, saved, turned
    into a page by the command line, and loaded."""
    import subprocess
    import sys

    ns = runpy.run_path(str(ROOT / "examples" / f"{example}.py"), run_name="not_main")
    res = ms.simulate(ns["model"], **dict(ns["simulation"], t_end=t_end))
    src = res.save(tmp_path / f"{example}.h5")
    r = subprocess.run([sys.executable, "-m", "mechsys", "view", str(src)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    p = Page(browser, tmp_path / f"{example}.html")
    assert p.errors == []
    assert p.js("window.mechsys.sceneBodyCount()") == len(res.model["bodies"])
    last = p.js("window.mechsys.frames - 1")
    p.js("(k) => window.mechsys.setFrame(k)", last)
    name = res.model["bodies"][-1]["name"]
    np.testing.assert_allclose(p.js(f"window.mechsys.bodyPosition('{name}')"), res[f"body/{name}/position"][-1], atol=1e-6)


def test_an_elastic_rod_deflects_on_the_page(browser, tmp_path):
    """The slider-crank's elastic rod: at a scrubbed frame its drawn node line is the undeformed
    nodes plus the magnified recorded deflection."""
    ns = runpy.run_path(str(ROOT / "examples" / "flexible_slider_crank.py"), run_name="not_main")
    res = ms.simulate(ns["model"], **dict(ns["simulation"], t_end=0.03, output_dt=1e-3))
    p = Page(browser, viewer.to_html(res, tmp_path / "crank.html"))
    assert p.errors == []
    assert "elastic deflection ×" in p.page.locator("#info").inner_text()
    k = p.js("Math.floor(window.mechsys.frames * 0.7)")
    p.js("(k) => window.mechsys.setFrame(k)", k)
    t = p.js("window.mechsys.time()")
    i = int(np.argmin(np.abs(res.t - t)))
    body = ns["ROD_BODY"]
    drawn = np.asarray(p.js("window.mechsys.elasticNodes(0)")).reshape(-1, 3)
    scale = p.js("window.mechsys.elasticScale(0)")
    expect = body.nodes + scale * np.einsum("k,nck->nc", res["body/rod/elastic_q"][i], body.modes[:, :3, :])
    np.testing.assert_allclose(drawn, expect, atol=1e-6)
    assert np.abs(drawn - body.nodes).max() > 1e-4  # it does bend, visibly
