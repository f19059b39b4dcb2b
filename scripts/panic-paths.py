#!/usr/bin/env python3
"""Reachable panic paths of a firmware ELF.

Builds the static call graph of the image from its disassembly (direct
`bl`/`b`/`blx`/`cbz`-free branches to function symbols) and walks it from
the entry points: the reset handler and every exception/interrupt handler in
the vector table. Any `core::panicking::*` function, `slice_index_fail`,
`unwrap_failed` or `expect_failed` reachable from there is a panic path;
the panic handler itself (`rust_begin_unwind`) is reachable only through
them, so an image without reachable panic paths has none except the handler.

Prints each reachable call site (the function that calls a panic function)
with one shortest call chain from an entry point. Exit status 1 when there is one (with --check), else 0.

Limits: calls through function pointers (trait objects, `blx reg`) are not
followed; the core crates use generics, not `dyn`, on the bus paths.

--entry REGEX adds the functions whose names match as entry points (a boot
loader's service table, boot::BootApi, is called by the running image, not
through the vector table).

usage: panic-paths.py ELF [--objdump TOOL] [--check] [--allow REGEX]... [--entry REGEX]...
"""
import argparse
import collections
import re
import sys

from elfgraph import parse, vector_entries

PANIC = re.compile(r"core::panicking::|slice_index_fail|unwrap_failed|expect_failed|len_mismatch_fail")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("--objdump")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--allow", action="append", default=[], help="regex of caller functions whose panic paths are accepted")
    ap.add_argument("--entry", action="append", default=[], help="regex of further entry points (functions called from outside)")
    args = ap.parse_args()
    calls, _frames, addr_of = parse(args.elf, args.objdump)
    entries = set(vector_entries(args.elf, addr_of, args.objdump))
    for e in args.entry:
        found = {f for f in set(addr_of.values()) | set(calls) if re.search(e, f)}
        if not found:
            sys.exit(f"panic-paths: no function matches --entry {e}")
        entries |= found
    allow = [re.compile(a) for a in args.allow]
    # breadth-first from the entries, remembering one parent per function
    parent = {e: None for e in entries}
    queue = collections.deque(sorted(entries))
    while queue:
        f = queue.popleft()
        if PANIC.search(f) or any(a.search(f) for a in allow):
            continue
        for g in sorted(calls.get(f, ())):
            if g not in parent:
                parent[g] = f
                queue.append(g)
    # every reachable function that calls a panic function directly: one line each
    sites = sorted(
        (f, p)
        for f in parent
        if not PANIC.search(f) and not any(a.search(f) for a in allow)
        for p in sorted(calls.get(f, ()))
        if PANIC.search(p)
    )
    allowed = sorted(f for f in parent if any(a.search(f) for a in allow))
    found = sorted({p for _, p in sites})
    print(
        f"panic-paths: {len(entries)} entry points, {len(parent)} reachable functions, "
        f"{len(sites)} reachable call sites of {len(found)} panic functions"
    )
    for f in allowed:
        print(f"  allowed: {f[:100]}")
    for f, p in sites:
        chain = [f]
        while parent[chain[-1]] is not None:
            chain.append(parent[chain[-1]])
        print(f"  {p[:60]} <- " + " <- ".join(c[:80] for c in chain))
    if args.check and sites:
        sys.exit(1)


if __name__ == "__main__":
    main()
