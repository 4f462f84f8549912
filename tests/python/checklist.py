"""Shared by the Python tests: each check is printed as ok/FAIL, and the tally becomes the exit code."""
import sys


class Checks:
    def __init__(self):
        self.failures = []

    def __call__(self, ok, what):
        print(f"{'ok  ' if ok else 'FAIL'} {what}")
        if not ok:
            self.failures.append(what)
        return ok

    def exit_code(self, name):
        print(f"{name}: {len(self.failures)} check(s) failed" if self.failures else f"{name}: all checks passed",
              file=sys.stderr if self.failures else sys.stdout)
        return 1 if self.failures else 0


def summarise(name, checks):
    """checks: list of (what, ok). Prints them and returns the exit code."""
    c = Checks()
    for what, ok in checks:
        c(ok, what)
    return c.exit_code(name)
