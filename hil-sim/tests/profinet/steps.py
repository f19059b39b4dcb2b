"""The step lines the controller scripts share (controller.py on
profinet-py, tia.py on scapy): `step X: ok: ...` or `step X: FAIL: ...`,
the failed steps kept in `failures`; a script's verdict on its steps (or
fb.py's on its scenarios). No import beyond the standard library, so that
every one of their pythons can load it."""

import traceback

# the steps that failed, in the order they were reported
failures = []


def report(step, ok, text):
    """Prints step `step`'s line; a failed one is kept in `failures`."""
    if not ok:
        failures.append(step)
    print(f"step {step}: {'ok' if ok else 'FAIL'}: {text}", flush=True)


def run(step, fn):
    """Runs one step; an exception is the step's failure (with its traceback)."""
    try:
        return fn()
    except Exception as e:  # noqa: BLE001 - every failure is reported the same way
        tb = traceback.format_exc().strip().replace("\n", "\n    ")
        report(step, False, f"{type(e).__name__}: {e}\n    {tb}")
        return None


def verdict(failed, kind, passed):
    """A script's exit code: 1 after naming the `failed` steps (`kind`: "steps",
    "scenarios"), 0 after the line `passed` when none failed."""
    if failed:
        print(f"failed {kind}: {' '.join(failed)}", flush=True)
        return 1
    print(passed, flush=True)
    return 0
