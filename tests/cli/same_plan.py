# SPDX-License-Identifier: Apache-2.0
"""check's plan (check --json) is what apply ran (apply --stats --json): row for row, every
field equal, but where check says the shape decides (an inflation's or a star-shaped swirl's
reach, a flow's segment count); there the stroke's rows are of the same type, as many as
check planned unless it is a flow. Prints how many rows were compared."""
import json
import sys
from collections import defaultdict


def by_stroke(rows):
    out = defaultdict(list)
    for row in rows:
        row = {k: v for k, v in row.items() if k != "ran"}
        out[row["stroke"]].append(row)
    return out


check = json.load(open(sys.argv[1]))
apply = json.load(open(sys.argv[2]))
assert check["strokes"] == len(json.load(open(sys.argv[3]))["strokes"]), check["strokes"]
planned, ran = by_stroke(check["deformations"]), by_stroke(apply["deformations"])
assert set(ran) <= set(planned), (sorted(planned), sorted(ran))
same = shaped = 0
for stroke, rows in planned.items():
    done = ran.get(stroke, [])
    if any(r.get("decided_on_shape") for r in rows):
        assert {r["type"] for r in done} == {rows[0]["type"]}, (stroke, rows, done)
        assert not any(r.get("decided_on_shape") for r in done), done
        if not rows[0]["type"].startswith("flow"):
            assert len(done) == len(rows), (stroke, rows, done)
        shaped += len(rows)
        continue
    assert rows == done, f"stroke {stroke}: check planned\n{rows}\napply ran\n{done}"
    same += len(rows)
print(same, shaped)
