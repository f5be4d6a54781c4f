#!/usr/bin/env python3
"""The replay page in a real browser: headless Chromium (Debian's chromium)
driven over its DevTools pipe (cdp.py). Run by ctest (label "browser"):

    viewer_test.py --cairn build/cairn            the default checks
    viewer_test.py --cairn build/cairn --large    a 1,000-body, 600-step
        replay (scenes/pile-1000.json): load time, frame times and the
        browser's CPU time per frame by process, printed and checked against
        what this machine reaches (ctest label "long")

For each page: no console error or uncaught exception; the instances drawn
equal the scene's shapes, kind by kind; the picture at t = 5 s differs from
the one at t = 0; a click on a body picks it and shows its name. A CSV
replay shows the CSV's numbers; a validation page draws Bullet's bodies too.
Exit status 77 (ctest: skipped) when Chromium is not installed.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cdp  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
ARGS = None

# Fraction of pixels that differ by more than 16 levels in some channel,
# computed by the browser from two PNG screenshots.
PIXEL_DIFF = """(async (a, b) => {
  const load = (src) => new Promise((ok) => { const i = new Image(); i.onload = () => ok(i); i.src = src; });
  const [x, y] = await Promise.all([load('data:image/png;base64,' + a), load('data:image/png;base64,' + b)]);
  const pixels = (img) => { const c = document.createElement('canvas'); c.width = img.width; c.height = img.height;
    const g = c.getContext('2d'); g.drawImage(img, 0, 0); return g.getImageData(0, 0, c.width, c.height).data; };
  const p = pixels(x), q = pixels(y);
  let n = 0;
  for (let i = 0; i < p.length; i += 4)
    if (Math.abs(p[i] - q[i]) > 16 || Math.abs(p[i + 1] - q[i + 1]) > 16 || Math.abs(p[i + 2] - q[i + 2]) > 16) n++;
  return n / (p.length / 4);
})"""

NEXT_FRAMES = "new Promise((ok) => requestAnimationFrame(() => requestAnimationFrame(ok)))"


def cairn(*args):
    result = subprocess.run([ARGS.cairn, *args], cwd=ROOT, capture_output=True, text=True)
    if result.returncode not in (0, 1):
        raise RuntimeError("cairn " + " ".join(args) + " failed: " + result.stderr)
    return result.stdout


def scene_shapes(path):
    with open(path) as f:
        scene = json.load(f)
    kinds = {}
    for body in scene["bodies"]:
        for shape in body.get("shapes", []):
            kinds[shape["type"]] = kinds.get(shape["type"], 0) + 1
    return scene, kinds


def open_page(browser, path):
    page = browser.open("file://" + path + "#paused")
    page.wait_for("window.cairnViewer && cairnViewer.ready", timeout=120)
    return page


def screenshot_at(page, seconds):
    page.evaluate("cairnViewer.seek(%r)" % seconds)
    page.evaluate(NEXT_FRAMES)
    return page.screenshot()


class ViewerPages(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="cairn_browser_")
        cls.scene_path = os.path.join(HERE, "all_shapes.json")
        cls.run_page = os.path.join(cls.tmp.name, "run.html")
        cls.csv = os.path.join(cls.tmp.name, "run.csv")
        cls.csv_page = os.path.join(cls.tmp.name, "csv.html")
        cls.report = os.path.join(cls.tmp.name, "report")
        cairn("view", cls.scene_path, "--run", "--out", cls.run_page)
        cairn("run", cls.scene_path, "--out", cls.csv)
        cairn("view", cls.scene_path, cls.csv, "--out", cls.csv_page)
        cairn("validate", "scenes/hinge-chain.json", "--steps", "120", "--report", cls.report)
        cls.browser = cdp.Browser().__enter__()

    @classmethod
    def tearDownClass(cls):
        cls.browser.__exit__(None, None, None)
        cls.tmp.cleanup()

    def assertNoErrors(self, page):
        self.assertEqual(page.errors, [], "console errors on the page")

    def test_every_shape_is_drawn_as_itself_once(self):
        page = open_page(self.browser, self.run_page)
        scene, kinds = scene_shapes(self.scene_path)
        self.assertEqual(page.evaluate("cairnViewer.drawnInstances()"), sum(kinds.values()))
        self.assertEqual(page.evaluate("cairnViewer.instancesByKind()"), kinds)
        self.assertEqual(set(kinds), {"plane", "mesh", "box", "sphere", "capsule", "cylinder", "convex_hull"})
        self.assertNoErrors(page)

    def test_the_picture_changes_as_bodies_fall(self):
        page = open_page(self.browser, self.run_page)
        start, later = screenshot_at(page, 0), screenshot_at(page, 5)
        changed = page.evaluate(PIXEL_DIFF + "(%s, %s)" % (json.dumps(start), json.dumps(later)))
        # Six bodies fall 2-6 m onto the ground: a few percent of the view.
        self.assertGreater(changed, 0.005)
        same = page.evaluate(PIXEL_DIFF + "(%s, %s)" % (json.dumps(later), json.dumps(screenshot_at(page, 5))))
        self.assertLess(same, 1e-4, "the same instant draws the same picture")
        self.assertNoErrors(page)

    def test_every_overlay_draws_without_error(self):
        page = open_page(self.browser, self.run_page)
        for name in ("contacts", "joints", "velocities", "sleep", "islands"):
            page.evaluate("cairnViewer.setOverlay(%r, true)" % name)
        for t in (0, 1, 2.5, 5):
            screenshot_at(page, t)
        self.assertNoErrors(page)

    def test_clicking_a_body_shows_its_name_mass_and_forces(self):
        page = open_page(self.browser, self.run_page)
        page.evaluate("cairnViewer.seek(5)")
        page.evaluate(NEXT_FRAMES)
        point = page.evaluate("cairnViewer.screenPoint('ball')")
        page.click(point["x"], point["y"])
        page.evaluate(NEXT_FRAMES)
        self.assertEqual(page.evaluate("cairnViewer.pickedName()"), "ball")
        info = page.evaluate("cairnViewer.infoText()")
        self.assertIn("ball", info)
        self.assertIn("mass 1.000 kg", info)
        self.assertIn("contacts", info)  # resting on the ground at 5 s
        self.assertNoErrors(page)

    def test_a_csv_replay_shows_the_csv_numbers(self):
        page = open_page(self.browser, self.csv_page)
        with open(self.csv) as f:
            rows = [line.strip().split(",") for line in f][1:]
        step60 = {r[2]: [float(v) for v in r[3:6]] for r in rows if r[0] == "60"}
        page.evaluate("cairnViewer.seek(1)")  # step 60 of 1/60 s
        for name, expected in step60.items():
            got = page.evaluate("cairnViewer.bodyPosition(%r)" % name)
            for g, e in zip(got, expected):
                self.assertAlmostEqual(g, e, delta=1e-6 * max(1, abs(e)))  # float32 storage
        self.assertTrue(page.evaluate("document.querySelector('[data-overlay=contacts]').disabled"))
        _, kinds = scene_shapes(self.scene_path)
        self.assertEqual(page.evaluate("cairnViewer.drawnInstances()"), sum(kinds.values()))
        self.assertNoErrors(page)

    def test_a_validation_page_draws_bullet_over_cairn_and_marks_the_parting(self):
        page = open_page(self.browser, os.path.join(self.report, "hinge-chain.replay.html"))
        scene, _ = scene_shapes(os.path.join(ROOT, "scenes", "hinge-chain.json"))
        moving = sum(len(b.get("shapes", [])) for b in scene["bodies"] if b.get("type", "dynamic") != "static")
        self.assertEqual(page.evaluate("cairnViewer.bulletInstances()"), moving)
        parting = page.evaluate("cairnViewer.parting()")
        self.assertIsNotNone(parting)
        marked = page.evaluate("!document.getElementById('parting').hidden")
        self.assertEqual(marked, parting["frame"] >= 0)
        self.assertNoErrors(page)


class LargeReplay(unittest.TestCase):
    """1,000 boxes for 600 steps: the figures go to docs/viewer.md."""

    def test_a_thousand_bodies_load_and_play(self):
        with tempfile.TemporaryDirectory(prefix="cairn_browser_") as tmp:
            path = os.path.join(tmp, "pile.html")
            out = cairn("view", "scenes/pile-1000.json", "--run", "--steps", "600", "--out", path)
            print(out.strip().splitlines()[-1])
            with cdp.Browser() as browser:
                page = open_page(browser, path)
                load_ms = page.evaluate("cairnViewer.loadMilliseconds")
                self.assertEqual(page.evaluate("cairnViewer.drawnInstances()"), 1001)
                before = browser.cpu_seconds()
                frames = page.evaluate("cairnViewer.measureFrames(5000)", timeout=60)
                after = browser.cpu_seconds()
                cpu = {k: 1000 * (after[k] - before.get(k, 0)) / max(1, frames["frames"]) for k in after}
                with open("/proc/loadavg") as f:
                    load_average = f.read().split()[0]
                print("load %.0f ms (navigation start to first frame drawn); playing: %.1f frames/s, "
                      "mean frame %.1f ms, 95th percentile %.1f ms over %d frames; page script %.2f ms per frame; "
                      "CPU per frame: GPU process %.1f ms, page (renderer) %.1f ms, browser %.1f ms; "
                      "machine load average %s" % (load_ms, frames["fps"], frames["meanMs"], frames["p95Ms"],
                                                   frames["frames"], frames["scriptMs"], cpu.get("gpu-process", 0),
                                                   cpu.get("renderer", 0), cpu.get("browser", 0), load_average))
                self.assertEqual(page.errors, [])
                # What this machine reaches, with a margin for its load (docs/viewer.md,
                # "Large runs"): headless Chromium draws WebGL with SwiftShader
                # (software), and the pile's front faces cover 2.45 million
                # pixels a frame at 1000 x 700, which SwiftShader rasterizes in
                # about 55 ms of CPU: 15-22 frames/s at load average 3-4, 7.5-10
                # at 5-6.6 on the 2 shared cores, so 60 frames/s (the target on
                # a GPU) is not asserted here; the floor is 5. Loading took
                # 1.2-2.7 s (3.7 s at load 6.7): under 6 s. The page's own
                # script must stay well inside a 60 Hz frame (16.7 ms): it
                # measured 1.0-2.9 ms.
                self.assertLess(load_ms, 6000)
                self.assertGreater(frames["fps"], 5)
                self.assertLess(frames["scriptMs"], 8)


def main():
    global ARGS
    parser = argparse.ArgumentParser()
    parser.add_argument("--cairn", required=True, help="the cairn binary")
    parser.add_argument("--large", action="store_true", help="run the 1,000-body replay only")
    ARGS, rest = parser.parse_known_args()
    ARGS.cairn = os.path.abspath(ARGS.cairn)
    if not cdp.find_chromium():
        print("SKIPPED: the browser tests need Chromium (Debian package 'chromium'; scripts/setup installs it)")
        return 77
    suite = unittest.TestLoader().loadTestsFromTestCase(LargeReplay if ARGS.large else ViewerPages)
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main())
