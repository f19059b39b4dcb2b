#!/usr/bin/env python3
"""Static worst-case stack use of each task (interrupt handler) of a firmware ELF.

From the disassembly (scripts/elfgraph.py): each function's frame is what its
pushes, vpushes and `sub sp` take; a task's worst case is its handler's frame
plus the deepest chain of direct calls below it, plus the exception frame the
core stacks on entry (104 bytes with the FPU context). Calls through
registers are not seen, and a cycle in the call graph (recursion) makes the
bound unknown: both are reported. Tasks at the same priority never nest;
preempting tasks add up (docs/architecture.md has the priorities).

`main` (the reset path: RTIC's `init`, where the images build their statics)
is measured as well, and the stack the image has is read from cortex-m-rt's
symbols (`_stack_start` down to the end of the statics, `__euninit`): the
start-up path must fit in it, and so must every task stacked on another
(their sum, an upper bound of any nesting). A shortfall fails the run: on
silicon it is a fault before the first frame (issue 36: the PROFINET
image's 86 KiB drive construction against 72 KiB of stack).

usage: stack-usage.py ELF HANDLER [HANDLER ...] [--objdump TOOL]
"""
import argparse
import subprocess
import sys

from elfgraph import parse, vector_entries

EXCEPTION_FRAME = 104  # 8 words + 18 FPU words (lazy stacking reserves them)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("handlers", nargs="*")
    ap.add_argument("--objdump")
    args = ap.parse_args()
    calls, frames, addr_of = parse(args.elf, args.objdump)
    handlers = args.handlers or vector_entries(args.elf, addr_of, args.objdump)
    memo, unknown = {}, set()

    def worst(f, path):
        if f in memo:
            return memo[f]
        if f in path:
            unknown.add(f)
            return 0
        path.add(f)
        below = max((worst(g, path) for g in calls.get(f, ())), default=0)
        path.discard(f)
        memo[f] = frames[f] + below
        return memo[f]

    print(f"{'task (handler)':<28} {'static worst case, bytes':>26}  deepest frame")
    for h in handlers:
        if h not in addr_of.values():
            print(f"{h:<28} {'(not in the image)':>26}")
            continue
        total = worst(h, set()) + EXCEPTION_FRAME
        deepest = max(((frames[g], g) for g in memo if g in reach(h, calls)), default=(0, h))
        print(f"{h:<28} {total:>26}  {deepest[1][:60]} ({deepest[0]} B)")
    if unknown:
        print("recursion (bound unknown) through: " + ", ".join(sorted(unknown)[:5]))
    room = stack_room(args.elf, args.objdump)
    if room is None or "main" not in addr_of.values():
        return 0
    start = worst("main", set())
    tasks = sum(worst(h, set()) + EXCEPTION_FRAME for h in handlers if h in addr_of.values() and h != "main")
    ok = start <= room and tasks <= room
    print(
        f"stack room {room} bytes (_stack_start - __euninit): start-up (main) {start}, "
        f"all tasks stacked {tasks}: " + ("fits" if ok else "DOES NOT FIT")
    )
    return 0 if ok else 1


def stack_room(elf, objdump):
    """Bytes from the end of the statics (`__euninit`) to `_stack_start`,
    from the ELF's symbols; None when they are not there."""
    nm = (objdump or "llvm-objdump").replace("objdump", "nm")
    try:
        out = subprocess.run([nm, elf], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    sym = {}
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3:
            sym[parts[2]] = int(parts[0], 16)
    if "_stack_start" not in sym or "__euninit" not in sym:
        return None
    return sym["_stack_start"] - sym["__euninit"]


def reach(h, calls):
    seen, todo = {h}, [h]
    while todo:
        f = todo.pop()
        for g in calls.get(f, ()):
            if g not in seen:
                seen.add(g)
                todo.append(g)
    return seen


if __name__ == "__main__":
    sys.exit(main())
