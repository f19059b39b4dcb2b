#!/usr/bin/env python3
"""Instruction profile of the QEMU image, per task and function.

Reads QEMU's `-d in_asm,exec,nochain` log on stdin (every translated block
with its instructions, then every block execution), attributes each executed
block to the task whose handler ran last (EXTI0 sync0, EXTI1 control, EXTI2
esc; the idle loop resets it), and prints per task the instructions per run
and the top functions. Deterministic under `-icount`. About seven minutes for
the end-to-end run; `scripts/cross profile` runs it.

usage: qemu-system-arm ... -d in_asm,exec,nochain 2>&1 >/dev/null | qemu-profile.py ELF [TASK:FIRST:LAST]

TASK:FIRST:LAST (e.g. EXTI1:69:319, the control cycles of the csp move)
counts only runs FIRST..=LAST (1-based) of that handler; its other runs are
reported as TASK-other.
"""
import bisect
import collections
import re
import shutil
import subprocess
import sys

elf = sys.argv[1]
window = None
if len(sys.argv) > 2:
    t, a, b = sys.argv[2].split(':')
    window = (t, int(a), int(b))
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
counts = collections.Counter()
task = 'idle'
entries = {}
for a, sz, nm in syms:
    if nm in ('EXTI0', 'EXTI1', 'EXTI2'):
        entries[a] = nm
idle_rng = [(a, a + sz) for a, sz, nm in syms if nm.startswith('firmware_qemu::app::idle')]
handlers = collections.Counter()
cur = None; n = 0
for line in sys.stdin:
    if line.startswith('IN:'):
        if cur is not None: tb_len[cur] = n
        cur = None; n = 0
        continue
    m = re.match(r'^0x([0-9a-f]{8}):', line)
    if m:
        if cur is None: cur = int(m.group(1), 16)
        n += 1
        continue
    if line.startswith('Trace'):
        if cur is not None: tb_len[cur] = n; cur = None; n = 0
        m = re.search(r'\[[0-9a-f]+/([0-9a-f]+)/', line)
        if m:
            pc = int(m.group(1), 16)
            if pc in entries:
                task = entries[pc]
                handlers[task] += 1
                if window and task == window[0] and not window[1] <= handlers[task] <= window[2]:
                    task = task + '-other'
                    handlers[task] += 1
            elif idle_rng and idle_rng[0][0] <= pc < idle_rng[0][1]:
                task = 'idle'
            counts[(task, pc)] += 1
per = collections.Counter()
tot = collections.Counter()
for (t, pc), c in counts.items():
    n = c * tb_len.get(pc, 1)
    per[(t, name(pc))] += n
    tot[t] += n
print('handler entries', dict(handlers))
for t in ('EXTI1', 'EXTI2', 'EXTI0'):
    k = max(handlers[t], 1)
    if window and t == window[0]:
        k = min(window[2], handlers[t]) - window[1] + 1
    print(f'== {t}: {tot[t]} instructions, {tot[t]//max(k, 1)} per run ({k} runs)')
    rows = [(c, f) for (tt, f), c in per.items() if tt == t]
    for c, f in sorted(rows, reverse=True)[:45]:
        print(f'{c//max(k, 1):>9} per run {100*c/max(tot[t],1):5.1f}% {f[:110]}')
