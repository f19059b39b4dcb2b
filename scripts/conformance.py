#!/usr/bin/env python3
"""Regenerates the item table of docs/conformance.md from the spec checklists
(../shared/spec/features-*.md) and the tests in the tree.

An item counts as tested when a test function is named after it
(`fn e025_...`, `fn c018_...`). Its status comes from docs/conformance.md's
own "Status overrides" table when one is given there (partial, n/a, ...),
otherwise: tested -> "tested", else "open".

  scripts/conformance.py          rewrite the generated section
  scripts/conformance.py --check  fail when the file is out of date (CI)
"""
import pathlib
import re
import sys

top = pathlib.Path(__file__).resolve().parent.parent
spec = (top / ".." / "shared" / "spec").resolve()
doc = top / "docs" / "conformance.md"
BEGIN = "<!-- BEGIN GENERATED: scripts/conformance.py -->"
END = "<!-- END GENERATED -->"

ITEM = re.compile(r"^- (?:\[[ x]\] )?\*{0,2}([CEP])-(\d{3})\*{0,2}\s*(?:—\s*)?(.*)$")


def items():
    if not any(spec.glob("features-*.md")):
        # a worktree or clone without ../shared beside it: say so rather
        # than write an empty table over the real one
        sys.exit(f"conformance.py: no spec checklists in {spec} (features-*.md); set up ../shared first")
    out = []
    for f in sorted(spec.glob("features-*.md")):
        for line in f.read_text().splitlines():
            m = ITEM.match(line)
            if m:
                text = re.sub(r"\s+[—-]\s+[SP]?\s*§.*$", "", m.group(3)).strip()
                text = re.sub(r"\s+§[\d.]+$", "", text)
                out.append((f"{m.group(1)}-{m.group(2)}", text))
    return out


def tests():
    found = {}
    # a test may name several items: fn e028_e045_..., fn e063_e064_e071_...
    pat = re.compile(r"fn\s+((?:[cep]\d{3}_)+)(\w*)")
    item = re.compile(r"([cep])(\d{3})_")
    for d in ("crates", "hil-sim", "tests", "firmware/src"):
        for f in sorted((top / d).rglob("*.rs")):
            if "target" in f.parts:
                continue
            for m in pat.finditer(f.read_text()):
                name = m.group(1) + m.group(2)
                for i in item.finditer(m.group(1)):
                    key = f"{i.group(1).upper()}-{i.group(2)}"
                    found.setdefault(key, []).append(name)
    return found


def overrides(text):
    ov = {}
    sect = text.split("## Status overrides", 1)
    if len(sect) < 2:
        return ov
    for line in sect[1].split(BEGIN)[0].splitlines():
        m = re.match(r"^\|\s*([CEP]-\d{3})\s*\|\s*([^|]+?)\s*\|\s*([^|]*?)\s*\|", line)
        if m:
            ov[m.group(1)] = (m.group(2), m.group(3))
    return ov


def render(text):
    ov = overrides(text)
    found = tests()
    rows = []
    counts = {}
    for key, desc in items():
        names = found.get(key, [])
        status = ov.get(key, ("tested" if names else "open", ""))[0]
        counts[status] = counts.get(status, 0) + 1
        shown = ", ".join(f"`{n}`" for n in sorted(set(names))[:3])
        if len(set(names)) > 3:
            shown += f" (+{len(set(names)) - 3})"
        desc = desc.replace("|", "\\|")
        if len(desc) > 110:
            desc = desc[:107] + "..."
        rows.append(f"| {key} | {status} | {desc} | {shown} |")
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    body = [BEGIN, "", f"Summary: {summary}.", "", "| item | status | requirement | tests |", "|---|---|---|---|", *rows, "", END]
    return "\n".join(body)


def main():
    text = doc.read_text()
    if BEGIN not in text or END not in text:
        sys.exit(f"{doc} lacks the generated-section markers")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    new = head + render(text) + tail
    if "--check" in sys.argv:
        if new != text:
            sys.exit("docs/conformance.md is out of date: run scripts/conformance.py")
        print("docs/conformance.md is up to date")
        return
    doc.write_text(new)


if __name__ == "__main__":
    main()
