"""Counts fuzz cases and records the count in the JUnit report (summary line)."""

import pytest

CASES = {"count": 0}


@pytest.fixture(scope="session", autouse=True)
def _record_case_count(record_testsuite_property):
    yield
    record_testsuite_property("cases", CASES["count"])
