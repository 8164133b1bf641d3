"""The fuzz tier's runner (tests/fuzz/run_fuzz.py) survives a crash of kodawari_native:
the run reports the case that was running and fails, instead of ending the test run."""

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import kodawari_native as kn

RUNNER = os.path.join(
    os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "fuzz", "run_fuzz.py"
)

# A pytest plugin that lets one fuzz case run, then segfaults like a native bug would.
CRASH_PLUGIN = """
import ctypes
import kodawari_native
real = kodawari_native.curve_length
def crashing(*args, **kwargs):
    real(*args, **kwargs)
    ctypes.string_at(0)
kodawari_native.curve_length = crashing
"""


def test_a_segfault_in_a_case_is_reported_with_the_case(tmp_path):
    (tmp_path / "crash_plugin.py").write_text(CRASH_PLUGIN)
    report = tmp_path / "fuzz.xml"
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), os.path.dirname(kn.__file__)])
    )
    proc = subprocess.run(
        [
            sys.executable,
            RUNNER,
            f"--junitxml={report}",
            "-p",
            "crash_plugin",
            "-k",
            "curve_length",
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )
    assert proc.returncode != 0, proc.stdout + proc.stderr
    assert "signal 11" in proc.stderr and "curve_length(control_points=" in proc.stderr
    failure = ET.parse(report).getroot().find(".//failure")
    assert failure is not None and "signal 11" in failure.get("message")
    assert failure.text.startswith("curve_length(control_points=")
    assert "1 cases in" in proc.stdout
