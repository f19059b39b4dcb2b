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

usage: panic-paths.py ELF [--objdump TOOL] [--check] [--allow REGEX]...
"""
import argparse
import collections
import re
import shutil
import subprocess
import sys

PANIC = re.compile(r"core::panicking::|slice_index_fail|unwrap_failed|expect_failed|len_mismatch_fail")


def objdump_tool(explicit):
    if explicit:
        return explicit
    for t in ("llvm-objdump-22", "llvm-objdump", "arm-none-eabi-objdump"):
        if shutil.which(t):
            return t
    sys.exit("panic-paths: no objdump found (llvm-objdump or binutils-arm-none-eabi)")


def strip_hash(name):
    return re.sub(r"::h[0-9a-f]{16}$", "", name)


def graph(elf, tool):
    out = subprocess.run([tool, "-d", "-C", "--no-show-raw-insn", elf], capture_output=True, text=True, check=True).stdout
    calls = collections.defaultdict(set)
    addr_of = {}
    cur = None
    for line in out.splitlines():
        m = re.match(r"^([0-9a-f]+) <(.*)>:$", line)
        if m:
            cur = strip_hash(m.group(2))
            addr_of[int(m.group(1), 16) & ~1] = cur
            continue
        m = re.search(r"\s(bl|blx|b|b\.w|beq|bne|bcs|bcc|bhi|bls|bge|blt|bgt|ble|bmi|bpl|bvs|bvc|beq\.w|bne\.w|bhi\.w|bls\.w|bcs\.w|bcc\.w|bge\.w|blt\.w|bgt\.w|ble\.w|bmi\.w|bpl\.w)\s+0x[0-9a-f]+ <([^>+]*)(\+0x[0-9a-f]+)?>", line)
        if m and cur is not None:
            target = strip_hash(m.group(2))
            if target != cur:
                calls[cur].add(target)
    return calls, addr_of


def vector_entries(elf, addr_of):
    """Function names in the vector table (reset + handlers)."""
    tool = shutil.which("llvm-readelf-22") or shutil.which("llvm-readelf") or shutil.which("readelf")
    hexdump = subprocess.run([objdump_tool(None), "-s", "-j", ".vector_table", elf], capture_output=True, text=True).stdout
    words = []
    for line in hexdump.splitlines():
        m = re.match(r"^\s*[0-9a-f]+ ((?:[0-9a-f]{8} ?){1,4})", line)
        if m:
            for w in m.group(1).split():
                words.append(int.from_bytes(bytes.fromhex(w), "little"))
    names = set()
    for w in words[1:]:  # word 0 is the initial stack pointer
        name = addr_of.get(w & ~1)
        if name:
            names.add(name)
    _ = tool
    return names


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("elf")
    ap.add_argument("--objdump")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--allow", action="append", default=[], help="regex of caller functions whose panic paths are accepted")
    args = ap.parse_args()
    calls, addr_of = graph(args.elf, objdump_tool(args.objdump))
    entries = vector_entries(args.elf, addr_of)
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
