"""Runs the fuzz tier (tests/fuzz) in a child process, so a segfault or abort in
kodawari_native is reported, not fatal to the test run:
    python tests/fuzz/run_fuzz.py --junitxml build/test-reports/fuzz.xml [pytest args...]
The child logs each case before calling; when it dies, the last case is the culprit and
goes into the report. Prints "fuzz: N cases in T s"; exits non-zero on any failure."""

import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import escape

HERE = Path(__file__).resolve().parent
TIMEOUT = 900  # the whole tier; a single case has CASE_TIMEOUT in test_fuzz_native.py


def case_count(report):
    try:
        root = ET.parse(report).getroot()
    except (OSError, ET.ParseError):
        return None
    for prop in root.iter("property"):
        if prop.get("name") == "cases":
            return int(prop.get("value"))
    return None


def write_crash_report(report, why, last_case, cases, seconds):
    report.parent.mkdir(parents=True, exist_ok=True)
    report.write_text(
        '<?xml version="1.0" encoding="utf-8"?>\n'
        f'<testsuites><testsuite name="fuzz" tests="1" failures="1" errors="0" skipped="0" time="{seconds:.1f}">'
        f'<properties><property name="cases" value="{cases}" /></properties>'
        f'<testcase classname="tests.fuzz" name="kodawari_native" time="{seconds:.1f}">'
        f'<failure message="{escape(why, {chr(34): "&quot;"})}">{escape(last_case)}</failure>'
        "</testcase></testsuite></testsuites>\n"
    )


def main(argv):
    reports = [a for a in argv if a.startswith("--junitxml=")]
    if reports:
        report, extra = Path(reports[0].split("=", 1)[1]), [a for a in argv if a != reports[0]]
    elif "--junitxml" in argv[:-1]:
        i = argv.index("--junitxml")
        report, extra = Path(argv[i + 1]), argv[:i] + argv[i + 2 :]
    else:
        sys.exit("usage: run_fuzz.py --junitxml=REPORT [pytest args...]")
    with tempfile.NamedTemporaryFile("r", suffix=".log", prefix="kodawari-fuzz-") as log:
        env = dict(os.environ, KODAWARI_FUZZ_LOG=log.name, PYTHONDONTWRITEBYTECODE="1")
        cmd = [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            "-W",
            "ignore::RuntimeWarning",
            "--rootdir",
            str(HERE),
            str(HERE),
            f"--junitxml={report}",
            *extra,
        ]
        start = time.monotonic()
        try:
            code = subprocess.run(cmd, env=env, timeout=TIMEOUT, check=False).returncode
            why = f"the fuzz child process died (signal {-code})" if code < 0 else None
        except subprocess.TimeoutExpired:
            code, why = 1, f"the fuzz tier took more than {TIMEOUT} s"
        seconds = time.monotonic() - start
        lines = Path(log.name).read_text(errors="replace").splitlines()
    if why is None and not report.exists():
        why = f"the fuzz child process exited with {code} and wrote no report"
    if why:
        last = lines[-1] if lines else "(no case logged)"
        print(
            f"fuzz: {why} after {len(lines)} cases; the case running was:\n  {last}",
            file=sys.stderr,
        )
        write_crash_report(report, why, last, len(lines), seconds)
        code = code or 1
    cases = case_count(report)
    print(f"fuzz: {cases if cases is not None else len(lines)} cases in {seconds:.0f} s")
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
