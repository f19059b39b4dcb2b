#!/usr/bin/env python3
"""Static worst-case stack use of each task (interrupt handler) of a firmware ELF.

From the disassembly (scripts/elfgraph.py): each function's frame is what its
pushes, vpushes and `sub sp` take; a task's worst case is its handler's frame
plus the deepest chain of direct calls below it, plus the exception frame the
core stacks on entry (104 bytes with the FPU context). Calls through
registers are not seen, and a cycle in the call graph (recursion) makes the
bound unknown: both are reported. Tasks at the same priority never nest;
preempting tasks add up (docs/architecture.md has the priorities).

usage: stack-usage.py ELF HANDLER [HANDLER ...] [--objdump TOOL]
"""
import argparse
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
