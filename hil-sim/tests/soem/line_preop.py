"""Steps 1 to 5 of the SOEM line test (line.py, whose docstring lists the
steps with their spec items), all in Pre-Op: the expected values from the
Rust side (`load_od`), the scan's identity and the SII read back, SDO Info
of every object, the default PDO objects, the refused SDOs, the remap in
Pre-Op, and the refusals at Pre-Op -> Safe-Op. line.py runs them (its
`run`) and gives every name here as L.<name> too.
"""
import struct
import time

from soem_mailbox import attempt, entry, sdo_abort, sdo_u, u, write, write_map
from soem_master import ERR, PREOP, SAFEOP, acknowledge, request
from soem_report import check, say


# --- expected values from the Rust side -------------------------------------


def load_od(path):
    """{index: (code, max_sub, dtype or None, name, {sub: (dtype, bits, access, default, name)})}"""
    od = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            p = line.rstrip("\n").split("\t")
            if p[0] == "obj":
                dtype = None if p[4] == "-" else int(p[4], 16)
                od[int(p[1], 16)] = (int(p[2]), int(p[3]), dtype, p[5], {})
            elif p[0] == "ent":
                od[int(p[1], 16)][4][int(p[2], 16)] = (
                    int(p[3], 16),
                    int(p[4]),
                    int(p[5], 16),
                    int(p[6]),
                    p[7],
                )
    return od


def name40(s):
    """A name as SOEM keeps it (EC_MAXNAME = 40 bytes)."""
    return s.encode("utf-8")[:40]


# --- 1. scan, identity, SII ---------------------------------------------------


def sii_strings_1(sii):
    """String 1 of the STRINGS category (10): SOEM's name of a slave."""
    word = 0x40
    while word * 2 + 4 <= len(sii):
        cat, size = struct.unpack_from("<HH", sii, word * 2)
        if cat == 0xFFFF:
            break
        if cat == 10:
            off = word * 2 + 4
            n = sii[off + 1]
            return sii[off + 2 : off + 2 + n].decode("latin-1")
        word += 2 + size
    return None


def identity_and_sii(m, sii):
    vendor, product, revision = struct.unpack_from("<III", sii, 0x08 * 2)
    name = sii_strings_1(sii)
    say(f"expected from the SII image: '{name}', vendor {vendor:#x}, product {product:#x}, revision {revision:#x}")
    for i, s in enumerate(m.slaves):
        say(f"slave {i + 1}: '{s.name}' vendor {s.man:#x} product {s.id:#x} revision {s.rev:#x}")
        check(s.name == name, f"slave {i + 1}: SOEM's name '{s.name}' (SII string 1) is '{name}'")
        check(
            (s.man, s.id, s.rev) == (vendor, product, revision),
            f"slave {i + 1}: identity from the SII {s.man:#x}/{s.id:#x}/{s.rev:#x}",
        )

        # E-004, E-005, E-151: 1000h, 1018h, and 1018h:03 equal to the SII's revision
        def identity():
            problems = []
            dev = sdo_u(s, 0x1000, 0)
            if dev != 0x0002_0192:
                problems.append(f"slave {i + 1}: 1000h = {dev:08X}h, expected 0002 0192h")
            ident = [sdo_u(s, 0x1018, k) for k in range(4)]
            if ident != [4, vendor, product, revision]:
                problems.append(f"slave {i + 1}: 1018h:00..03 = {ident}, the SII says {[4, vendor, product, revision]}")
            return problems

        attempt(m, i, "identity objects", identity)

        def sii_image():
            t = time.monotonic()
            got = bytearray()
            for w in range(0, len(sii) // 2, 2):
                got += s.eeprom_read(w, 100_000)
            got = bytes(got[: len(sii)])
            diff = [k for k in range(len(sii)) if got[k] != sii[k]]
            say(f"slave {i + 1}: SII read back through SOEM, {len(got)} bytes in {time.monotonic() - t:.2f} s, {len(diff)} differ")
            return [f"slave {i + 1}: SII byte {k:#x} is {got[k]:#04x}, the image has {sii[k]:#04x}" for k in diff[:8]]

        attempt(m, i, "SII", sii_image)


# --- 2. SDO Info, PDO objects ------------------------------------------------


def object_problems(m, i, o, od):
    """What SOEM read of object `o` (description, every entry) against the
    declaration."""
    code, max_sub, dtype, name, ents = od[o.index]
    at = f"slave {i + 1}: {o.index:04X}h"
    problems = []
    m._collect_mailbox_errors()
    if o.name != name40(name):
        problems.append(f"{at} name {o.name!r}, declared {name!r}")
    if o.object_code != code:
        problems.append(f"{at} object code {o.object_code}, declared {code}")
    if dtype is not None and o.data_type != dtype:
        problems.append(f"{at} data type {o.data_type:#06x}, declared {dtype:#06x}")
    got = o.entries  # SOEM reads the description of every sub 0..max sub
    errors = m._collect_mailbox_errors()  # the SDO Info errors of subs that do not exist
    if max_sub == 0:
        e = ents[0]
        if (o.bit_length, o.obj_access) != (e[1], e[2]):
            problems.append(f"{at}:00 bit length {o.bit_length}, access {o.obj_access:#06x}; declared {e[1]}, {e[2]:#06x}")
        return problems, 1
    if len(got) != max_sub + 1:
        problems.append(f"{at} max subindex {len(got) - 1}, declared {max_sub}")
    gaps = described = 0
    for sub, ge in enumerate(got):
        if sub not in ents:
            gaps += 1
            if ge.data_type != 0:
                problems.append(f"{at}:{sub:02X} not declared but described")
            continue
        d_type, bits, access, _default, e_name = ents[sub]
        described += 1
        if (ge.name, ge.data_type, ge.bit_length, ge.obj_access) != (name40(e_name), d_type, bits, access):
            problems.append(
                f"{at}:{sub:02X} entry ({ge.name!r}, {ge.data_type:#06x}, {ge.bit_length}, {ge.obj_access:#06x}), "
                f"declared ({e_name!r}, {d_type:#06x}, {bits}, {access:#06x})"
            )
    if len(errors) != gaps:
        problems.append(f"{at}: {len(errors)} SDO Info errors for {gaps} undeclared subindexes")
    return problems, described


def sdo_info(m, i, od):
    s = m.slaves[i]
    t = time.monotonic()
    listed = []

    def object_list():
        listed[:] = [o.index for o in s.od]
        m._collect_mailbox_errors()
        if listed != sorted(od):
            return [f"slave {i + 1}: OD list of {len(listed)} objects, the dictionary shows {len(od)}"]
        return []

    attempt(m, i, "OD list", object_list)
    entries = 0
    objects = s.od
    for o in objects:
        if o.index not in od:
            continue
        found = [o]

        def description():
            # a repeated read needs a fresh object (pysoem keeps what it read)
            if found[0] is None:
                found[0] = next(x for x in s.od if x.index == o.index)
            problems, n = object_problems(m, i, found[0], od)
            found[0] = None
            found.append(n)
            return problems

        attempt(m, i, f"SDO Info of {o.index:04X}h", description)
        entries += found[-1] if len(found) > 1 else 0
    say(f"slave {i + 1}: SDO Info: {len(listed)} objects, {entries} entry descriptions in {time.monotonic() - t:.2f} s")


def default_pdo_objects(od):
    assign = {}
    maps = {}
    for a in (0x1C12, 0x1C13):
        ents = od[a][4]
        assign[a] = [ents[k][3] for k in range(1, ents[0][3] + 1)]
    for p in list(range(0x1600, 0x1604)) + list(range(0x1A00, 0x1A04)):
        ents = od[p][4]
        maps[p] = [ents[k][3] for k in range(1, ents[0][3] + 1)]
    return assign, maps


# --- 3. refused SDOs ----------------------------------------------------------


def bad_sdos(m, i, od):
    s = m.slaves[i]
    missing = next(x for x in range(0x5FFF, 0x5000, -1) if x not in od)
    cases = [
        (f"read of the non-existent object {missing:04X}h", lambda: s.sdo_read(missing, 0), 0x0602_0000),
        ("read of the non-existent subindex 1018h:09", lambda: s.sdo_read(0x1018, 9), 0x0609_0011),
        ("write of the read-only 1018h:01", lambda: s.sdo_write(0x1018, 1, (0x1234).to_bytes(4, "little")), 0x0601_0002),
        ("write of the read-only 6041h", lambda: s.sdo_write(0x6041, 0, b"\x00\x00"), 0x0601_0002),
    ]
    for what, call, want in cases:

        def abort():
            got = sdo_abort(call)
            shown = "no abort" if got is None else f"{got:08X}h"
            say(f"slave {i + 1}: {what}: {shown}")
            return [] if got == want else [f"slave {i + 1}: {what}: {shown}, expected {want:08X}h"]

        attempt(m, i, what, abort)


# --- 4. remap in Pre-Op -------------------------------------------------------


# axis A: a shorter RxPDO and a different TxPDO; axis B keeps its default
# mapping, and both channels are assigned (the default assigns axis A only)
RX_A = [entry(0x6040, 0, 16), entry(0x6060, 0, 8), entry(0x607A, 0, 32)]
TX_A = [
    entry(0x6041, 0, 16),
    entry(0x6061, 0, 8),
    entry(0x6064, 0, 32),
    entry(0x60F4, 0, 32),
    entry(0x606C, 0, 32),
    entry(0x603F, 0, 16),
]
ASSIGN = {0x1C12: [0x1600, 0x1601], 0x1C13: [0x1A00, 0x1A01]}


def remap(s):
    for a in ASSIGN:
        s.sdo_write(a, 0, b"\x00")
    write_map(s, 0x1600, RX_A)
    write_map(s, 0x1A00, TX_A)
    for a, pdos in ASSIGN.items():
        for k, p in enumerate(pdos, 1):
            s.sdo_write(a, k, p.to_bytes(2, "little"))
        s.sdo_write(a, 0, bytes([len(pdos)]))


# --- 5. refusals at Pre-Op -> Safe-Op ----------------------------------------


def refusal(m, emcys, i, what, want_code, undo, emcy=True):
    st, code = request(m, i, SAFEOP)
    say(f"slave {i + 1}: {what}: Pre-Op -> Safe-Op gives state {st:#04x}, AL status code {code:04X}h")
    check(st == PREOP | ERR and code == want_code, f"slave {i + 1}: {what}: state {st:#04x} AL {code:04X}h, expected 0x12 and {want_code:04X}h")
    got = emcys.drain(m, i, 0.5 if emcy else 0.0)
    codes = [f"{e.error_code:04X}h" for e in got]
    say(f"slave {i + 1}: EMCY after the refusal: {codes}")
    if emcy:
        # E-028: a refused SyncManager configuration is reported by EMCY A000h
        check(any(e.error_code == 0xA000 for e in got), f"slave {i + 1}: {what}: EMCY A000h expected, got {codes}")
    undo()
    st, code = acknowledge(m, i)
    check(st == PREOP, f"slave {i + 1}: back in Pre-Op after the acknowledge: {st:#04x} {code:04X}h")


def refusals(m, emcys, layout_in):
    n = len(m.slaves)
    # the mapping changed behind the master's back: SM2 as SOEM configured it
    # (from the mapping it read) is longer than the mapping now
    write(m, 0, 0x1600, 0, bytes([len(RX_A) - 1]))
    refusal(
        m,
        emcys,
        0,
        f"1600h:00 = {len(RX_A) - 1} after config_map (SM2 length from the previous mapping)",
        0x001D,
        lambda: write(m, 0, 0x1600, 0, bytes([len(RX_A)])),
    )
    # SM3 length register not matching the mapping
    i = 1 % n
    s = m.slaves[i]
    sm3 = s._fprd(0x0818, 8, 20_000)
    length = u(sm3[2:4])
    check(length == layout_in.bytes, f"slave {i + 1}: SOEM programmed SM3 with {length} bytes, the mapping has {layout_in.bytes}")
    s._fpwr(0x0818 + 2, (length + 2).to_bytes(2, "little"), 20_000)
    refusal(m, emcys, i, f"SM3 length {length + 2} for a {length}-byte mapping", 0x001E, lambda: s._fpwr(0x081A, sm3[2:4], 20_000))
    # SYNC0 cycles the drive must refuse (A150 = 1 ms)
    i = 2 % n
    s = m.slaves[i]
    s.dc_sync(True, 1_100_000)
    refusal(m, emcys, i, "SYNC0 cycle 1.1 ms (not a multiple of 250 us)", 0x0035, lambda: s.dc_sync(False, 0), emcy=False)
    s.dc_sync(True, 1_500_000)
    refusal(m, emcys, i, "SYNC0 cycle 1.5 ms (not a multiple of A150 = 1 ms)", 0x0036, lambda: s.dc_sync(False, 0), emcy=False)
