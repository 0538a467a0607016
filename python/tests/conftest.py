"""pytest's hooks for python/tests, run one file a ctest (tests/CMakeLists.txt).

A file whose tests passed but some were skipped (a real-time test on a loaded machine, PyKDL or
the view's front end missing) must not show as Passed in ctest: that would be a silent pass. Its
summary then says "rccx-skip:", the ctests' SKIP_REGULAR_EXPRESSION, and -rs prints each skip's
reason. A file with a failure fails whatever else was skipped.
"""


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    skipped = len(terminalreporter.stats.get("skipped", []))
    if exitstatus != 0 or skipped == 0:
        return
    passed = len(terminalreporter.stats.get("passed", []))
    terminalreporter.write_line(
        f"rccx-skip: {skipped} test(s) of this file skipped (reasons in the summary below); "
        f"{passed} passed")
