#!/usr/bin/env python3
"""Prints the rows of peers_*.json files as one Markdown table: python3 table.py OUT_DIR/peers_*.json"""
import json
import sys


def pct(v):
    return "–" if v is None else f"{100 * v:.1f} %"


print("| peer | scene | nodes | setting | ms/step | stretch at 2 s | largest stretch | diverged at | DC |")
print("|---|---|---|---|---|---|---|---|---|")
for path in sys.argv[1:]:
    doc = json.load(open(path))
    for r in doc["rows"]:
        scene = f"sheet {r['side']} × {r['side']}" if r["scene"] == "sheet" else "drape"
        ms = "–" if r["ms_per_step"] is None else f"{r['ms_per_step']:.1f}"
        div = "–" if r["diverged_at_s"] is None else f"{r['diverged_at_s']:.1f} s"
        dc = "–" if r["drape_coefficient"] is None else f"{r['drape_coefficient']:.2f}"
        print(f"| {doc['peer']} | {scene} | {r['nodes']} | {r['setting']} | {ms} | "
              f"{pct(r['stretch_end'])} | {pct(r['stretch_max'])} | {div} | {dc} |")
