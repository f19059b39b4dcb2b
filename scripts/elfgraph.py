"""Static call graph and stack frames of a Cortex-M ELF, from its disassembly.

Shared by scripts/panic-paths.py and scripts/stack-usage.py. Direct branches
to function symbols (`bl`, `b`, conditional branches to another function:
tail calls) are edges; calls through registers (`blx rN`) are not seen.
"""
import collections
import re
import shutil
import subprocess
import sys

BRANCH = re.compile(
    r"\s(bl|blx|b|b\.w|beq|bne|bcs|bcc|bhi|bls|bge|blt|bgt|ble|bmi|bpl|bvs|bvc|beq\.w|bne\.w|bhi\.w|bls\.w"
    r"|bcs\.w|bcc\.w|bge\.w|blt\.w|bgt\.w|ble\.w|bmi\.w|bpl\.w)\s+0x[0-9a-f]+ <([^>+]*)(\+0x[0-9a-f]+)?>"
)
PUSH = re.compile(r"\s(push|push\.w|stmdb)\s+(?:sp!,\s*)?\{([^}]*)\}")
VPUSH = re.compile(r"\svpush\s+\{([^}]*)\}")
SUB_SP = re.compile(r"\bsub(?:w|\.w)?\s+sp,\s*(?:sp,\s*)?#(0x[0-9a-f]+|\d+)")


def tool(*names):
    for t in names:
        if shutil.which(t):
            return t
    sys.exit(f"elfgraph: none of {names} found")


def objdump_tool(explicit=None):
    return explicit or tool("llvm-objdump-22", "llvm-objdump", "arm-none-eabi-objdump")


def strip_hash(name):
    return re.sub(r"::h[0-9a-f]{16}$", "", name)


def reg_count(regs):
    """Registers in a push list such as `r4, r5, r6, r7, lr` or `r4-r7`."""
    n = 0
    for part in regs.split(","):
        part = part.strip()
        m = re.match(r"[rd](\d+)-[rd](\d+)", part)
        n += int(m.group(2)) - int(m.group(1)) + 1 if m else (1 if part else 0)
    return n


def parse(elf, objdump=None):
    """(calls, frames, addr_of): callee sets, bytes each function pushes and
    subtracts from sp, and function name by start address."""
    out = subprocess.run([objdump_tool(objdump), "-d", "-C", "--no-show-raw-insn", elf],
                         capture_output=True, text=True, check=True).stdout
    ends = function_ends(elf, objdump)
    calls = collections.defaultdict(set)
    frames = collections.Counter()
    addr_of = {}
    cur = None
    end = None
    in_data = False
    for line in out.splitlines():
        m = re.match(r"^([0-9a-f]+) <(.*)>:$", line)
        if m:
            name = m.group(2)
            if re.match(r"^\$[adt](\.\d+)?$", name):
                # ARM mapping symbols mark code ($t, $a) and literal pools ($d)
                # inside a function: the function goes on
                in_data = name.startswith("$d")
                continue
            cur = strip_hash(name)
            in_data = False
            start = int(m.group(1), 16) & ~1
            addr_of[start] = cur
            end = ends.get(start)
            continue
        if cur is None or in_data:
            continue
        if end is not None:
            a = re.match(r"^\s*([0-9a-f]+):", line)
            if a and int(a.group(1), 16) >= end:
                # past the function's size: alignment padding (a hand-written
                # function has no $d symbol over it) decoded as instructions
                continue
        m = BRANCH.search(line)
        if m:
            target = strip_hash(m.group(2))
            if target != cur:
                calls[cur].add(target)
            continue
        m = PUSH.search(line)
        if m:
            frames[cur] += 4 * reg_count(m.group(2))
            continue
        m = VPUSH.search(line)
        if m:
            frames[cur] += 8 * reg_count(m.group(1))
            continue
        m = SUB_SP.search(line)
        if m:
            frames[cur] += int(m.group(1), 0)
    return calls, frames, addr_of


def function_ends(elf, objdump=None):
    """End address of each function symbol with a size, by start address
    (the symbol table: `objdump -t`)."""
    out = subprocess.run([objdump_tool(objdump), "-t", elf], capture_output=True, text=True).stdout
    ends = {}
    for line in out.splitlines():
        m = re.match(r"^([0-9a-f]+)\s.*\sF\s+\S+\s+([0-9a-f]+)\s", line)
        if m and int(m.group(2), 16) > 0:
            start = int(m.group(1), 16) & ~1
            ends[start] = start + int(m.group(2), 16)
    return ends


def vector_entries(elf, addr_of, objdump=None):
    """Handler names in the vector table, in table order (reset first)."""
    dump = subprocess.run([objdump_tool(objdump), "-s", "-j", ".vector_table", elf],
                          capture_output=True, text=True).stdout
    words = []
    for line in dump.splitlines():
        m = re.match(r"^\s*[0-9a-f]+ ((?:[0-9a-f]{8} ?){1,4})", line)
        if m:
            for w in m.group(1).split():
                words.append(int.from_bytes(bytes.fromhex(w), "little"))
    names = []
    for w in words[1:]:  # word 0 is the initial stack pointer
        name = addr_of.get(w & ~1)
        if name and name not in names:
            names.append(name)
    return names
