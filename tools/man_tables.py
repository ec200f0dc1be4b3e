#!/usr/bin/env python3
"""Markdown tables -> bullet lists, for the man page: a terminal is 80 columns wide, and tbl splits a
table whose rows are wider across lines that no longer read as rows (docs/manual.md keeps its tables,
which read well on the web). Each row becomes one item: its first cell, then every other cell after its
column's name. Reads standard input, writes standard output.

    | option | default | meaning |          - `--spp` (default: 1): samples per pixel
    |---|---|---|                     ->
    | `--spp` | 1 | samples per pixel |
"""
import re
import sys


def cells(line):
    # "\\|" is a pipe inside a cell (`perspective\\|ortho`), not a border.
    inner = line.strip().strip("|")
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", inner)]


def main():
    lines = sys.stdin.read().split("\n")
    out, k = [], 0
    while k < len(lines):
        line = lines[k]
        rule = lines[k + 1] if k + 1 < len(lines) else ""
        if line.lstrip().startswith("|") and re.fullmatch(r"\s*\|?(\s*:?-+:?\s*\|)+\s*:?-*:?\s*\|?\s*", rule):
            head = cells(line)
            k += 2
            while k < len(lines) and lines[k].lstrip().startswith("|"):
                row = cells(lines[k])
                rest = []
                for name, value in zip(head[1:], row[1:]):
                    if value in ("", "-"):
                        continue
                    # The last column is the row's description: no label before it.
                    rest.append(value if name == head[-1] and len(head) > 2 else f"{name}: {value}")
                text = row[0]
                if len(head) > 2 and len(rest) > 1:
                    text += " (" + "; ".join(rest[:-1]) + "): " + rest[-1]
                elif rest:
                    text += ": " + "; ".join(rest)
                out.append("- " + text)
                k += 1
            out.append("")
            continue
        out.append(line)
        k += 1
    sys.stdout.write("\n".join(out))


if __name__ == "__main__":
    main()
