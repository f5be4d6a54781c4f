#!/usr/bin/env python3
"""Mutated-scene campaign: `cairn run --steps 30` over scenes mutated from scenes/.

Writes COUNT mutants of the shipped scenes (missing and wrong-typed keys,
extreme numbers, huge arrays, odd names, broken OBJ files; the same seed
gives the same files), runs each with a time limit, and counts the outcomes
docs/reliability.md reports:

  crashed        killed by a signal, or an exit status other than 0, 1, 2, 3
  too slow       still running after --timeout seconds (killed)
  null energy    exit 0 and a metrics file with null where a number belongs
  bad CSV        exit 0 and a trajectory that does not parse as 16-field CSV
  left behind    a temporary or partial file next to the outputs after a failure

    fuzz/campaign.py --cairn build/cairn --dir /tmp/campaign [--count 3600] [--seed 1] [--timeout 20]

The mutants are written once per directory (about 15 minutes, 3 GB) and
reused by later runs with the same count and seed, so two builds can be
compared on the same files.
"""
import argparse
import copy
import csv
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

EXTREMES = [1e308, -1e308, 1e-308, 5e-324, 1e200, -1e200, 1e30, 1e-30, 4294967297, 4294967296, 2147483648,
            2 ** 63, 2 ** 64, -1, 0, -0.0, 1e20, 1e-20, 3.5]
WRONG = [None, "x", "", [], {}, True, [1, 2], {"a": 1}, 0]
NAMES = ["a,b", 'say "hi"', "line\nbreak", "cr\rlf", "tab\there", "world", "", "x" * 5000, "ünïcødé", "\u0000nul",
         ",", '"', "emoji 🚀", " "]
BROKEN_OBJ = {
    "degenerate": "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n",
    "nan": "v 0 0 0\nv nan 0 0\nv 0 0 1\nf 1 2 3\n",
    "huge": "v 0 0 0\nv 1e300 0 0\nv 0 0 1e300\nf 1 2 3\n",
    "badindex": "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 7\n",
    "empty": "",
    "noface": "v 0 0 0\nv 1 0 0\n",
    "garbage": "this is not an obj file\n\x00\x01\x02\n",
    "overflow": "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 99999999999999999999999\n",
    "good": "v -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\nf 1 4 3\nf 1 3 2\n",
}


def paths(node, prefix=()):
    """Every (container, key) in a JSON tree."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append((node, k))
            out += paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append((node, i))
            out += paths(v, prefix + (i,))
    return out


def bodies_of(scene):
    """The scene's body list, made one if an earlier mutation broke it."""
    if not isinstance(scene.get("bodies"), list):
        scene["bodies"] = []
    return scene["bodies"]


def mutate(scene, rng, objdir):
    kind = rng.choice(["delete", "wrong_type", "extreme", "extreme", "huge_array", "odd_name", "broken_obj"])
    places = paths(scene)
    if kind == "delete":
        dicts = [(c, k) for c, k in places if isinstance(c, dict)]
        if dicts:
            c, k = rng.choice(dicts)
            del c[k]
    elif kind == "wrong_type":
        c, k = rng.choice(places)
        c[k] = copy.deepcopy(rng.choice(WRONG))
    elif kind == "extreme":
        nums = [(c, k) for c, k in places if isinstance(c[k], (int, float)) and not isinstance(c[k], bool)]
        if nums:
            for _ in range(rng.randint(1, 3)):
                c, k = rng.choice(nums)
                c[k] = rng.choice(EXTREMES)
    elif kind == "huge_array":
        what = rng.choice(["bodies", "points", "nesting", "shapes"])
        # Small bodies only: copying one that an earlier mutation made huge
        # would multiply the file, not the test.
        bodies = [b for b in bodies_of(scene) if isinstance(b, dict) and len(json.dumps(b)) < 2000]
        if what == "bodies" and bodies:
            n = rng.choice([5000, 20000, 150000])
            scene["bodies"] = [dict(bodies[i % len(bodies)], name=f"copy{i}") for i in range(n)]
        elif what == "points":
            bodies_of(scene).append({"name": "rock", "shapes": [{"type": "convex_hull", "points": [
                [rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)] for _ in range(rng.choice([1000, 100000]))]}]})
        elif what == "shapes":
            bodies_of(scene).append({"name": "many", "shapes": [
                {"type": "sphere", "radius": 0.1, "position": [i * 0.01, 0, 0]} for i in range(rng.choice([2000, 50000]))]})
        else:
            depth = rng.choice([1000, 100000])
            scene["validation"] = "@NEST@"
            return depth
    elif kind == "odd_name":
        named = [b for b in bodies_of(scene) if isinstance(b, dict) and "name" in b and b.get("type") != "static"]
        if named:
            b = rng.choice(named)
            old, new = b["name"], rng.choice(NAMES)
            b["name"] = new
            for group in ("joints", "springs"):  # keep references valid so the run gets to the CSV
                for j in scene.get(group, []) if isinstance(scene.get(group), list) else []:
                    if isinstance(j, dict) and isinstance(j.get("bodies"), list):
                        j["bodies"] = [new if x == old else x for x in j["bodies"]]
    elif kind == "broken_obj":
        name = rng.choice(sorted(BROKEN_OBJ))
        (objdir / f"{name}.obj").write_text(BROKEN_OBJ[name])
        bodies_of(scene).append({"name": "level", "type": "static", "shapes": [{"type": "mesh", "obj": f"{name}.obj"}]})
        bodies_of(scene).append({"name": "faller", "position": [0, 2, 0],
                                 "shapes": [{"type": "box", "half_extents": [0.2, 0.2, 0.2]}]})
    return 0


def write_mutants(src, outdir, count, seed):
    rng = random.Random(seed)
    scenes = sorted(Path(src).glob("*.json"))
    outdir.mkdir(parents=True, exist_ok=True)
    files = []
    for n in range(count):
        base = scenes[n % len(scenes)]
        scene = json.loads(base.read_text())
        depth = 0
        for _ in range(rng.randint(1, 2)):
            depth = mutate(scene, rng, outdir) or depth
        text = json.dumps(scene)
        if depth:
            text = text.replace('"@NEST@"', "[" * depth + "]" * depth)
        f = outdir / f"m{n:05d}-{base.stem}.json"
        f.write_text(text)
        files.append(f)
    return files


def null_inside(node):
    if node is None:
        return True
    if isinstance(node, dict):
        return any(null_inside(v) for v in node.values())
    if isinstance(node, list):
        return any(null_inside(v) for v in node)
    return False


def csv_parses(path):
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f, strict=True))
    except (csv.Error, UnicodeDecodeError):
        return False
    return bool(rows) and rows[0][:3] == ["step", "time", "body"] and all(len(r) == 16 for r in rows)


def run(cairn, files, outdir, timeout):
    tally = {"total": 0, "ok": 0, "status1": 0, "status2": 0, "status3": 0, "crashed": 0, "too_slow": 0,
             "null_energy": 0, "bad_csv": 0, "left_behind": 0}
    examples = {}
    for f in files:
        tally["total"] += 1
        csv_out, metrics_out = outdir / (f.stem + ".csv"), outdir / (f.stem + ".metrics.json")
        before = set(os.listdir(outdir))
        t0 = time.monotonic()
        try:
            p = subprocess.run([cairn, "run", str(f), "--steps", "30", "--out", str(csv_out), "--metrics", str(metrics_out)],
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, timeout=timeout)
            status = p.returncode
        except subprocess.TimeoutExpired:
            status = None
        wall = time.monotonic() - t0
        key = None
        if status is None:
            key = "too_slow"
        elif status < 0 or status not in (0, 1, 2, 3):
            key = "crashed"
        elif status == 0:
            tally["ok"] += 1
            try:
                m = json.loads(metrics_out.read_text())
                if null_inside(m.get("energy_initial")) or null_inside(m.get("energy_final")) or null_inside(m):
                    key = "null_energy"
            except (OSError, ValueError):
                key = "null_energy"
            if key is None and not csv_parses(csv_out):
                key = "bad_csv"
        else:
            tally[f"status{status}"] += 1
            new = set(os.listdir(outdir)) - before
            if new:
                key = "left_behind"
        if key:
            tally[key] += 1
            examples.setdefault(key, []).append(f"{f.name} (status {status}, {wall:.1f} s)")
        for p in (csv_out, metrics_out):
            if p.exists():
                p.unlink()
        for leftover in set(os.listdir(outdir)) - before:
            (outdir / leftover).unlink()
    return tally, examples


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cairn", required=True)
    ap.add_argument("--dir", required=True, help="scratch directory for the mutants and outputs")
    ap.add_argument("--scenes", default=str(Path(__file__).resolve().parent.parent / "scenes"))
    ap.add_argument("--count", type=int, default=3600)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=20)
    a = ap.parse_args()
    outdir = Path(a.dir)
    stamp = outdir / "scenes" / f".complete-{a.count}-{a.seed}"
    if stamp.exists():  # the same mutants, e.g. to compare two builds
        files = sorted((outdir / "scenes").glob("m*.json"))
    else:
        files = write_mutants(a.scenes, outdir / "scenes", a.count, a.seed)
        stamp.touch()
    out = outdir / ("out-" + str(os.getpid()))
    out.mkdir()
    tally, examples = run(os.path.abspath(a.cairn), files, out, a.timeout)
    out.rmdir()
    print(json.dumps(tally))
    for k, v in examples.items():
        print(f"{k}: {len(v)}, e.g. " + "; ".join(v[:5]))


if __name__ == "__main__":
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    sys.exit(main())
