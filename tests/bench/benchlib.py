"""Shared benchmark plumbing: rounds, machine load, peak memory, child processes, out/bench.json.

Benchmarks print figures and ratios measured in the same run; they never pass or fail on
time. Conventions every bench_*.py follows:

- A *side* is one way of getting the same picture (Kodawari, a Geometry Nodes bend, Blender's
  bare evaluation, ...). Timing runs every side of one size in ONE process, interleaved round by
  round (round 1: A B C, round 2: A B C, ...), so a ratio compares like with like under the same
  machine load. A figure is the mean time per frame of one round; we print the min and median
  over ROUNDS rounds, and the 1-minute load average when the side was measured.
- Peak memory is measured per side in its own child process (Blender + that side only, built and
  played the same way), because a process's peak resident set cannot be split between sides that
  share it. "peak" is VmHWM over the whole child (building included); "above start" is the peak
  while playing (VmHWM reset once the side is built) minus the process's resident size before
  the side was built (Blender itself and the add-on): what the side costs as the user plays it.
"""

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OUT = os.path.join(ROOT, "out", "bench.json")
SAMPLES = os.path.join(ROOT, "blend_samples")
if SAMPLES not in sys.path:  # the sample creatures the benchmarks build (not in the add-on)
    sys.path.insert(0, SAMPLES)
ROUNDS = 3
CHILD_ENV = "KODAWARI_BENCH_CHILD"
EXIT_GRACE = 60  # seconds a child may take to exit after reporting


def say(*args, **kwargs):
    """print, flushed: the runner pipes our output, and a long benchmark should show as it goes."""
    print(*args, **kwargs, flush=True)


def sizes(all_sizes):
    """All sizes, or only those listed in $KODAWARI_BENCH_SIZES (comma separated) for a quick look."""
    only = os.environ.get("KODAWARI_BENCH_SIZES")
    if not only:
        return all_sizes
    keep = {int(x) for x in only.split(",") if x.strip()}
    return {k: v for k, v in all_sizes.items() if k in keep}


def blender_label():
    kind = "Blender" if bpy.app.binary_path else "bpy"
    return f"{kind} {bpy.app.version_string}"


def blender_key():
    return ".".join(str(v) for v in bpy.app.version[:2])


def load():
    return round(os.getloadavg()[0], 2)


def _status(field):
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024.0  # kB -> MB
    return float("nan")


def rss_mb():
    return _status("VmRSS")


def peak_rss_mb():
    return _status("VmHWM")


def reset_peak_rss():
    """Linux (4.0+): writing 5 to clear_refs resets VmHWM to the current resident size."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


class Rounds:
    """Interleaved rounds: run(sides) calls each side's play(round) ROUNDS times, A B C A B C ...;
    play returns the list of per-frame seconds of that round."""

    def __init__(self, rounds=ROUNDS):
        self.rounds = rounds

    def run(self, sides):
        per_round = {name: [] for name in sides}
        loads = {name: [] for name in sides}
        for r in range(self.rounds):
            for name, play in sides.items():
                seconds = play(r)
                per_round[name].append(sum(seconds) / len(seconds))
                loads[name].append(load())
        return {
            name: {
                "ms_min": round(min(values) * 1e3, 3),
                "ms_median": round(statistics.median(values) * 1e3, 3),
                "ms_rounds": [round(v * 1e3, 3) for v in values],
                "load": round(statistics.mean(loads[name]), 2),
            }
            for name, values in per_round.items()
        }


def timed(call):
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


# ----------------------------------------------------------------------------- child processes


def child_spec():
    raw = os.environ.get(CHILD_ENV)
    return json.loads(raw) if raw else None


def child_report(payload):
    """The child's answer to its parent: one line on stdout."""
    payload = dict(payload)
    payload.setdefault("peak_rss_mb", round(peak_rss_mb(), 1))
    print("KODAWARI_BENCH_RESULT " + json.dumps(payload), flush=True)


def run_child(script, spec, timeout=900):
    """Runs `script` in a fresh Blender of the same kind as this one (the Blender executable, or
    this Python with the bpy module), the add-on installed, with `spec` in its environment;
    returns the dict the child reported, or {"error": ...}."""
    # Its own throw-away Blender folders: installing the add-on again into ours would overwrite
    # the native library this process has mapped (SIGBUS later).
    home = tempfile.mkdtemp(prefix="kodawari-bench-child-")
    env = dict(os.environ, **{CHILD_ENV: json.dumps(spec)})
    for name, sub in (
        ("SCRIPTS", "scripts"),
        ("CONFIG", "config"),
        ("DATAFILES", "data"),
        ("EXTENSIONS", "extensions"),
    ):
        env[f"BLENDER_USER_{name}"] = os.path.join(home, sub)
    if bpy.app.binary_path:
        command = [
            bpy.app.binary_path,
            "-b",
            "--factory-startup",
            "-noaudio",
            "--python-exit-code",
            "1",
            "--python",
            os.path.join(ROOT, "tools", "blender_install_addon.py"),
            "--python",
            script,
        ]
    else:
        bootstrap = (
            "import runpy, sys; sys.path.insert(0, 'tools')\n"
            "from blender_install_addon import install_addon; install_addon()\n"
            "runpy.run_path(sys.argv[1], run_name='__main__')"
        )
        command = [sys.executable, "-c", bootstrap, script]
    # Read as it comes: once the result line is in, the child gets EXIT_GRACE seconds to
    # exit. bpy 4.5 as a module sometimes never does (its exit handlers wait on a thread of
    # its own, seen once in ~20 children): the figures are in hand by then, not lost.
    child = subprocess.Popen(
        command, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    watchdog = threading.Timer(timeout, child.kill)
    watchdog.start()
    grace = threading.Timer(EXIT_GRACE, child.kill)
    lines, result = [], None
    try:
        for line in child.stdout:
            lines.append(line.rstrip("\n"))
            if result is None and line.startswith("KODAWARI_BENCH_RESULT "):
                result = json.loads(line.split(" ", 1)[1])
                grace.start()
        child.wait()
    finally:
        watchdog.cancel()
        grace.cancel()
        child.stdout.close()
        shutil.rmtree(home, ignore_errors=True)
    if result is not None:
        return result
    if child.returncode is not None and child.returncode < 0:
        return {"error": f"killed after {timeout} s: " + " | ".join(lines[-8:])}
    return {"error": f"exit {child.returncode}: " + " | ".join(lines[-8:])}


# ----------------------------------------------------------------------------- results


def record(area, payload):
    """Stores one benchmark's figures under out/bench.json -> runs -> <Blender x.y> -> area."""
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    try:
        with open(OUT) as f:
            data = json.load(f)
    except (OSError, ValueError):
        data = {}
    run = data.setdefault("runs", {}).setdefault(blender_key(), {})
    run["blender"] = blender_label()
    run["cpus"] = os.cpu_count()
    run[area] = payload
    with open(OUT, "w") as f:
        json.dump(data, f, indent=1, sort_keys=True)


def fmt_ms(row):
    return f"{row['ms_min']:9.2f} / {row['ms_median']:9.2f} ms"


def fmt_mem(row):
    peak = row.get("peak_rss_mb")
    if peak is None:
        return "      (memory n/a)"
    above = row.get("above_start_mb")
    return f"peak {peak:7.0f} MB" + (
        f" (playing: {above:6.0f} above start)" if above is not None else ""
    )
