#!/usr/bin/env python3
"""Instruction profile of the QEMU image, per task and function.

Reads QEMU's `-d in_asm,exec,nochain` log on stdin (every translated block
with its instructions, then every block execution), attributes each executed
block to the task whose handler ran last (EXTI0 sync0, EXTI1 control, EXTI2
esc; the idle loop resets it), and prints per task the instructions per run
and the top functions. Deterministic under `-icount`. About seven minutes for
the end-to-end run; `scripts/cross profile` runs it.

usage: qemu-system-arm ... -d in_asm,exec,nochain 2>&1 >/dev/null | qemu-profile.py ELF [TASK:FIRST:LAST [LINES]]

TASK:FIRST:LAST[:EVERY] (e.g. EXTI1:69:319, the control cycles of the csp
move) counts only runs FIRST..=LAST (1-based) of that handler, with EVERY
only every EVERY-th of them from FIRST on; its other runs are reported as
TASK-other. PROFILE_ENTRY=NAME:SYMBOL makes the calls of the function whose
name contains SYMBOL the runs of a task NAME (an image without tasks:
firmware-qemu-pn), PROFILE_IDLE=SYMBOL the caller whose blocks end a run. LINES (e.g. 60) also lists that task's costliest
source lines per run: each instruction charged to the innermost frame in the
project's crates (llvm-addr2line with inlining, so the lines of functions
LTO inlined into the task count where they are written), and the call sites
of the memory routines (memcpy, memclr, memset, memcmp) with the
instructions those calls cost.
"""
import bisect
import collections
import json
import os
import re
import shutil
import subprocess
import sys

elf = sys.argv[1]
window = None
if len(sys.argv) > 2:
    t, a, b, *every = sys.argv[2].split(':')
    window = (t, int(a), int(b), int(every[0]) if every else 1)
lines_wanted = int(sys.argv[3]) if len(sys.argv) > 3 else 0
# symbols
syms = []
nm = shutil.which('llvm-nm-22') or shutil.which('llvm-nm') or 'arm-none-eabi-nm'
out = subprocess.run([nm, '-C', '--defined-only', '-S', '-n', elf], capture_output=True, text=True).stdout
for line in out.splitlines():
    p = line.split(None, 3)
    if len(p) == 4 and p[2].lower() == 't':
        syms.append((int(p[0], 16) & ~1, int(p[1], 16), re.sub(r'::h[0-9a-f]{16}$', '', p[3])))
syms.sort()
starts = [s[0] for s in syms]
def name(pc):
    i = bisect.bisect_right(starts, pc) - 1
    if i >= 0 and pc < syms[i][0] + max(syms[i][1], 1):
        return syms[i][2]
    return '?'
tb_len = {}   # pc -> instruction count (from in_asm)
tb_ins = {}   # pc -> the block's instruction addresses (for the per-line listing)
tb_last = {}  # pc -> the block's last instruction (a call site)
# the memory routines: their instructions charged to the block that called them
mem_rng = [(a, a + max(sz, 1)) for a, sz, nm in syms
           if re.match(r'(__aeabi_mem|compiler_builtins::mem::|memc(py|mp)$|memset$|memmove$)', nm)]
mem_calls = collections.Counter()
caller = {}
counts = collections.Counter()
task = 'idle'
entries = {}
# PROFILE_ENTRY=NAME:SYMBOL (an image without tasks, e.g. firmware-qemu-pn):
# the function whose demangled name contains SYMBOL counts as the task NAME
# (its runs are entries), and PROFILE_IDLE=SYMBOL the code that ends a run
# (the caller's own blocks; default the RTIC idle loop)
extra = os.environ.get('PROFILE_ENTRY', '')
extra_name, _, extra_sym = extra.partition(':')
for a, sz, nm in syms:
    if nm in ('EXTI0', 'EXTI1', 'EXTI2'):
        entries[a] = nm
    elif extra_sym and extra_sym in nm:
        entries[a] = extra_name
idle_sym = os.environ.get('PROFILE_IDLE', 'firmware_qemu::app::idle')
idle_rng = [(a, a + sz) for a, sz, nm in syms if nm.startswith(idle_sym)]
handlers = collections.Counter()
cur = None; n = 0; ins = []
for line in sys.stdin:
    if line.startswith('IN:'):
        if cur is not None: tb_len[cur] = n; tb_ins[cur] = ins; tb_last[cur] = last
        cur = None; n = 0; ins = []
        continue
    m = re.match(r'^0x([0-9a-f]{8}):', line)
    if m:
        if cur is None: cur = int(m.group(1), 16)
        last = int(m.group(1), 16)
        n += 1
        if lines_wanted: ins.append(int(m.group(1), 16))
        continue
    if line.startswith('Trace'):
        if cur is not None: tb_len[cur] = n; tb_ins[cur] = ins; tb_last[cur] = last; cur = None; n = 0; ins = []
        m = re.search(r'\[[0-9a-f]+/([0-9a-f]+)/', line)
        if m:
            pc = int(m.group(1), 16)
            if pc in entries and not (extra_name and entries[pc] == extra_name and task != 'idle'):
                # (the extra entry counts a run only from the caller: its
                # first block runs again within a run)
                task = entries[pc]
                handlers[task] += 1
                if window and task == window[0] and not (
                    window[1] <= handlers[task] <= window[2] and (handlers[task] - window[1]) % window[3] == 0
                ):
                    task = task + '-other'
                    handlers[task] += 1
            elif any(lo <= pc < hi for lo, hi in idle_rng):
                task = 'idle'
            counts[(task, pc)] += 1
            if lines_wanted and window and task == window[0]:
                if any(lo <= pc < hi for lo, hi in mem_rng):
                    mem_calls[caller.get(task)] += tb_len.get(pc, 1)
                else:
                    caller[task] = pc
per = collections.Counter()
tot = collections.Counter()
for (t, pc), c in counts.items():
    n = c * tb_len.get(pc, 1)
    per[(t, name(pc))] += n
    tot[t] += n
print('handler entries', dict(handlers))
for t in ('EXTI1', 'EXTI2', 'EXTI0') + ((extra_name,) if extra_name else ()):
    k = max(handlers[t], 1)
    if window and t == window[0]:
        k = (min(window[2], handlers[t]) - window[1]) // window[3] + 1
    print(f'== {t}: {tot[t]} instructions, {tot[t]//max(k, 1)} per run ({k} runs)')
    rows = [(c, f) for (tt, f), c in per.items() if tt == t]
    for c, f in sorted(rows, reverse=True)[:45]:
        print(f'{c//max(k, 1):>9} per run {100*c/max(tot[t],1):5.1f}% {f[:110]}')

if lines_wanted and window:
    # the window task's instructions, each charged to its innermost frame
    # in the project's crates
    t = window[0]
    k = max((min(window[2], handlers[t]) - window[1]) // window[3] + 1, 1)
    per_ins = collections.Counter()
    for (tt, pc), c in counts.items():
        if tt == t:
            for a in tb_ins.get(pc, [pc]):
                per_ins[a] += c
    tool = shutil.which('llvm-addr2line-22') or shutil.which('llvm-addr2line')
    if not tool:
        print('(no llvm-addr2line: no per-line listing)')
        sys.exit(0)
    addrs = sorted(per_ins)
    out = subprocess.run([tool, '-e', elf, '-i', '-f', '--output-style=JSON'],
                         input='\n'.join(hex(a) for a in addrs), capture_output=True, text=True).stdout
    per_line = collections.Counter()
    top_dir = elf.split('/firmware/target/')[0] + '/'
    for a, row in zip(addrs, out.splitlines()):
        frames = json.loads(row).get('Symbol') or []
        where = None
        for f in frames:
            if f['FileName'].startswith(top_dir + 'crates/'):
                where = f"{f['FileName'][len(top_dir):]}:{f['Line']}"
                break
        if where is None:
            # outside crates/: the firmware's own code by line, anything
            # else (core, compiler-builtins, the runtime) by function
            f = frames[-1] if frames else {}
            fname = f.get('FileName', '')
            if fname.startswith(top_dir):
                where = f"{fname[len(top_dir):]}:{f.get('Line', 0)}"
            else:
                where = f"? {f.get('FunctionName', '')[:80]}"
        per_line[where] += per_ins[a]
    total = max(sum(per_line.values()), 1)
    print(f'== {t}: the {lines_wanted} costliest source lines per run (innermost frame in crates/)')
    for where, c in per_line.most_common(lines_wanted):
        print(f'{c/k:>9.1f} per run {100*c/total:5.1f}% {where}')
    # the memory routines by call site (the calling block's last instruction)
    sites = [(pc, c) for pc, c in mem_calls.most_common(20) if pc is not None]
    out = subprocess.run([tool, '-e', elf, '-i', '-f', '--output-style=JSON'],
                         input='\n'.join(hex(tb_last.get(pc, pc)) for pc, _ in sites),
                         capture_output=True, text=True).stdout
    print(f'== {t}: the memory routines by call site per run ({sum(mem_calls.values())/k:.1f} per run)')
    for (pc, c), row in zip(sites, out.splitlines()):
        frames = json.loads(row).get('Symbol') or []
        chain = ' < '.join(f"{f['FileName'][len(top_dir):] if f['FileName'].startswith(top_dir) else f['FunctionName'][:40]}:{f['Line']}"
                           for f in frames[:3])
        print(f'{c/k:>9.1f} per run {tb_last.get(pc, pc):#x} {name(pc)[:60]} @ {chain}')
