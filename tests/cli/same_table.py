# SPDX-License-Identifier: Apache-2.0
"""Two study tables (study.csv) hold the same runs and results: every column but those
that say how long a run took, how much memory it used and where it ran."""
import csv
import sys

WHERE_AND_HOW_LONG = {"wall_s", "measure_s", "advect_s", "renorm_s", "mesh_s", "peak_rss_mb", "threads",
                      "host"}


def table(path):
    rows = list(csv.DictReader(open(path)))
    return [{k: v for k, v in r.items() if k not in WHERE_AND_HOW_LONG} for r in rows]


a, b = table(sys.argv[1]), table(sys.argv[2])
assert len(a) == len(b), f"{len(a)} rows against {len(b)}"
for ra, rb in zip(a, b):
    differ = {k: (ra[k], rb[k]) for k in ra if ra[k] != rb.get(k)}
    assert not differ, f"run {ra['script']}-{ra['variant']} at {ra['voxel_size']}: {differ}"
print(f"same table: {sys.argv[1]} and {sys.argv[2]}, {len(a)} runs")
