"""Prints one line per test tier and the totals from the JUnit reports; exits 1
when any tier failed (including a tier that crashed before writing a report)."""

import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def counts(report):
    root = ET.parse(report).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    tests = failed = skipped = 0
    for suite in suites:
        tests += int(suite.get("tests", 0))
        failed += int(suite.get("failures", 0)) + int(suite.get("errors", 0))
        skipped += int(suite.get("skipped", 0) or suite.get("disabled", 0) or 0)
    return tests - failed - skipped, failed, skipped


def extras(report):
    """Text like " (9000 cases, 61 s)": the generated cases (a `cases` suite property,
    written by the fuzz tier) and the tier's duration, when the report has them."""
    root = ET.parse(report).getroot()
    suites = [root] if root.tag == "testsuite" else list(root.iter("testsuite"))
    parts = [
        f"{int(p.get('value'))} cases" for p in root.iter("property") if p.get("name") == "cases"
    ]
    seconds = sum(float(s.get("time") or 0) for s in suites)
    if parts and seconds:
        parts.append(f"{seconds:.0f} s")
    return f" ({', '.join(parts)})" if parts else ""


def main():
    reports = Path(sys.argv[1])
    split = sys.argv.index("--")
    names, states = sys.argv[2:split], sys.argv[split + 1 :]
    total = [0, 0, 0]
    ok = True
    for name, state in sorted(zip(names, states)):
        path = reports / f"{name}.xml"
        more = ""
        if path.exists():
            p, f, s = counts(path)
            more = extras(path)
        else:
            p, f, s = 0, 1, 0
        if state != "pass":
            ok = False
            f = max(f, 1)
        total = [total[0] + p, total[1] + f, total[2] + s]
        print(f"  {name:12s} {state:5s} {p} passed, {f} failed, {s} skipped{more}")
    print(f"{total[0]} passed, {total[1]} failed, {total[2]} skipped")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
