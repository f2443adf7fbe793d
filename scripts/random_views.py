#!/usr/bin/env python3
"""Random views around the default scene, rendered and checked (docs/reliability.md,
"Random views"). A robustness sweep for people changing the ground truth or a technique: it
draws N scenes from the default one (waves 0-1.9x, sun 0.5-90 degrees high and 0-5 degrees
wide, g from -0.95 to 0.9999, absorption and scattering over four decades per channel, the
camera 1 mm to 100 m deep and up to 100 km from the origin, pitch -89..89, field of view
5-170 degrees, occluders and seabed on or off; --real-sun: the sun's 0.53 degrees and g in
[0.5, 0.999]) and runs each through `godrays reference` (--mode truth) or `godrays run`
(--mode run).

A view passes when the command exits 0; 2 naming the scene file (bad input, e.g. a camera
above the wave at its position); or, for `run`, 3 (a technique failed: rendered black, say),
and when no message reports a non-finite value (every image writer refuses NaN and Inf:
docs/reliability.md). Anything else (exit 1, a signal, a timeout, "non-finite") fails the
view; the script prints one line per view and exits 1 if any view failed. The same --seed
gives the same scenes. Two bugs were found this way on 2026-11-30 (docs/benchmarks.md).

--memory (truth mode): each view's memory estimate (read from the refusal of a render under
a 1 KiB limit, which exits before any beam is built) against the render's peak RSS (the
child's ru_maxrss); a view that peaks over its estimate fails.

usage: scripts/random_views.py [--count N] [--seed S] [--mode truth|run] [--size WxH]
                               [--real-sun] [--out DIR] [--binary PATH] [--timeout S] [--memory]
"""
import argparse
import json
import os
import random
import re
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def draw(base, rng, name, real_sun, size):
    s = json.loads(json.dumps(base))
    s["name"] = name
    amp = rng.choice([0.0, 0.3, 1.0, 1.5, 1.9])
    for w in s["water"]["waves"]:
        w["amplitude_m"] *= amp
    if rng.random() < 0.3:
        s["water"]["time_s"] = rng.uniform(0, 1000)
    s["sun"]["elevation_deg"] = rng.choice([rng.uniform(0.5, 5), rng.uniform(5, 90), 90, 89.99])
    s["sun"]["azimuth_deg"] = rng.uniform(-360, 360)
    if real_sun:
        s["sun"]["angular_diameter_deg"] = 0.53
        s["medium"]["g"] = rng.choice([rng.uniform(0.5, 0.99), 0.8, 0.95, 0.999])
    else:
        s["sun"]["angular_diameter_deg"] = rng.choice([0, 0.01, 0.53, 2, 5])
        s["medium"]["g"] = rng.choice([rng.uniform(-0.95, 0.999), 0, 0.9999, -0.5])
    s["medium"]["absorption_per_m"] = [10 ** rng.uniform(-4, 1.3) for _ in range(3)]
    s["medium"]["scattering_per_m"] = [10 ** rng.uniform(-4, 0.5) for _ in range(3)]
    cam = s["camera"]
    depth = rng.choice([1e-3, 0.05, 0.5, 3, 8, 30, 100])
    cam["position_m"] = [rng.uniform(-50, 50), -depth, rng.uniform(-50, 50)]
    if rng.random() < 0.15:
        cam["position_m"][0] += 1e5
    cam["yaw_deg"] = rng.uniform(-180, 180)
    cam["pitch_deg"] = rng.uniform(-89, 89)
    cam["fov_deg"] = rng.choice([5, 30, 60, 120, 170])
    cam["width"], cam["height"] = size
    if rng.random() < 0.5:
        s["occluders"] = []
    if rng.random() < 0.3:
        s.pop("seabed", None)
    elif "seabed" in s:
        s["seabed"]["depth_m"] = depth + rng.uniform(0.01, 40)
    s.pop("reference", None)
    return s


def run_measured(cmd, env, timeout):
    """Runs cmd; returns (exit code or "timeout", its stderr, its peak RSS in MiB or None). The
    child is reaped with wait4, whose rusage is that child's alone."""
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    chunks = []
    reader = threading.Thread(target=lambda: chunks.append(p.stderr.read()))
    reader.start()
    deadline = time.monotonic() + timeout
    while True:
        pid, status, ru = os.wait4(p.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() > deadline:
            p.kill()
            os.wait4(p.pid, 0)
            reader.join()
            p.returncode = -9
            return "timeout", "", None
        time.sleep(0.05)
    reader.join()
    p.returncode = os.waitstatus_to_exitcode(status)
    err = b"".join(chunks).decode("utf-8", "replace")
    return p.returncode, err, ru.ru_maxrss / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=10)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mode", choices=["truth", "run"], default="truth")
    ap.add_argument("--size", default="48x27")
    ap.add_argument("--real-sun", action="store_true")
    ap.add_argument("--out", default="out/random_views")
    ap.add_argument("--binary", default=os.path.join(HERE, "build", "godrays"))
    ap.add_argument("--timeout", type=float, default=600)
    ap.add_argument("--memory", action="store_true")
    a = ap.parse_args()
    try:
        w, h = (int(v) for v in a.size.lower().split("x"))
        if w < 1 or h < 1:
            raise ValueError
    except ValueError:
        print(f"random_views: --size {a.size}: expected WxH, e.g. 48x27", file=sys.stderr)
        return 2
    if not os.access(a.binary, os.X_OK):
        print(f"random_views: --binary {a.binary}: not an executable (build first)", file=sys.stderr)
        return 2
    with open(os.path.join(HERE, "data", "scenes", "default.json")) as f:
        base = json.load(f)
    os.makedirs(a.out, exist_ok=True)
    env = dict(os.environ)
    env.setdefault("GODRAYS_CACHE", os.path.join(os.path.abspath(a.out), "cache"))
    rng = random.Random(a.seed)
    failed = 0
    for i in range(a.count):
        name = f"rv{a.seed}_{i}"
        scene = os.path.join(a.out, name + ".json")
        with open(scene, "w") as f:
            json.dump(draw(base, rng, name, a.real_sun, (w, h)), f, indent=1)
        if a.mode == "truth":
            cmd = [a.binary, "reference", scene, "-o", os.path.join(a.out, name + ".exr"), "-q", "--no-preview"]
            ok_codes = {0}
        else:
            cmd = [a.binary, "run", scene, "-o", os.path.join(a.out, name), "-q"]
            ok_codes = {0, 3}
        est = None
        if a.memory and a.mode == "truth":
            q = subprocess.run(cmd + ["--max-memory", "1K"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               env=env, text=True, errors="replace")
            m = re.search(r"the ground truth needs about ([0-9.]+) GiB", q.stderr)
            est = float(m.group(1)) * 1024.0 if m else None  # MiB
        t0 = time.monotonic()
        rc, err, peak = run_measured(cmd, env, a.timeout)
        dt = time.monotonic() - t0
        lines = [l for l in err.splitlines() if l.strip()]
        why = ""
        if any("non-finite" in l for l in lines):
            why = "a non-finite value"
        elif rc == 2 and not any(scene in l for l in lines):
            why = "exit 2 without naming the scene"
        elif rc != 2 and rc not in ok_codes:
            why = f"exit {rc}"
        mem = ""
        if est is not None and peak is not None and rc == 0:
            mem = f" peak {peak:.0f} / estimate {est:.0f} MiB"
            if peak > est and not why:
                why = "peak RSS over the memory estimate"
        verdict = "FAIL" if why else "ok"
        failed += bool(why)
        last = lines[-1][:160] if lines else ""
        print(f"{verdict:4s} {name} exit {rc} {dt:6.1f} s{mem}{(' (' + why + ')') if why else ''}  {last}", flush=True)
    print(f"random_views: {a.count - failed} of {a.count} views passed (seed {a.seed}, mode {a.mode}, {a.size})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
