#!/usr/bin/env python3
"""Writes the parameter table of docs/model.md from the one declaration.

Usage: .venv/bin/python scripts/gen_param_docs.py [--check]
--check exits 1 (and prints the difference) when the docs are out of date.
"""
import pathlib
import sys

import cloudgen_native

BEGIN, END = "<!-- params:begin -->", "<!-- params:end -->"
DOC = pathlib.Path(__file__).resolve().parent.parent / "docs" / "model.md"


def fmt(v):
    if isinstance(v, (list, tuple)):
        if len(v) > 3:
            return f"{len(v)} values"
        return "(" + ", ".join(fmt(x) for x in v) + ")"
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


def table():
    rows = ["| group | key | label | kind | default | limits | slider | maps to | unit | help |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for d in cloudgen_native.parameters():
        lo, hi = d["map"]
        mapping = "–" if (lo, hi) == (0, 1) else f"{fmt(lo)} … {fmt(hi)}"
        rows.append("| {} | `{}` | {} | {} | {} | [{}, {}] | [{}, {}] | {} | {} | {} |".format(
            d["group"], d["name"], d["label"], d["kind"], fmt(d["default"]), fmt(d["min"]),
            fmt(d["max"]), fmt(d["soft_min"]), fmt(d["soft_max"]), mapping, d["unit"] or "–",
            d["help"].replace("|", "\\|")))
    return "\n".join(rows)


def render(text):
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{table()}\n{END}{tail}"


def main():
    text = DOC.read_text()
    new = render(text)
    if "--check" in sys.argv:
        if new != text:
            print("docs/model.md parameter table is out of date: run scripts/gen_param_docs.py")
            return 1
        return 0
    DOC.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
