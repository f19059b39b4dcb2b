"""The checks and the report every SOEM script against the line shares (they
came out of line.py; `import line as L` still gives them as L.<name>).

`check` prints a failed check and keeps it in `failures` (the one list of the
run, read by `report`: a script may read it, never rebind it); `Fatal` stops a
run; `say` prints at once; `report` prints the failed checks at the end and
gives the exit code.
"""


failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print(f"FAIL: {what}", flush=True)
    return ok


class Fatal(Exception):
    """A failure after which the run cannot go on."""


def say(*a):
    print(*a, flush=True)


def report(done):
    """Prints the failed checks (returns exit code 1) or `done` (0)."""
    if failures:
        say(f"\n{len(failures)} check(s) failed:")
        for f in failures:
            say(f"  {f}")
        return 1
    say(f"\n{done}")
    return 0
