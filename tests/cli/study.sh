#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# sweepers-cli study: a script replayed at several voxel sizes and variants and measured
# against the exact shape its history defines. Checked here: the table's columns and rows,
# the error of a translated sphere against the analytic sphere computed independently,
# the convergence of the rigid-motion study, resuming after a SIGKILL without redoing
# finished runs, and every refusal with its exact message.
. "$(dirname "$0")/common.sh" "$@"

# --- a translated sphere: the study's error against an independent measure ------------
cat >"$tmp/translate.json" <<'EOF'
{ "sweepers": 1, "grid": { "voxel_size": 0.03125, "half_width": 3 },
  "start": { "sphere": { "center": [0, 0, 0], "radius": 0.5 } },
  "strokes": [ { "type": "sweep", "tools": [ { "shape": "ball", "size": 1.5, "falloff": 0.5,
    "path": [ { "t": [0, 0, 0] }, { "t": [0.2, 0.1, 0] } ] } ] } ] }
EOF
"$cli" study "$tmp/translate.json" -o "$tmp/t" --voxel-sizes 1/32,1/64 \
  --variants trilinear,first-order -q
"$py" - "$tmp/t" "$(dirname "$0")/.." <<'PY'
import csv, math, sys
sys.path.insert(0, sys.argv[2])
from ply import read_ply
d = sys.argv[1]
rows = list(csv.DictReader(open(f"{d}/study.csv")))
columns = ("script variant voxel_size wall_s measure_s advect_s renorm_s mesh_s peak_rss_mb active_voxels volume "
           "volume_change_pct area euler genus components err_mean err_rms err_max "
           "err_rms_voxels sign_flips order_rms volume_ref volume_err order_volume threads host").split()
missing = [c for c in columns if c not in rows[0]]
assert not missing, f"columns missing: {missing}"
assert [(r["variant"], float(r["voxel_size"])) for r in rows] == [
    ("trilinear", 1 / 32), ("first-order", 1 / 32), ("trilinear", 1 / 64),
    ("first-order", 1 / 64)], rows
for r in rows:
    assert r["script"] == "translate" and int(r["threads"]) >= 1 and r["host"], r
    assert r["failure"] == "" and int(r["euler"]) == 2 and int(r["components"]) == 1, r
    # Measuring against the exact reference takes time of its own, outside wall_s.
    assert float(r["measure_s"]) > 0 and float(r["wall_s"]) > 0, r
# Independently: the distance of every vertex of the exported mesh to the moved sphere
# (a binary PLY whose vertices are float properties, x y z first).
points, triangles = read_ply(f"{d}/runs/translate-trilinear_64/mesh.ply")
err, moved = [], []
c, radius = (0.2, 0.1, 0.0), 0.5
for p in points:
    d = math.dist(p, c)
    err.append(d - radius)
    moved.append(tuple(c[k] + radius * (p[k] - c[k]) / d for k in range(3)))
independent = math.sqrt(sum(e * e for e in err) / len(err))
study = float(rows[2]["err_rms"])
print(f"translated sphere at 1/64: study err_rms {study:.3g}, mesh to analytic sphere {independent:.3g}")
assert abs(study - independent) < 0.05 * independent, (study, independent)
# The volume error: the mesh's volume against that of the same mesh with every vertex moved
# radially onto the analytic sphere (the study moves them along their normals).
def volume(v, triangles):
    total = 0.0
    for a, b, t in triangles:
        (ax, ay, az), (bx, by, bz), (tx, ty, tz) = v[a], v[b], v[t]
        total += ax * (by * tz - bz * ty) - ay * (bx * tz - bz * tx) + az * (bx * ty - by * tx)
    return total / 6.0
mesh, exact = abs(volume(points, triangles)), abs(volume(moved, triangles))
independent, study = mesh - exact, float(rows[2]["volume_err"])
print(f"translated sphere at 1/64: study volume_err {study:.3g}, against the analytic sphere "
      f"{independent:.3g} ({100 * independent / exact:.2g}% of {exact:.5g})")
assert abs(float(rows[2]["volume_ref"]) - exact) < 1e-6 * exact, (rows[2]["volume_ref"], exact)
assert abs(study - independent) < 0.05 * abs(independent), (study, independent)
PY
# The plots draw the table's figures: the first data block (trilinear) holds each run's
# voxel size, RMS error and volume error in percent of the exact volume.
"$py" - "$tmp/t" <<'PY'
import csv, sys
d = sys.argv[1]
rows = [r for r in csv.DictReader(open(f"{d}/study.csv")) if r["variant"] == "trilinear"]
gp = open(f"{d}/convergence.gp").read()
block = gp.split("$s0v0 << EOD\n", 1)[1].split("EOD\n", 1)[0].split("\n")[:-1]
assert len(block) == len(rows), (block, rows)
for line, r in zip(block, rows):
    h, rms, volume = map(float, line.split()[:3])
    percent = 100 * float(r["volume_err"]) / float(r["volume_ref"])
    assert h == float(r["voxel_size"]) and rms == float(r["err_rms"]), (line, r)
    assert abs(volume - percent) < 1e-5 * abs(percent), (line, percent)
PY
for f in study.csv report.md convergence.gp convergence.png convergence.svg; do
  [ -s "$tmp/t/$f" ] || fail "the study of two sizes and two variants wrote no $f"
done

# --- a topology change the exact shape does not have ------------------------------------
# The membrane that data/studies/thin_membrane.json squeezes is 0.021 thick on its axis
# (0.66 voxels at 1/32): the grid pokes a hole through it, which the report marks against
# the exact topology (the start's); at 1/64 (1.3 voxels) it holds.
"$cli" study "$data/studies/thin_membrane.json" -o "$tmp/membrane" --voxel-sizes 1/32,1/64 -q
"$py" - "$tmp/membrane/study.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
topology = [(r["genus"], r["components"], r["ref_genus"], r["ref_components"]) for r in rows]
print("thin membrane: genus, components, exact genus, exact components:", topology)
assert topology == [("1", "1", "0", "1"), ("0", "1", "0", "1")], topology
PY
grep -qF "| 0 | 1 | 1 (exact: Euler 2, genus 0, 1 component) |" "$tmp/membrane/report.md" ||
  fail "report.md does not mark the hole at 1/32: $(grep '1/32' "$tmp/membrane/report.md")"

# --- the rigid-motion study converges --------------------------------------------------
"$cli" study "$data/studies/rigid_motion.json" -o "$tmp/rigid" --voxel-sizes 1/16,1/32,1/64 -q
"$py" - "$tmp/rigid/study.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
errs = [float(r["err_rms"]) for r in rows]
orders = [float(r["order_rms"]) for r in rows[1:]]
print("rigid motion, corrected: err_rms", errs, "orders", orders)
assert errs[0] > errs[1] > errs[2], errs
assert all(p >= 1.0 for p in orders), orders
PY
grep -q "| corrected | 1/64 |" "$tmp/rigid/report.md" || fail "report.md lacks the 1/64 row"
"$py" - "$tmp/rigid" <<'PY'
import sys, xml.etree.ElementTree as ET
from PIL import Image
d = sys.argv[1]
png = Image.open(f"{d}/convergence.png")
png.load()
assert png.size == (1280, 960), png.size
# Something is drawn: many distinct colours, not a blank page.
assert len(png.convert("RGB").getcolors(1 << 20) or []) > 8
root = ET.parse(f"{d}/convergence.svg").getroot()
assert root.tag.endswith("svg"), root.tag
assert sum(1 for e in root.iter() if e.tag.endswith("path")) > 10
print("plots: convergence.png 1280x960 and a valid convergence.svg")
PY

# --- several scripts; --jobs 2 gives the table of one run at a time ---------------------
two=("$data/studies/rigid_motion.json" "$tmp/translate.json")
sizes=(--voxel-sizes 1/16,1/32 --variants trilinear,cubic)
"$cli" study "${two[@]}" -o "$tmp/jobs1" "${sizes[@]}" -q
"$cli" study "${two[@]}" -o "$tmp/jobs2" "${sizes[@]}" --jobs 2 -q
"$py" "$(dirname "$0")/same_table.py" "$tmp/jobs1/study.csv" "$tmp/jobs2/study.csv"
"$py" - "$tmp/jobs2" <<'PY'
import csv, json, sys
from PIL import Image
d = sys.argv[1]
rows = list(csv.DictReader(open(f"{d}/study.csv")))
assert [r["script"] for r in rows] == ["rigid_motion"] * 4 + ["translate"] * 4, rows
# Each run had half the threads, in a process of its own.
assert {r["threads"] for r in rows} == {str(max(1, int(rows[0]["threads"])))}, rows
plan = json.load(open(f"{d}/plan.json"))
assert [r["id"] for r in plan["runs"]][:2] == ["rigid_motion-trilinear_16", "rigid_motion-cubic_16"]
# Before any run finished, only the memory of a sphere's band is estimated: more at half
# the voxel size.
est = {r["id"]: r["estimate"] for r in plan["runs"]}
coarse, fine = est["translate-trilinear_16"], est["translate-trilinear_32"]
assert coarse["seconds"] is None and coarse["basis"].startswith("start band"), coarse
assert fine["memory_mb"] > coarse["memory_mb"] > 64, (coarse, fine)
png = Image.open(f"{d}/convergence.png")
assert png.size == (1280, 1920), png.size  # a set of four panels per script
report = open(f"{d}/report.md").read()
assert "## rigid_motion" in report and "## translate" in report, report
print("two scripts, --jobs 2: the same table; plan estimates; one panel set per script")
PY

# --- --stats: where each run's measuring went, kept in its result, phases within measure_s
"$cli" study -o "$tmp/jobs2" --merge --stats -q 2>"$tmp/stats"
"$py" - "$tmp/stats" "$tmp/jobs2" <<'PY'
import csv, json, sys
lines = open(sys.argv[1]).read().splitlines()
assert lines[0].split()[:5] == ["measured", "in", "seconds:", "wall", "measure"], lines
rows = list(csv.DictReader(open(f"{sys.argv[2]}/study.csv")))
assert len(lines) == 1 + len(rows), lines
for line, row in zip(lines[1:], rows):
    cells = line.split()
    assert cells[:2] == [row["script"], row["variant"]], (line, row)
    wall, measure, grid, voxels, crossings, n_crossings, vertices, n_vertices = map(float, cells[3:])
    # (Five figures rounded to 0.01 each.)
    assert 0 < grid + voxels + crossings + vertices <= measure + 0.025, line
    # Each of the grid's crossings and each mesh vertex gave one error sample.
    assert n_crossings + n_vertices == int(row["err_samples"]), (line, row["err_samples"])
    assert n_crossings > 0 and n_vertices > 0, line
print(f"--stats: the measure's phases of {len(rows)} runs, read back from their results")
PY

# --- a voxel size a double does not hold exactly: its run is found again ----------------
"$cli" study "$data/studies/rigid_motion.json" -o "$tmp/odd" --voxel-sizes 0.07 -q
"$cli" study "$data/studies/rigid_motion.json" -o "$tmp/odd" --voxel-sizes 0.07 2>"$tmp/err"
grep -q "1 runs (1 reused from before, 0 failed)" "$tmp/err" || fail "0.07 again: $(cat "$tmp/err")"

# --- the plan run step by step, as any other engine runs it (a shell loop) --------------
"$cli" study "${two[@]}" -o "$tmp/loop" "${sizes[@]}" --plan-only -q
"$cli" study -o "$tmp/loop" --list >"$tmp/ids"
[ "$(wc -l <"$tmp/ids")" = 8 ] || fail "--list: $(cat "$tmp/ids")"
while read -r id; do "$cli" study -o "$tmp/loop" --run "$id" -q; done <"$tmp/ids"
[ -z "$("$cli" study -o "$tmp/loop" --list)" ] || fail "runs left after running them all"
"$cli" study -o "$tmp/loop" --merge -q
"$py" "$(dirname "$0")/same_table.py" "$tmp/jobs1/study.csv" "$tmp/loop/study.csv"
# --- what runs keep: --keep and --half go into the plan, which --run follows; no row changes
"$cli" study "${two[@]}" -o "$tmp/kept" "${sizes[@]}" --plan-only --keep grids --half -q
while read -r id; do "$cli" study -o "$tmp/kept" --run "$id" -q; done <"$tmp/ids"
"$cli" study -o "$tmp/kept" --merge -q
"$py" "$(dirname "$0")/same_table.py" "$tmp/jobs1/study.csv" "$tmp/kept/study.csv"
"$cli" study "${two[@]}" -o "$tmp/bare" "${sizes[@]}" --keep none --json -q >"$tmp/bare.json"
"$py" "$(dirname "$0")/same_table.py" "$tmp/jobs1/study.csv" "$tmp/bare/study.csv"
"$py" - "$tmp" "$tmp/ids" <<'PY'
import json, os, sys, pyopenvdb as vdb
t, ids = sys.argv[1], open(sys.argv[2]).read().split()
assert json.load(open(f"{t}/kept/plan.json"))["keep"] == "grids"
assert json.load(open(f"{t}/kept/plan.json"))["half"] is True
for run in ids:
    kept, bare, both = (f"{t}/{d}/runs/{run}" for d in ("kept", "bare", "jobs1"))
    assert not os.path.exists(f"{kept}/mesh.ply"), run
    assert vdb.read(f"{kept}/grid.vdb", "surface").metadata["is_saved_as_half_float"] is True
    assert not vdb.read(f"{both}/grid.vdb", "surface").metadata.get("is_saved_as_half_float")
    assert sorted(os.listdir(bare)) == ["result.json"], os.listdir(bare)
files = json.load(open(f"{t}/bare.json"))["files"]
assert not [f for f in files if "/runs/" in f], files
print(f"--keep grids --half: {len(ids)} half-float grids and no meshes; --keep none: results "
      "only; the same table")
PY
refuses "sweepers-cli: --keep: 'some' is not one of both, grids, meshes, none" \
  study -o "$tmp/kept" --keep some
refuses "sweepers-cli: $tmp/loop: the study has no run 'nope' (its runs: $(paste -sd, "$tmp/ids" | sed 's/,/, /g'))" \
  study -o "$tmp/loop" --run nope
refuses "sweepers-cli: $tmp/none: no study plan there (plan.json); plan one with sweepers-cli study SCRIPT... -o $tmp/none" \
  study -o "$tmp/none" --merge
# A script edited after planning: its runs refuse, rather than mix two scripts' results.
cp "$tmp/translate.json" "$tmp/edited.json"
"$cli" study "$tmp/edited.json" -o "$tmp/edit" --voxel-sizes 1/16 --plan-only -q
sed -i 's/0.2, 0.1, 0/0.25, 0.1, 0/' "$tmp/edited.json"
rc=0
"$cli" study -o "$tmp/edit" --run edited-corrected_16 2>"$tmp/err" || rc=$?
[ "$rc" = 1 ] && grep -q "changed since the study was planned" "$tmp/err" ||
  fail "an edited script ran: $rc $(cat "$tmp/err")"
# A plan whose run id would name a directory elsewhere is refused, not followed.
sed -i 's#"id": "edited-corrected_16"#"id": "../../outside"#' "$tmp/edit/plan.json"
rc=0
"$cli" study -o "$tmp/edit" --list 2>"$tmp/err" || rc=$?
[ "$rc" = 1 ] && grep -q "is not one of a study" "$tmp/err" ||
  fail "a plan with a run id outside the study: $rc $(cat "$tmp/err")"
echo "plan, list, run one by one, merge: the same table"

# --- resuming after a SIGKILL ------------------------------------------------------------
stopped KILL "$tmp/killed.err" '[ -f "$tmp/killed/study.csv" ] && [ "$(wc -l <"$tmp/killed/study.csv")" -ge 3 ]' \
  study "$data/studies/rigid_motion.json" -o "$tmp/killed" --voxel-sizes 1/16,1/32,1/64 -q
done_rows=$(($(wc -l <"$tmp/killed/study.csv") - 1))
[ "$done_rows" -ge 2 ] || fail "the study wrote $done_rows rows before it was killed"
stamp() { stat -c %y "$tmp/killed/runs/rigid_motion-corrected_16/grid.vdb" "$tmp/killed/runs/rigid_motion-corrected_32/grid.vdb"; }
before=$(stamp)
"$cli" study "$data/studies/rigid_motion.json" -o "$tmp/killed" --voxel-sizes 1/16,1/32,1/64 \
  2>"$tmp/err"
grep -q "3 runs ($done_rows reused from before, 0 failed)" "$tmp/err" ||
  fail "resume: $(cat "$tmp/err"), expected $done_rows reused"
[ "$(stamp)" = "$before" ] || fail "a finished run was redone"
[ "$(wc -l <"$tmp/killed/study.csv")" -eq 4 ] || fail "the resumed table does not hold 3 rows"
if find "$tmp/killed" -name "*.tmp-*" | grep -q .; then
  fail "temporary files left: $(find "$tmp/killed" -name "*.tmp-*")"
fi
echo "resumed after SIGKILL: $done_rows of 3 runs reused"

# --- Ctrl-C: the finished runs are kept and said ------------------------------------------
stopped INT "$tmp/stopped.err" '[ -f "$tmp/stopped/study.csv" ] && [ "$(wc -l <"$tmp/stopped/study.csv")" -ge 2 ]' \
  study "$data/studies/rigid_motion.json" -o "$tmp/stopped" --voxel-sizes 1/16,1/128 -q
[ "$rc" = 130 ] || fail "a study stopped by SIGINT exited $rc"
grep -q "interrupted after 1 of 2 runs; they are in $tmp/stopped/study.csv" "$tmp/stopped.err" ||
  fail "SIGINT: $(cat "$tmp/stopped.err")"
echo "stopped by SIGINT: exit 130, the finished run kept"

# --- refusals: one line, nothing written -------------------------------------------------
s="$data/studies/rigid_motion.json"
refuses "sweepers-cli: --voxel-sizes: no voxel size given" study "$s" -o "$tmp/bad" --voxel-sizes ""
refuses "sweepers-cli: --voxel-sizes: '-0.1' is not a positive size" \
  study "$s" -o "$tmp/bad" --voxel-sizes=-0.1
refuses "sweepers-cli: --voxel-sizes: 'fine' is not a voxel size (a decimal such as 0.02, or 1/N)" \
  study "$s" -o "$tmp/bad" --voxel-sizes 1/32,fine
refuses "sweepers-cli: a sphere of radius 0.5 at voxel size 1e-09 is 5e+08 voxels in radius; use 1.5 to 100000" \
  study "$s" -o "$tmp/bad" --voxel-sizes 1e-9
refuses "sweepers-cli: --variants: unknown variant 'quintic' (corrected, trilinear, cubic, per-substep, first-order)" \
  study "$s" -o "$tmp/bad" --variants trilinear,quintic
[ ! -e "$tmp/bad" ] || fail "a refused study left $tmp/bad"
touch "$tmp/file"
refuses "sweepers-cli: $tmp/file/study: cannot create the study directory (Not a directory)" \
  study "$s" -o "$tmp/file/study"
echo "study: all checks passed"
