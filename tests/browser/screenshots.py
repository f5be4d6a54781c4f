#!/usr/bin/env python3
"""Regenerates the viewer's screenshots in docs/img/viewer/ (shown in
README.md and docs/viewer.md):

    python3 tests/browser/screenshots.py --cairn build/cairn

pyramid-20 hit by a projectile (tests/browser/pyramid-20-hit.json) at
t = 0 and after the hit, with velocity arrows; the ragdoll
(scenes/ragdoll.json) with its joints shown.
"""
import argparse
import base64
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cdp  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHOTS = [  # page source, time (s), overlays, file
    ("tests/browser/pyramid-20-hit.json", 0.0, [], "pyramid-20-start.png"),
    ("tests/browser/pyramid-20-hit.json", 1.5, ["velocities"], "pyramid-20-hit.png"),
    ("scenes/ragdoll.json", 1.0, ["joints"], "ragdoll.png"),
]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--cairn", required=True)
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "img", "viewer"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="cairn_shots_") as tmp, cdp.Browser() as browser:
        pages = {}
        for scene, seconds, overlays, name in SHOTS:
            if scene not in pages:
                pages[scene] = os.path.join(tmp, os.path.basename(scene) + ".html")
                subprocess.run([os.path.abspath(args.cairn), "view", scene, "--run", "--out", pages[scene]],
                               cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
            page = browser.open("file://" + pages[scene] + "#paused", width=1000, height=620)
            page.wait_for("window.cairnViewer && cairnViewer.ready", timeout=120)
            for o in overlays:
                page.evaluate("cairnViewer.setOverlay(%r, true)" % o)
            page.evaluate("cairnViewer.seek(%r)" % seconds)
            page.evaluate("new Promise((ok) => requestAnimationFrame(() => requestAnimationFrame(ok)))")
            with open(os.path.join(args.out, name), "wb") as f:
                f.write(base64.b64decode(page.screenshot()))
            if page.errors:
                sys.exit(name + ": " + "; ".join(page.errors))
            print(os.path.join(args.out, name))


if __name__ == "__main__":
    main()
