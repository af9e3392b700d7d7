#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sweepers-cli check on real scripts: a valid one prints its plan, a bad one fails with one
# line on stderr that names the file, the location and the reason.
. "$(dirname "$0")/common.sh" "$@"

"$cli" check "$data/pull.json" >"$tmp/out"
grep -q "segment 0: 1 tool(s), 2 sub-steps" "$tmp/out" || { cat "$tmp/out"; exit 1; }
"$cli" check --json "$data/pull.json" | /usr/bin/python3 -c '
import json, sys
report = json.load(sys.stdin)
plan = report["deformations"]
assert report["valid"] and report["strokes"] == 1, report
assert len(plan) == 2 and all(p["steps"] == 2 for p in plan), plan'

printf '{"sweepers": 1, "strokes": [{"type": "sweep", "tools": [{"shape": "ball", "size": 0.3, "falloff": -1, "path": []}]}]}' >"$tmp/bad.json"
if "$cli" check "$tmp/bad.json" >"$tmp/out" 2>"$tmp/err"; then
  echo "a bad script was accepted"; exit 1
fi
[ "$(wc -l <"$tmp/err")" -eq 1 ] || { echo "expected one line:"; cat "$tmp/err"; exit 1; }
grep -q "bad.json: /strokes/0/tools/0/falloff: must be positive" "$tmp/err" || { cat "$tmp/err"; exit 1; }
[ ! -s "$tmp/out" ] || { echo "unexpected stdout"; cat "$tmp/out"; exit 1; }

if "$cli" check "$tmp/missing.json" 2>"$tmp/err"; then echo "a missing file was accepted"; exit 1; fi
grep -q "missing.json: cannot open" "$tmp/err"

# Every stroke kind apply takes, check takes (a smooth stroke once failed with
# "std::get: wrong index for variant"): every data script, and a smooth stroke.
for script in "$data"/*.json "$data"/animation/*.json "$data"/flows/*.json "$data"/studies/*.json; do
  "$cli" check "$script" >"$tmp/out" 2>"$tmp/err" || { echo "$script:"; cat "$tmp/err"; exit 1; }
done
printf '{"sweepers": 1, "strokes": [{"type": "smooth", "tool": {"shape": "ball", "size": 0.3, "falloff": 0.2, "path": [{"t": [0, 1, 0]}, {"t": [0, 0.9, 0.3]}]}, "radial": {"count": 3, "axis": [0, 1, 0], "center": [0, 0, 0]}}]}' >"$tmp/smooth.json"
"$cli" check "$tmp/smooth.json" >"$tmp/out" 2>"$tmp/err" || { cat "$tmp/err"; exit 1; }
grep -q "stroke 0: smooth, 6 dab(s)" "$tmp/out" || { cat "$tmp/out"; exit 1; }
"$cli" check --json "$tmp/smooth.json" | /usr/bin/python3 -c '
import json, sys
plan = json.load(sys.stdin)["deformations"]
assert [(p["type"], p["segment"]) for p in plan] == [("smooth", k) for k in range(6)], plan
assert abs(plan[4]["center"][0] - 0.3 * 3 ** 0.5 / 2) < 1e-12, plan[4]  # [0, 0.9, 0.3] turned 120'

# check's plan is what apply runs (one planner makes both): on every data script and on a
# script of every stroke kind and the options whose plans differ, at a voxel size none of them
# has (pinch and strangle plan their sub-steps by it).
same=0
for script in "$(dirname "$0")/every_stroke_kind.json" "$data"/*.json "$data"/animation/*.json "$data"/flows/*.json \
              "$data"/fluid/*.json "$data"/studies/*.json; do
  "$cli" check --json --voxel-size 0.05 "$script" >"$tmp/plan.json"
  "$cli" -q apply --stats --json --voxel-size 0.05 "$script" -o "$tmp/out.vdb" >"$tmp/ran.json" \
    2>/dev/null || fail "apply $script"
  read -r rows shaped < <(/usr/bin/python3 "$(dirname "$0")/same_plan.py" "$tmp/plan.json" \
    "$tmp/ran.json" "$script") || fail "$script: check's plan is not what apply ran"
  same=$((same + rows))
done
[ "$same" -gt 300 ] || fail "only $same rows compared"
echo "check: its plan is what apply ran, $same steps of every data script"
echo "check: ok"
